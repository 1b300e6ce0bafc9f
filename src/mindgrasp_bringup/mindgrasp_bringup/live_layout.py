"""The Foxglove layout of the live view, built with ``foxglove.layouts`` (foxglove-sdk).

    python -m mindgrasp_bringup.live_layout     # rewrites foxglove/mindgrasp_live.json

In Foxglove: Layouts > Import from file > ``mindgrasp_live.json`` (in mindgrasp_bringup's
``foxglove/``; ``share/mindgrasp_bringup/foxglove/`` of a colcon install). Panels:
the eye-in-hand camera with the vision overlay, the 3D scene (URDF from /robot_description moved
by /tf, the objects from /sim/objects), the EEG (first sample of the first channels of each
chunk), the classifier's certainty and class, and the controller state over time.
"""

from __future__ import annotations

import sys
from pathlib import Path

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

__all__ = ['LAYOUT_FILE', 'TOPICS', 'build_layout']

#: the committed layout file (package data of mindgrasp_bringup)
LAYOUT_FILE = resource_path('mindgrasp_bringup', 'foxglove') / 'mindgrasp_live.json'

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
        layers={'urdf': fl.BaseRendererUrdfLayerSettings(
            layer_id='foxglove.Urdf', instance_id='urdf', label='MIndGrasp arm',
            source_type='topic', topic=ROBOT_DESCRIPTION.name, control_mode='transforms')},
        topics={SIM_OBJECTS.name: fl.BaseRendererRosMarkerTopicSettings(visible=True)}))
    eeg = fl.PlotPanel(title='EEG (V, first sample of each chunk)', config=fl.PlotConfig(
        paths=[fl.PlotSeries(value=f'{EEG_RAW.name}.data[{i}]', label=f'channel {i + 1}',
                             timestamp_method='headerStamp') for i in range(3)],
        time_window_mode='sliding', following_view_width=10.0, show_legend=True))
    prediction = fl.PlotPanel(title='Prediction certainty and class', config=fl.PlotConfig(
        paths=[fl.PlotSeries(value=f'{BCI_PREDICTION.name}.certainty', label='certainty',
                             timestamp_method='headerStamp'),
               fl.PlotSeries(value=f'{BCI_PREDICTION.name}.class_index', label='class (0 L, 1 R, '
                             '2 both hands, 3 feet)', timestamp_method='headerStamp',
                             line_interpolation='step')],
        time_window_mode='sliding', following_view_width=30.0, show_legend=True))
    state = fl.StateTransitionsPanel(title='Controller state', config=fl.StateTransitionsConfig(
        paths=[fl.StateTransitionsSeries(value=f'{FSM_STATE.name}.state_name', label='state'),
               fl.StateTransitionsSeries(value=f'{FSM_STATE.name}.object_of_interest',
                                         label='object of interest')],
        time_window_mode='sliding', x_axis_range=60.0))
    left = fl.SplitContainer(direction='column', items=[
        fl.SplitItem(proportion=0.5, content=camera), fl.SplitItem(proportion=0.5, content=scene)])
    right = fl.SplitContainer(direction='column', items=[
        fl.SplitItem(proportion=0.35, content=eeg),
        fl.SplitItem(proportion=0.35, content=prediction),
        fl.SplitItem(proportion=0.3, content=state)])
    layout = fl.Layout(content=fl.SplitContainer(direction='row', items=[
        fl.SplitItem(proportion=0.5, content=left), fl.SplitItem(proportion=0.5, content=right)]))
    return layout.to_json()


def main(argv: list[str] | None = None) -> int:
    """Write :data:`LAYOUT_FILE` (or the path given)."""
    argv = sys.argv[1:] if argv is None else argv
    path = Path(argv[0]) if argv else LAYOUT_FILE
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(build_layout() + '\n', encoding='utf-8')
    print(f'wrote {path}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
