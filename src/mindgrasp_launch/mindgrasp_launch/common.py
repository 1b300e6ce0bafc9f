"""Pieces several launch profiles share, built through :mod:`mindgrasp_launch.launch_api`: real
launch_ros actions under ``ros2 launch``, ours under ``mindgrasp launch``."""

from __future__ import annotations

import uuid
from pathlib import Path
from typing import Any

from mindgrasp_launch import launch_api as la


def _if_equal(argument: str, value: str) -> Any:
    """``IfCondition(EqualsSubstitution(LaunchConfiguration(argument), value))`` (what Jazzy's
    launch recommends instead of the deprecated LaunchConfigurationEquals)."""
    return la.IfCondition(la.EqualsSubstitution(la.LaunchConfiguration(argument), value))


def _if_differs(argument: str, value: str) -> Any:
    """``IfCondition(NotEqualsSubstitution(LaunchConfiguration(argument), value))``."""
    return la.IfCondition(la.NotEqualsSubstitution(la.LaunchConfiguration(argument), value))


def classifier_nodes(files: list[Path], model_argument: str = 'model') -> list[Any]:
    """The classifier node (name ``classifier``), with ``model:=<file>`` when that launch argument
    is not empty, else the model of its parameter files. Declare the argument in the profile."""
    return [
        la.Node(package='mindgrasp_classifier', executable='classifier_node', name='classifier',
                parameters=list(files),
                condition=_if_equal(model_argument, '')),
        la.Node(package='mindgrasp_classifier', executable='classifier_node', name='classifier',
                parameters=[*files, {'model': la.LaunchConfiguration(model_argument)}],
                condition=_if_differs(model_argument, '')),
    ]


def eeg_source_arguments() -> list[Any]:
    """``amp:=virtual|lsl`` and ``eeg_stream:=NAME``, for :func:`eeg_source_nodes`."""
    return [
        la.DeclareLaunchArgument('amp', default_value='virtual', choices=['virtual', 'lsl'],
                                 description='EEG source: virtual (virtual amplifier + virtual '
                                             'subject) or lsl (a real amplifier streaming over '
                                             'LSL)'),
        la.DeclareLaunchArgument('eeg_stream', default_value='MIndGrasp-VirtualAmp',
                                 description='LSL stream name of the amplifier'),
    ]


def virtual_amp_pin() -> tuple[dict[str, str], dict[str, str]]:
    """``(virtual amplifier parameters, acquisition parameters)`` that pin a launch's
    acquisition node to the launch's own virtual amplifier: a source id made for this launch
    (``mindgrasp-<12 hex digits>``, a uuid made once per launch when its parameters are
    resolved) and this host. LSL streams are visible across the machine and the lab's
    network, so a second demo (another ROS domain, another rig) with the same stream name can
    no longer feed this one's classifier (issue 42). Lock-step runs have no LSL stream: their
    records do not depend on it. The acquisition waits up to 120 s for that amplifier (not the
    30 s of a stream started by hand): it starts beside it, and a real ``ros2 launch`` demo on a
    loaded 2-core machine took over 30 s to bring it up."""
    source_id = _run_source_id()
    return {'source_id': source_id}, {'source_id': source_id, 'hostname': 'local',
                                      'resolve_timeout': 120.0}


#: the launch configuration that keeps a launch's source id once made
_RUN_SOURCE_ID = 'mindgrasp_eeg_run_source_id'


def _run_source_id() -> Any:
    """A substitution resolved once per launch (not per generated description, which a process
    that launches several times keeps in a cache) to ``mindgrasp-<12 hex digits>``."""
    if la.using_real_launch():
        from launch import Substitution
    else:
        from mindgrasp_launch.substitutions import Substitution

    class RunSourceId(Substitution):
        def perform(self, context: Any) -> str:
            return context.launch_configurations.setdefault(
                _RUN_SOURCE_ID, f'mindgrasp-{uuid.uuid4().hex[:12]}')

        def describe(self) -> str:
            return 'RunSourceId()'

    return RunSourceId()


