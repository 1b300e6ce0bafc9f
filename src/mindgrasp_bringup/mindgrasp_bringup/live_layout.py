"""The Foxglove layout of the live view, built with ``foxglove.layouts`` (foxglove-sdk).

    python -m mindgrasp_bringup.live_layout     # rewrites both files in foxglove/

Two files of the same layout (in mindgrasp_bringup's ``foxglove/``;
``share/mindgrasp_bringup/foxglove/`` of a colcon install), for Layouts > Import from file:

- ``mindgrasp_live.json``: Foxglove's layout format, as the SDK writes it (the Foxglove app);
- ``mindgrasp_live_lichtblick.json``: the format Lichtblick imports (that of the open-source
  Foxglove Studio it was forked from); Lichtblick refuses the SDK's ("missing configById,
  globalVariables, playbackConfig"). The SDK writes no such file, so :func:`studio_layout`
  converts its tree.

Panels: the eye-in-hand camera with the vision overlay, the 3D scene (URDF from
/robot_description moved by /tf, the objects from /sim/objects), the EEG (first sample of the
first channels of each chunk), the classifier's certainty and class, and the controller state.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from mindgrasp_common.resources import resource_path
from mindgrasp_ros.topics import (
    BCI_PREDICTION,
    EEG_RAW,
    FSM_STATE,
    ROBOT_DESCRIPTION,
    SIM_OBJECTS,
    TF,
    TF_STATIC,
    VISION_OVERLAY,
)

__all__ = ['LAYOUT_FILE', 'STUDIO_LAYOUT_FILE', 'TOPICS', 'build_layout', 'studio_layout']

#: the committed layout files (package data of mindgrasp_bringup): Foxglove's format, and that
#: of Lichtblick / Foxglove Studio
LAYOUT_FILE = resource_path('mindgrasp_bringup', 'foxglove') / 'mindgrasp_live.json'
STUDIO_LAYOUT_FILE = LAYOUT_FILE.with_name('mindgrasp_live_lichtblick.json')

#: EEG plot range, V: the auto range of Lichtblick's plot rounds its ticks to 1 mV, which draws
#: microvolt EEG as a flat line; 100 uV holds EEG without its DC offset (change it in the panel)
EEG_RANGE_V = 100e-6

#: topics the layout's panels show (each published by the demo): what the Foxglove app
#: subscribes to with this layout open
TOPICS = tuple(t.name for t in (VISION_OVERLAY, ROBOT_DESCRIPTION, TF, TF_STATIC, SIM_OBJECTS,
                                 EEG_RAW, BCI_PREDICTION, FSM_STATE))


def build_layout() -> str:
    """The layout as Foxglove layout JSON text."""
    import foxglove.layouts as fl

    camera = fl.ImagePanel(title='Eye-in-hand camera + overlay', config=fl.ImageConfig(
        image_mode=fl.ImageModeConfig(image_topic=VISION_OVERLAY.name)))
    scene = fl.ThreeDeePanel(title='Arm and objects (TF, URDF)', config=fl.ThreeDeeConfig(
        follow_tf='base_link', fixed_frame='world',
        # the arm is ~1 m tall: look at it from 2.3 m (the apps' default camera is 20 m away),
        # frame axes without their labels, which would hide the arm
        camera_state=fl.ThreeDeeCameraState(
            distance=2.3, perspective=True, phi=60.0, theta_offset=45.0, target=[0.0, 0.0, 0.0],
            target_offset=[0.3, 0.0, 0.3], target_orientation=[0.0, 0.0, 0.0, 1.0], fovy=45.0,
            near=0.01, far=5000.0),
        scene=fl.BaseRendererSceneSettings(transforms=fl.BaseRendererTransforms(
            show_label=False)),
        layers={'urdf': fl.BaseRendererUrdfLayerSettings(
            layer_id='foxglove.Urdf', instance_id='urdf', label='MIndGrasp arm',
            source_type='topic', topic=ROBOT_DESCRIPTION.name, control_mode='transforms')},
        topics={SIM_OBJECTS.name: fl.BaseRendererRosMarkerTopicSettings(visible=True)}))
    # series enabled, time axes not synced across panels: Lichtblick hides series without
    # 'enabled' and a synced axis ignores each panel's window
    eeg = fl.PlotPanel(title='EEG (V, first sample of each chunk)', config=fl.PlotConfig(
        paths=[fl.PlotSeries(value=f'{EEG_RAW.name}.data[{i}]', label=f'channel {i + 1}',
                             timestamp_method='headerStamp', enabled=True) for i in range(3)],
        min_y_value=-EEG_RANGE_V, max_y_value=EEG_RANGE_V, is_synced=False,
        time_window_mode='sliding', following_view_width=10.0, show_legend=True))
    prediction = fl.PlotPanel(title='Prediction certainty and class', config=fl.PlotConfig(
        paths=[fl.PlotSeries(value=f'{BCI_PREDICTION.name}.certainty', label='certainty',
                             timestamp_method='headerStamp', enabled=True),
               fl.PlotSeries(value=f'{BCI_PREDICTION.name}.class_index', label='class (0 L, 1 R, '
                             '2 both hands, 3 feet)', timestamp_method='headerStamp',
                             line_interpolation='step', enabled=True)],
        is_synced=False, time_window_mode='sliding', following_view_width=30.0,
        show_legend=True))
    state = fl.StateTransitionsPanel(title='Controller state', config=fl.StateTransitionsConfig(
        paths=[fl.StateTransitionsSeries(value=f'{FSM_STATE.name}.state_name', label='state',
                                         timestamp_method='headerStamp', enabled=True),
               fl.StateTransitionsSeries(value=f'{FSM_STATE.name}.object_of_interest',
                                         label='object of interest',
                                         timestamp_method='headerStamp', enabled=True)],
        is_synced=False, time_window_mode='sliding', x_axis_range=60.0))
    left = fl.SplitContainer(direction='column', items=[
        fl.SplitItem(proportion=0.5, content=camera), fl.SplitItem(proportion=0.5, content=scene)])
    right = fl.SplitContainer(direction='column', items=[
        fl.SplitItem(proportion=0.35, content=eeg),
        fl.SplitItem(proportion=0.35, content=prediction),
        fl.SplitItem(proportion=0.3, content=state)])
    layout = fl.Layout(content=fl.SplitContainer(direction='row', items=[
        fl.SplitItem(proportion=0.5, content=left), fl.SplitItem(proportion=0.5, content=right)]))
    return layout.to_json()


#: panel types whose names differ in Lichtblick / Foxglove Studio
_STUDIO_PANEL_TYPES = {'ThreeDee': '3D'}
#: settings of the SDK's format that those apps do not know
_SDK_ONLY = {'Plot': ('timeWindowMode',), 'StateTransitions': ('timeWindowMode',),
             '3D': ('fixedFrame',)}


def studio_layout(sdk_layout: str) -> str:
    """The layout in Lichtblick's / Foxglove Studio's format (``LayoutData``: ``configById``, a
    mosaic tree of two-way splits, ``globalVariables``, ``userNodes``, ``playbackConfig``).

    Panel ids are ``<type>!<n>`` in tree order (deterministic), titles go to
    ``lichtblickPanelTitle`` (Lichtblick) and ``foxglovePanelTitle`` (Foxglove Studio).
    """
    config_by_id: dict[str, Any] = {}

    def panel(node: dict[str, Any]) -> str:
        kind = _STUDIO_PANEL_TYPES.get(node['panelType'], node['panelType'])
        config = {k: v for k, v in node.get('config', {}).items()
                  if k not in _SDK_ONLY.get(kind, ())}
        if node.get('title'):
            config['lichtblickPanelTitle'] = config['foxglovePanelTitle'] = node['title']
        panel_id = f'{kind}!{len(config_by_id) + 1}'
        config_by_id[panel_id] = config
        return panel_id

    def tree(node: dict[str, Any]) -> str | dict[str, Any]:
        if node['type'] == 'panel':
            return panel(node)
        items = node['items']
        if len(items) == 1:
            return tree(items[0]['content'])
        rest = {'type': 'split', 'direction': node['direction'], 'items': items[1:]}
        total = sum(item['proportion'] for item in items)
        return {'first': tree(items[0]['content']), 'second': tree(rest),
                'direction': node['direction'],
                'splitPercentage': round(100.0 * items[0]['proportion'] / total, 3)}

    layout = tree(json.loads(sdk_layout)['content'])
    return json.dumps({'configById': config_by_id, 'globalVariables': {}, 'userNodes': {},
                       'playbackConfig': {'speed': 1.0}, 'layout': layout}, indent=2)


def main(argv: list[str] | None = None) -> int:
    """Write :data:`LAYOUT_FILE` and :data:`STUDIO_LAYOUT_FILE` (or into the folder given)."""
    argv = sys.argv[1:] if argv is None else argv
    folder = Path(argv[0]) if argv else LAYOUT_FILE.parent
    folder.mkdir(parents=True, exist_ok=True)
    sdk = build_layout()
    for name, text in ((LAYOUT_FILE.name, sdk), (STUDIO_LAYOUT_FILE.name, studio_layout(sdk))):
        (folder / name).write_text(text + '\n', encoding='utf-8')
        print(f'wrote {folder / name}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
