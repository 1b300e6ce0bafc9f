"""The Foxglove layout of the live view, built with ``foxglove.layouts`` (foxglove-sdk) from the
robot description, so it follows the robot (``robot:=``).

    python -m mindgrasp_bringup.live_layout                      # rewrites both files in foxglove/
    python -m mindgrasp_bringup.live_layout /tmp/xarm --robot xarm6   # another robot's layout

Two files of the same layout (in mindgrasp_bringup's ``foxglove/``;
``share/mindgrasp_bringup/foxglove/`` of a colcon install), for Layouts > Import from file:

- ``mindgrasp_live.json``: Foxglove's layout format, as the SDK writes it (the Foxglove app);
- ``mindgrasp_live_lichtblick.json``: the format Lichtblick imports (that of the open-source
  Foxglove Studio it was forked from); Lichtblick refuses the SDK's ("missing configById,
  globalVariables, playbackConfig"). The SDK writes no such file, so :func:`studio_layout`
  converts its tree.

Panels: the eye-in-hand camera with the vision overlay, the 3D scene (URDF from
/robot_description moved by /tf, the objects from /sim/objects, following the URDF's root link),
the arm joint positions (named after the description's arm joints), the EEG (first sample of the
first channels of each chunk), the classifier's certainty and class, and the controller state.
The committed files are the shipped arm's; the live view node writes the layout of the robot it
is given into the run directory (``foxglove/``).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from mindgrasp_common.resources import resource_path
from mindgrasp_common.robot import DEFAULT_ROBOT
from mindgrasp_common.robot_description import RobotDescription, RobotDescriptionError, load_robot
from mindgrasp_ros.topics import (
    BCI_PREDICTION,
    EEG_RAW,
    FSM_STATE,
    JOINT_STATES,
    ROBOT_DESCRIPTION,
    SIM_OBJECTS,
    TF,
    TF_STATIC,
    VISION_OVERLAY,
)

__all__ = ['LAYOUT_FILE', 'STUDIO_LAYOUT_FILE', 'TOPICS', 'build_layout', 'studio_layout',
           'write_layouts']

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
                                 JOINT_STATES, EEG_RAW, BCI_PREDICTION, FSM_STATE))


def build_layout(robot: str | Path | RobotDescription = DEFAULT_ROBOT) -> str:
    """The layout of ``robot`` (a shipped name, a description YAML path or a description) as
    Foxglove layout JSON text; a bad description raises its one-line
    :class:`~mindgrasp_common.robot_description.RobotDescriptionError`."""
    import foxglove.layouts as fl

    from mindgrasp_sim.tf_tree import TfTree

    description = load_robot(robot)
    # the 3D view follows the URDF's root link (base_link, link_base, world, ...), the frame the
    # simulator (or robot_state_publisher) hangs the arm from
    root = TfTree(description.urdf.read_text(encoding='utf-8')).root
    camera = fl.ImagePanel(title='Eye-in-hand camera + overlay', config=fl.ImageConfig(
        image_mode=fl.ImageModeConfig(image_topic=VISION_OVERLAY.name)))
    scene = fl.ThreeDeePanel(title='Arm and objects (TF, URDF)', config=fl.ThreeDeeConfig(
        follow_tf=root, fixed_frame='world',
        # the arm is ~1 m tall: look at it from 2.3 m (the apps' default camera is 20 m away),
        # frame axes without their labels, which would hide the arm
        camera_state=fl.ThreeDeeCameraState(
            distance=2.3, perspective=True, phi=60.0, theta_offset=45.0, target=[0.0, 0.0, 0.0],
            target_offset=[0.3, 0.0, 0.3], target_orientation=[0.0, 0.0, 0.0, 1.0], fovy=45.0,
            near=0.01, far=5000.0),
        scene=fl.BaseRendererSceneSettings(transforms=fl.BaseRendererTransforms(
            show_label=False)),
        layers={'urdf': fl.BaseRendererUrdfLayerSettings(
            layer_id='foxglove.Urdf', instance_id='urdf', label=f'{description.name} (URDF)',
            source_type='topic', topic=ROBOT_DESCRIPTION.name, control_mode='transforms')},
        topics={SIM_OBJECTS.name: fl.BaseRendererRosMarkerTopicSettings(visible=True)}))
    # series enabled, time axes not synced across panels: Lichtblick hides series without
    # 'enabled' and a synced axis ignores each panel's window
    # /joint_states lists the arm joints in the description's order (the simulator's contract;
    # a driver's order may differ: the labels then say which index is which in its message)
    joints = fl.PlotPanel(title=f'Arm joints (rad, {description.name})', config=fl.PlotConfig(
        paths=[fl.PlotSeries(value=f'{JOINT_STATES.name}.position[{i}]', label=name,
                             timestamp_method='headerStamp', enabled=True)
               for i, name in enumerate(description.arm_joints)],
        is_synced=False, time_window_mode='sliding', following_view_width=30.0,
        show_legend=True))
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
        fl.SplitItem(proportion=0.4, content=camera), fl.SplitItem(proportion=0.4, content=scene),
        fl.SplitItem(proportion=0.2, content=joints)])
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


def write_layouts(folder: Path, robot: str | Path | RobotDescription = DEFAULT_ROBOT
                  ) -> list[Path]:
    """Write the layout of ``robot`` in both formats into ``folder`` (created); the paths."""
    folder.mkdir(parents=True, exist_ok=True)
    sdk = build_layout(robot)
    out = []
    for name, text in ((LAYOUT_FILE.name, sdk), (STUDIO_LAYOUT_FILE.name, studio_layout(sdk))):
        (folder / name).write_text(text + '\n', encoding='utf-8')
        out.append(folder / name)
    return out


def main(argv: list[str] | None = None) -> int:
    """Write :data:`LAYOUT_FILE` and :data:`STUDIO_LAYOUT_FILE` (or into the folder given)."""
    parser = argparse.ArgumentParser(prog='python -m mindgrasp_bringup.live_layout',
                                     description='Write the Foxglove layouts of the live view.')
    parser.add_argument('folder', nargs='?', default=str(LAYOUT_FILE.parent),
                        help='where to write them (default: the committed files)')
    parser.add_argument('--robot', default=DEFAULT_ROBOT, metavar='NAME|YAML',
                        help='the robot whose description the layout follows (default '
                             f'{DEFAULT_ROBOT})')
    args = parser.parse_args(argv)
    try:
        paths = write_layouts(Path(args.folder), args.robot)
    except RobotDescriptionError as exc:
        parser.exit(2, f'{parser.prog}: error: --robot: {exc}\n')
    for path in paths:
        print(f'wrote {path}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