def eeg_source_nodes(files: list[Path], seed: object, subject_mode: object) -> list[Any]:
    """The virtual amplifier (only with ``amp:=virtual``) and the acquisition node on
    ``eeg_stream``, pinned to that amplifier (:func:`virtual_amp_pin`) with ``amp:=virtual``;
    declare :func:`eeg_source_arguments` in the profile."""
    stream = la.LaunchConfiguration('eeg_stream')
    amp_pin, acquisition_pin = virtual_amp_pin()
    return [
        la.Node(package='mindgrasp_eeg', executable='virtual_amp_node', name='virtual_amp',
                parameters=[*files, {'stream_name': stream, 'seed': seed,
                                     'subject_mode': subject_mode, **amp_pin}],
                condition=_if_equal('amp', 'virtual')),
        la.Node(package='mindgrasp_eeg', executable='acquisition_node', name='eeg_acquisition',
                parameters=[*files, {'stream_name': stream, **acquisition_pin}],
                condition=_if_equal('amp', 'virtual')),
        la.Node(package='mindgrasp_eeg', executable='acquisition_node', name='eeg_acquisition',
                parameters=[*files, {'stream_name': stream}],
                condition=_if_differs('amp', 'virtual')),
    ]


def eeg_pin_arguments() -> list[Any]:
    """``eeg_source_id:=``, ``eeg_host:=`` and ``eeg_unpinned:=false`` of a profile that reads
    a real amplifier: under ``mindgrasp launch`` the launch is refused in one line, before any
    process starts, unless both are given or ``eeg_unpinned:=true`` says on purpose that any
    sender of the stream name is accepted (the acquisition node refuses the same at its start
    under ``ros2 launch``: :func:`eeg_pin_parameters`)."""
    from mindgrasp_launch.number_argument import pin_check_argument

    return [
        la.DeclareLaunchArgument('eeg_source_id', default_value='',
                                 description="the amplifier's LSL source_id (`mindgrasp "
                                             'launch eeg eeg_stream:=NAME` logs it on '
                                             'connecting)'),
        la.DeclareLaunchArgument('eeg_host', default_value='',
                                 description="the host the amplifier's LSL app runs on (local: "
                                             'this host)'),
        pin_check_argument('eeg_unpinned', default_value='false',
                           description='true: accept any LSL sender of eeg_stream (a bench '
                                       'test; another rig or demo with the same stream name '
                                       'could drive the arm)'),
    ]


def eeg_pin_parameters() -> dict[str, Any]:
    """The acquisition node's pinning parameters from :func:`eeg_pin_arguments`."""
    return {'source_id': la.LaunchConfiguration('eeg_source_id'),
            'hostname': la.LaunchConfiguration('eeg_host'),
            'allow_unpinned': la.LaunchConfiguration('eeg_unpinned')}


#: values of the ``display:=`` launch argument
DISPLAY_MODES = ('off', 'window', 'fullscreen', 'headless')


def display_arguments() -> list[Any]:
    """``display:=off|window|fullscreen|headless`` and the display's options, for
    :func:`display_nodes`."""
    return [
        la.DeclareLaunchArgument('display', default_value='off', choices=list(DISPLAY_MODES),
                              description="the participant's screen (pygame): a window, full "
                                          'screen, or headless (frames to /display/image and '
                                          'PNG files); off: none'),
        la.DeclareLaunchArgument('display_png_dir', default_value='',
                              description='folder for the display PNG frames (one per prompt '
                                          "phase); '' none"),
        la.DeclareLaunchArgument('display_layout', default_value='auto',
                              choices=['auto', 'graz', 'trainer', 'test'],
                              description='display layout; auto follows the prompts'),
        la.DeclareLaunchArgument('display_label', default_value='',
                              description="phase name in the display's banner"),
        la.DeclareLaunchArgument('markers', default_value='auto',
                              choices=['auto', 'true', 'false'],
                              description='mirror prompts (at the display flip when a display '
                                          'runs), targets, results and controller states to the '
                                          'LSL marker stream MIndGrasp-Markers, for LabRecorder; '
                                          'auto: when a display shows the participant something'),
    ]


def display_nodes(files: list[Path], n_trials: object = 0) -> list[Any]:
    """The participant display node (name ``participant_display``) in the mode of ``display:=``;
    declare :func:`display_arguments` in the profile."""
    common = {'png_dir': la.LaunchConfiguration('display_png_dir'),
              'layout': la.LaunchConfiguration('display_layout'),
              'phase_label': la.LaunchConfiguration('display_label'), 'n_trials': n_trials}
    return [
        la.Node(package='mindgrasp_trainer', executable='display_node', name='participant_display',
             parameters=[*files, {**common, 'headless': mode == 'headless',
                                  'fullscreen': mode == 'fullscreen'}],
             condition=_if_equal('display', mode))
        for mode in DISPLAY_MODES[1:]
    ] + [
        # what the participant saw, when: the display's flips (markers auto or true); without a
        # display (markers true) the prompts as sent
        la.GroupAction([la.Node(package='mindgrasp_eeg', executable='marker_node',
                                name='lsl_markers', condition=display,
                                parameters=[*la.config_files('eeg'), {'cue_topic': cues}])],
                       condition=markers)
        for markers, display, cues in (
            (_if_differs('markers', 'false'), _if_differs('display', 'off'), '/display/flip'),
            (_if_equal('markers', 'true'), _if_equal('display', 'off'), '/trainer/prompt'))]


def sim_scene_camera(display_rate: float = 3.0) -> list[tuple[object, dict]]:
    """(condition, parameters) pairs for the simulator: its scene camera
    (``/scene/image_raw``) runs at ``display_rate`` Hz when a display is shown, else it is off.

    3 Hz: a 320x240 view with the training robot takes two TinyRenderer passes (about 30 ms on
    an idle core, several times that on a loaded machine; benchmarks/display.py), which the
    simulator pays inside its real-time loop; the training robot moves slowly enough for 3 Hz."""
    return [(_if_equal('display', 'off'), {'scene_camera_rate': 0.0}),
            (_if_differs('display', 'off'),
             {'scene_camera_rate': display_rate})]


def fsm_node(files: list[Path], parameters: dict | None = None) -> Any:
    """The grasp controller (name ``fsm``) with ``command_interface:=`` of the profile (declare
    it with :func:`command_interface_argument`) after its parameter files."""
    return la.Node(package='mindgrasp_fsm', executable='fsm_node', name='fsm',
                   parameters=[*files, {**(parameters or {}), 'command_interface':
                                        la.LaunchConfiguration('command_interface')}])


def command_interface_argument(default: str = 'velocity') -> Any:
    """``command_interface:=velocity|trajectory|servo_twist``: the arm command the driver takes
    (mindgrasp_fsm.command_interface)."""
    from mindgrasp_fsm.command_interface import COMMAND_INTERFACES

    return la.DeclareLaunchArgument(
        'command_interface', default_value=default, choices=list(COMMAND_INTERFACES),
        description='arm command of the controller: velocity (std_msgs/Float64MultiArray on '
                    '/arm_controller/commands, forward velocity controller), trajectory '
                    '(trajectory_msgs/JointTrajectory on /arm_controller/joint_trajectory, '
                    'JointTrajectoryController) or servo_twist (geometry_msgs/TwistStamped on '
                    '/servo_node/delta_twist_cmds, MoveIt Servo)')


def robot_argument(default: str = 'mindgrasp_arm', description: str = '') -> Any:
    """``robot:=NAME|path/to/robot.yaml``: the arm every node that reads it gets (simulator,
    controller, trainer, live view). Under ``mindgrasp launch`` a bad name or description is
    one line naming the problem and the fix, before any process starts (checked by
    :func:`~mindgrasp_common.robot_description.load_robot`, which the nodes use too); an empty
    ``default`` accepts an empty value (the profile then means "the recorded run's robot")."""
    from mindgrasp_common.robot_description import load_robot, robot_choices

    def check(text: str) -> object:
        return None if not text.strip() and not default else load_robot(text.strip())

    return la.checked_argument(
        'robot', check=check, default_value=default,
        description=description or f'the arm: {robot_choices()} '
                                   '(mindgrasp_common.robot_description)')


def live_view_arguments() -> list[Any]:
    """``live_view:=true|false`` and ``live_view_port:=8765``, for :func:`live_view_nodes`."""
    return [
        la.DeclareLaunchArgument('live_view', default_value='true', choices=['true', 'false'],
                                 description='serve the topics to Foxglove on '
                                             'ws://localhost:<live_view_port> (loopback only)'),
        la.DeclareLaunchArgument('live_view_port', default_value='8765',
                                 description='TCP port of the live view (0: any free port, '
                                             'printed in its log; a port in use turns the view '
                                             'off with one error line, the rest runs on)'),
    ]


def live_view_nodes() -> list[Any]:
    """The Foxglove bridge (``foxglove_bridge``) when ``live_view:=true``, its layout following
    ``robot:=``; declare :func:`live_view_arguments` and :func:`robot_argument` in the
    profile."""
    return [
        la.Node(package='mindgrasp_bringup', executable='foxglove_bridge_node',
                name='foxglove_bridge',
                # no parameter file of its own; $MINDGRASP_PARAMS_FILES reach it like any node
                parameters=[*la.config_files('live_view'),
                            {'port': la.LaunchConfiguration('live_view_port'),
                             'port_in_use': 'skip', 'robot': la.LaunchConfiguration('robot')}],
                condition=la.IfCondition(la.LaunchConfiguration('live_view'))),
    ]


def run_directory_actions() -> list[Any]:
    """The run directory, the recorder and the ``duration:=`` limit as ordinary launch actions,
    for ``ros2 launch``: the launch arguments ``record``, ``record_topics``, ``record_regex``,
    ``duration`` and ``run_dir``, then a
    :class:`~mindgrasp_launch.launch_ros_extras.RunDirectory`. Put them after the profile's
    own arguments and before its first node.

    Under ``mindgrasp launch`` the list is empty: that launcher adds the same to every launch
    file (a user's too), with the same arguments and rules (:mod:`.run_extras`).
    """
    if not la.using_real_launch():
        return []
    from mindgrasp_launch.launch_ros_extras import RunDirectory
    from mindgrasp_launch.run_extras import COMMON_ARGUMENTS

    return [
        *(la.DeclareLaunchArgument(a.name, default_value=a.default_text(),
                                   description=a.description, choices=a.choices)
          for a in COMMON_ARGUMENTS),
        la.DeclareLaunchArgument('run_dir', default_value='',
                                 description='the run directory (empty: a new '
                                             '<UTC time>_<profile> in $MINDGRASP_RUNS_DIR or '
                                             'runs/)'),
        RunDirectory(),
    ]


def driver_nodes(role: str, condition: Any = None) -> list[Any]:
    """The ``<role>_driver`` node of a real arm or camera: the program ``<role>_driver:=`` names
    (on PATH, a path, ``package/executable``; under ``mindgrasp launch`` also a Python module)
    with ``<role>_driver_args:=`` split by shell rules into its arguments. Declare both launch
    arguments in the profile.

    A driver is a required node: its end, even with exit code 0, stops the launch, which then
    ends with a non-zero exit code under ``mindgrasp launch`` (``ros2 launch`` shuts down
    through ``on_exit=Shutdown()``, with its own exit code 0)."""
    if la.using_real_launch():
        from launch.actions import OpaqueFunction

        from mindgrasp_launch.launch_ros_extras import driver_node

        return [OpaqueFunction(function=driver_node, args=[role], condition=condition)]
    from mindgrasp_launch.substitutions import SplitArguments

    return [la.Node(executable=la.LaunchConfiguration(f'{role}_driver'), name=f'{role}_driver',
                    arguments=[SplitArguments(la.LaunchConfiguration(f'{role}_driver_args'))],
                    condition=condition, required=True)]
