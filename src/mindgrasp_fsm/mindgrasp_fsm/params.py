"""Gains and thresholds of the grasp controller, loadable from a ROS-format parameter file.

Every number the controller uses lives here, with its unit; ``config/param/fsm.yaml`` holds
the same names under ``fsm: ros__parameters:``. Per-shape values are flat names prefixed by the
shape (``cube_approach_height``), so they are plain ROS parameters.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mindgrasp_common.cli_checks import yaml_error_text
from mindgrasp_common.resources import resource_path
from mindgrasp_common.robot import (
    ARM_JOINTS,
    ARM_LOWER_LIMITS,
    ARM_MAX_VELOCITY,
    ARM_UPPER_LIMITS,
    HOME_POSE,
    URDF_URI,
)
from mindgrasp_common.robot_description import GRASP_CHECKS, load_robot, robot_choices
from mindgrasp_fsm.command_interface import COMMAND_INTERFACES, check_command_interface
from mindgrasp_fsm.errors import FsmError
from mindgrasp_ros.params import ParameterError, check_value, param

SHAPES = ('cube', 'cylinder', 'sphere')
RESUME_MODES = ('require_new_command', 'resume')
#: interaction paradigms of the BCI mode (see :mod:`mindgrasp_fsm.grasp_fsm`)
PARADIGMS = ('paper', 'scan')


#: what a robot description sets (:meth:`FsmParams.apply_robot`); their defaults are the shipped
#: arm's description, so the parameter file leaves them out
ROBOT_PARAMETERS = ('urdf_file', 'tool_link', 'camera_link', 'joint_names', 'home_position',
                    'joint_lower_limits', 'joint_upper_limits', 'max_joint_velocity')


@dataclass
class FsmParams:
    """Parameters of :class:`mindgrasp_fsm.grasp_fsm.GraspFsm` (SI units: s, rad, rad/s, m, N).

    Each field is a ROS parameter of the fsm node (:func:`mindgrasp_ros.params.param`: unit,
    range, description); ``live`` ones take effect at the next tick when set while it runs.
    """

    # --- general (read-only: the robot model and timer are built at start) ---------------------
    autonomous: bool = param(False, 'no BCI: search left, approach and grasp on vision alone')
    robot: str = param('', f'the arm: {robot_choices()}; its URDF, TCP and camera links, '
                       'joints, home pose, limits and velocity limits replace the eight '
                       'parameters below (and grasp_check, and the per-shape values of its '
                       "hand's grasp: section); '' = those as given")
    urdf_file: str = param(URDF_URI, 'URDF for forward / inverse kinematics: a path or a '
                           'package:// URI')
    tool_link: str = param('tcp', 'URDF link of the grasp point between the fingertips')
    camera_link: str = param('camera_color_optical_frame',
                             'URDF link of the camera optical frame')
    joint_names: list[str] = param(list(ARM_JOINTS), 'the arm joints (6 or 7) in /joint_states')
    # start pose of the URDF: long arm up, short arm forward, wrist pitched so the camera looks
    # down at the objects (the paper: all straight except joint 5)
    home_position: list[float] = param(list(HOME_POSE), 'start pose, one per arm joint', unit='rad')
    joint_lower_limits: list[float] = param(list(ARM_LOWER_LIMITS), 'lower joint limits',
                                            unit='rad')
    joint_upper_limits: list[float] = param(list(ARM_UPPER_LIMITS), 'upper joint limits',
                                            unit='rad')
    joint_limit_margin: float = param(0.02, 'kept clear of each joint limit', unit='rad',
                                      min=0.0, max=0.5, live=True)
    max_joint_velocity: list[float] = param(list(ARM_MAX_VELOCITY), 'velocity limit per joint',
                                            unit='rad/s')
    # no profile may step a joint from slow to fast in one tick (braking is never limited)
    max_joint_acceleration: list[float] = param([2.0] * 6, 'speed-up limit per joint for every '
                                                'velocity command', unit='rad/s^2', live=True)
    control_period: float = param(0.02, 'control tick: the node ticks on a fresh joint state '
                                  'once 0.75 of it passed, at once on a prediction, and on its '
                                  'timer after 1.5 of it without a tick', unit='s', min=0.001,
                                  max=1.0)
    # the form of the arm command for the driver (mindgrasp_fsm.command_interface): the same
    # acceleration-limited joint velocities, sent as a driver of each kind takes them
    command_interface: str = param('velocity', 'arm command: velocity (ros2_control forward '
                                   'velocity controller), trajectory (JointTrajectoryController) '
                                   'or servo_twist (MoveIt Servo)', choices=COMMAND_INTERFACES)
    trajectory_horizon: float = param(0.1, 'trajectory: time of the last point of each streamed '
                                      'trajectory (one point per control tick ahead, 2 at least)',
                                      unit='s', min=0.001, max=1.0)
    servo_frame: str = param('base_link', 'servo_twist: frame_id of the twist (the arm base '
                             'frame, MoveIt Servo robot_link_command_frame)')
    lock_duration: float = param(1.0, 'all joints held between states (paper: locks)', unit='s',
                                 min=0.001, max=30.0, live=True)
    watchdog_timeout: float = param(0.3, 'oldest acceptable prediction / joint state; older '
                                    'inputs stop every joint', unit='s', min=0.01, max=10.0,
                                    live=True)
    camera_timeout: float = param(0.5, 'without detections for this long the arm holds still',
                                  unit='s', min=0.01, max=10.0, live=True)
    # after the MI predictions went stale (EEG or classifier lost) and came back: wait for a
    # fresh decision (one class decoded without a break for resume_hold, on windows that began
    # after the loss) or go on with whatever is decoded (resume)
    resume_after_stale: str = param('require_new_command', 'after an EEG/prediction loss: '
                                    'require_new_command (hold still until a fresh decision) '
                                    'or resume', choices=RESUME_MODES, live=True)
    resume_hold: float = param(1.0, 'a fresh decision after a loss: one class decoded without '
                               'a break for this long', unit='s', min=0.0, max=10.0, live=True)
    # a sensor fault (joint states with NaN/inf, wrong names or sizes, stale) latches a stop as
    # a prediction loss does: released once the joint states were clean this long, then the
    # person's fresh decision (resume_after_stale) restarts the arm
    sensor_clean_time: float = param(1.0, 'after a joint-state fault the arm holds until the '
                                     'joint states were clean this long', unit='s', min=0.0,
                                     max=60.0, live=True)
    # --- BCI -----------------------------------------------------------------------------------
    # paper: the person steers with 4 classes (left/right turn, both hands select and approach,
    # both feet back off). scan: the arm turns from object to object itself and offers each one;
    # the person answers yes (both hands) or no (both feet) and cancels an approach with both
    # feet, each decision taken on accumulated evidence (mindgrasp_fsm.evidence). Thresholds
    # chosen on docs/subjects/eegmmidb_s001_swapped.yaml (benchmarks/decision_layer.py); measured
    # in the loop on other runs (src/mindgrasp_experiments/README.md).
    paradigm: str = param('scan', 'BCI interaction: paper (4-class steering) or scan (the arm '
                          'offers each object, the person confirms or cancels)',
                          choices=PARADIGMS)
    # the person's answer pair (mindgrasp_common.answer_pair): auto = the one the classifier
    # model chose at calibration (hands_feet for a model without one); the model's decision
    # thresholds replace the four below unless model_thresholds is false
    answer_pair: str = param('auto', "scan: the imagery that answers yes / no: auto (the "
                             "classifier model's choice, else hands_feet), hands_feet, "
                             'left_right, mi_rest or <yes>_<no> (decoder class names)')
    classifier_model: str = param('', 'scan: classifier model (.json) whose answer pair and '
                                  "decision thresholds auto takes ('': none, hands_feet and the "
                                  'thresholds below)')
    model_thresholds: bool = param(True, "scan: use the classifier model's per-person decision "
                                   'thresholds (when it has them) instead of the four below')
    require_ready_model: bool = param(False, 'refuse to start unless classifier_model was '
                                      "called ready by its calibration gate (the hardware "
                                      'profile sets it; false overrides)')
    confirm_threshold: float = param(3.0, 'scan: evidence for both hands against both feet '
                                     'that commits to the offered object', unit='nat s',
                                     min=0.01, max=100.0, live=True)
    pass_threshold: float = param(3.0, 'scan: evidence for both feet against both hands that '
                                  'passes the offered object at once', unit='nat s', min=0.01,
                                  max=100.0, live=True)
    affirm_threshold: float = param(3.0, 'scan: evidence for both hands against both feet '
                                    'during the approach (go on) before the final approach and '
                                    'grasp start', unit='nat s', min=0.01, max=100.0, live=True)
    cancel_threshold: float = param(5.0, 'scan: evidence for both feet against both hands that '
                                    'cancels an approach before the gripper closes',
                                    unit='nat s', min=0.01, max=100.0, live=True)
    evidence_clip: float = param(2.0, 'scan: largest log-probability ratio one decoder window '
                                 'adds to the evidence', unit='nat', min=0.01, max=20.0,
                                 live=True)
    offer_timeout: float = param(10.0, 'scan: an object is offered this long; without an '
                                 'answer the arm passes on to the next', unit='s',
                                 min=0.5, max=120.0, live=True)
    offer_delay: float = param(2.5, 'scan: decoder windows ending this soon after an offer '
                               'began are not counted (the person sees the offer and starts '
                               'to imagine; a 2 s window then still holds what came before)',
                               unit='s', min=0.0, max=10.0, live=True)
    scan_skip_angle: float = param(0.35, 'scan: an object whose bearing lies this close to '
                                   'one passed or cancelled in this scan is not offered again '
                                   'until the scan has reached both ends of joint 1',
                                   unit='rad', min=0.0, max=6.3, live=True)
    certainty_threshold: float = param(0.5, 'certainty below which state 3 uses the default '
                                       'slow approach', min=0.0, max=100.0, live=True)
    certainty_cap: float = param(2.0, 'certainty that gives full speed (certainty is unbounded, '
                                 'Eq. 1)', min=0.01, max=100.0, live=True)
    # --- state 1: object search ----------------------------------------------------------------
    # 1.0: at the virtual subject's typical certainty (0.2) the arm turns 0.2 rad/s, so reaching
    # an object 80 deg away takes 7 s, not the 25 s in which misdecoded windows select others
    search_gain: float = param(1.0, 'joint 1 velocity per unit certainty (left +, right -)',
                               unit='rad/s', min=0.0, max=3.0, live=True)
    autonomous_search_velocity: float = param(0.8, 'joint 1 velocity of the autonomous search '
                                              '(turn left)', unit='rad/s', min=0.0, max=3.0,
                                              live=True)
    # added to joint 5 of home for each sweep of the autonomous search (0.15: the view spans
    # 0.15-0.75 m from the base)
    autonomous_search_tilts: list[float] = param(
        [0.15, 0.15, 0.3, 0.0], 'joint 5 tilt added to home for each autonomous sweep',
        unit='rad', live=True)
    search_confirm_time: float = param(0.2, 'an object must be seen this long before it is '
                                       'taken', unit='s', min=0.0, max=10.0, live=True)
    search_ignore_angle: float = param(1.0, 'joint 1 turns this far away from an object it '
                                       'could not centre', unit='rad', min=0.0, max=6.3,
                                       live=True)
    # BCI mode: after an object could not be centred, both-hands MI does not select again until
    # joint 1 has turned this far or this long has passed; the user turns first
    bci_reselect_angle: float = param(0.1, 'joint 1 turn before both-hands re-selects an object '
                                      'that could not be centred', unit='rad', min=0.0,
                                      max=6.3, live=True)
    # BCI mode: both-hands must be decoded without a break for this long before it selects the
    # object in view; one misdecoded window of a left/right intent must not start a grasp. With
    # the default decoder 11-14 % of left/right windows read as both hands, in runs of 1 s or more
    # 1-2 times a minute (benchmarks/selection.py); 1.5 s keeps wrong objects from being selected
    bci_select_dwell: float = param(1.5, 'unbroken both-hands predictions before an object is '
                                    'selected', unit='s', min=0.0, max=10.0, live=True)
    bci_reselect_delay: float = param(3.0, 'after this long an object that could not be centred '
                                      'may be selected again', unit='s', min=0.0, max=60.0,
                                      live=True)
    # --- state 2: center object ----------------------------------------------------------------
    center_gain_joint1: float = param(1.5, 'joint 1 velocity per unit normalised x error '
                                      '(error / width)', unit='rad/s', min=0.0, max=10.0,
                                      live=True)
    center_gain_joint5: float = param(1.5, 'joint 5 velocity per unit normalised y error '
                                      '(error / height)', unit='rad/s', min=0.0, max=10.0,
                                      live=True)
    center_sign_joint1: float = param(-1.0, 'object right of centre -> turn right (joint 1 '
                                      'negative)', min=-1.0, max=1.0, live=True)
    center_sign_joint5: float = param(1.0, 'object below centre -> tilt the camera down',
                                      min=-1.0, max=1.0, live=True)
    center_tolerance: float = param(0.04, 'normalised error counted as centred', min=0.001,
                                    max=0.5, live=True)
    center_hold_time: float = param(0.2, 'centred this long before leaving state 2', unit='s',
                                    min=0.0, max=10.0, live=True)
    recenter_threshold: float = param(0.18, 'normalised error in states 3/4 that enters state 2',
                                      min=0.001, max=1.0, live=True)
    center_timeout: float = param(10.0, 'then go on anyway (object still visible)', unit='s',
                                  min=0.1, max=120.0, live=True)
    # --- state 3: initial approach -------------------------------------------------------------
    approach_joint: int = param(2, 'joint (1-based) that moves the long arm', min=1, max=7)
    approach_sign: float = param(1.0, 'sign of the approach joint velocity that goes forward',
                                 min=-1.0, max=1.0, live=True)
    approach_gain: float = param(0.2, 'approach joint velocity per unit certainty',
                                 unit='rad/s', min=0.0, max=3.0, live=True)
    retreat_gain: float = param(0.2, 'backwards velocity per unit certainty (both feet)',
                                unit='rad/s', min=0.0, max=3.0, live=True)
    turn_gain: float = param(0.3, 'joint 1 velocity per unit certainty (left/right)',
                             unit='rad/s', min=0.0, max=3.0, live=True)
    default_approach_velocity: float = param(0.12, 'approach velocity with no class above the '
                                             'threshold, and in autonomous mode', unit='rad/s',
                                             min=0.0, max=3.0, live=True)
    approach_center_gain: float = param(1.0, 'centring gain (x joint 1, y joint 5) while '
                                        'approaching', min=0.0, max=10.0, live=True)
    final_approach_pixel_fraction: float = param(0.15, 'image fraction the object fills when '
                                                 'the final approach starts', min=0.0, max=1.0,
                                                 live=True)
    final_approach_distance: float = param(0.40, 'camera-object distance that starts the final '
                                           'approach', unit='m', min=0.0, max=5.0, live=True)
    object_lost_timeout: float = param(1.5, 'without the object of interest this long -> back '
                                       'to search', unit='s', min=0.0, max=60.0, live=True)
    # --- state 4: final approach (grasp policy) ------------------------------------------------
    ik_gain: float = param(4.0, 'joint velocity = gain * (IK target - position)', unit='1/s',
                           min=0.01, max=100.0, live=True)
    joint_tolerance: float = param(0.01, 'IK target reached', unit='rad', min=0.0001, max=0.5,
                                   live=True)
    cartesian_speed: float = param(0.12, 'tool speed along straight segments', unit='m/s',
                                   min=0.001, max=1.0, live=True)
    settle_time: float = param(0.3, 'still before a depth measurement', unit='s', min=0.0,
                               max=10.0, live=True)
    measure_frames: int = param(3, 'camera frames whose median position is one measurement (a '
                                'noisy depth camera scatters)', min=1, max=30, live=True)
    refine_max_correction: float = param(0.15, 'larger top-view corrections are rejected',
                                         unit='m', min=0.0, max=1.0, live=True)
    max_refinements: int = param(2, 'top-view re-measurements before descending', min=0, max=20,
                                 live=True)
    table_height: float = param(0.0, 'z of the surface the objects stand on', unit='m',
                                min=-2.0, max=2.0, live=True)
    min_reach: float = param(0.12, 'objects closer to the base axis are not grasped', unit='m',
                             min=0.0, max=5.0, live=True)
    max_reach: float = param(0.85, 'objects farther from the base axis are not grasped',
                             unit='m', min=0.0, max=5.0, live=True)
    # an arm folded near its base cannot hold the tool vertical over a near object (the
    # Panda's elbow at its limit, 0.20 m from the base axis): the tool then leans back
    max_approach_tilt: float = param(0.45, 'largest lean of the tool from vertical, its tip '
                                     'towards the base, where no vertical grasp pose exists',
                                     unit='rad', min=0.0, max=1.2, live=True)
    segment_timeout: float = param(8.0, 'for one motion segment', unit='s', min=0.1, max=120.0,
                                   live=True)
    # a velocity command runs on until the next one or the driver's own timeout (and the arm
    # coasts for its lag), and the joint states it was computed from are already old: the
    # straight moves of states 4-6 never go faster than the distance left (from where the
    # commands sent since those states put the tool) over timeout + lag, and the joint-space
    # moves use a gain of at most 1 / (age + timeout + lag), so a late tick or an old state
    # cannot carry the tool past its goal (the table)
    driver_command_timeout: float = param(0.25, "how long the arm driver runs a velocity command "
                                          "without a newer one (the simulator's "
                                          'command_timeout)', unit='s', min=0.0, max=10.0,
                                          live=True)
    driver_velocity_lag: float = param(0.05, "time constant of the arm's response to a new "
                                       'velocity (the realism profile: 50 ms): the arm coasts '
                                       'about this long at its old speed after a stop',
                                       unit='s', min=0.0, max=10.0, live=True)
    # the fingertips reach 0.025 m below the grasp point and would stall on the table
    min_tcp_height: float = param(0.03, 'lowest grasp point above the table', unit='m', min=0.0,
                                  max=1.0, live=True)
    # per shape: pre-grasp height above the object top, grasp height as a fraction of the
    # object height from the table plus an offset (a sphere is held with the fingertips at its
    # equator, not squeezed upwards from below), object size used for the depth-surface
    # correction, wrist yaw offset relative to the approach direction, closing force
    cube_approach_height: float = param(0.10, 'cube: pre-grasp height above the object top',
                                        unit='m', min=0.0, max=1.0, live=True)
    cube_grasp_height_fraction: float = param(0.5, 'cube: grasp height as a fraction of the '
                                              'object height', min=0.0, max=1.0, live=True)
    cube_grasp_height_offset: float = param(0.0, 'cube: added to the grasp height', unit='m',
                                            min=-0.5, max=0.5, live=True)
    cube_size: float = param(0.05, 'cube: object size for the depth-surface correction',
                             unit='m', min=0.0, max=1.0, live=True)
    cube_wrist_yaw: float = param(0.0, 'cube: wrist yaw offset from the approach direction',
                                  unit='rad', min=-3.15, max=3.15, live=True)
    cube_close_force: float = param(40.0, 'cube: closing force', unit='N', min=0.0, max=500.0,
                                    live=True)
    cylinder_approach_height: float = param(0.10, 'cylinder: pre-grasp height above the object '
                                            'top', unit='m', min=0.0, max=1.0, live=True)
    cylinder_grasp_height_fraction: float = param(0.5, 'cylinder: grasp height as a fraction of '
                                                  'the object height', min=0.0, max=1.0,
                                                  live=True)
    cylinder_grasp_height_offset: float = param(0.0, 'cylinder: added to the grasp height',
                                                unit='m', min=-0.5, max=0.5, live=True)
    cylinder_size: float = param(0.05, 'cylinder: object size for the depth-surface correction',
                                 unit='m', min=0.0, max=1.0, live=True)
    cylinder_wrist_yaw: float = param(0.0, 'cylinder: wrist yaw offset from the approach '
                                      'direction', unit='rad', min=-3.15, max=3.15, live=True)
    cylinder_close_force: float = param(40.0, 'cylinder: closing force', unit='N', min=0.0,
                                        max=500.0, live=True)
    sphere_approach_height: float = param(0.10, 'sphere: pre-grasp height above the object top',
                                          unit='m', min=0.0, max=1.0, live=True)
    sphere_grasp_height_fraction: float = param(0.6, 'sphere: grasp height as a fraction of the '
                                                'object height', min=0.0, max=1.0, live=True)
    sphere_grasp_height_offset: float = param(0.015, 'sphere: added to the grasp height',
                                              unit='m', min=-0.5, max=0.5, live=True)
    sphere_size: float = param(0.05, 'sphere: object size for the depth-surface correction',
                               unit='m', min=0.0, max=1.0, live=True)
    sphere_wrist_yaw: float = param(0.0, 'sphere: wrist yaw offset from the approach direction',
                                    unit='rad', min=-3.15, max=3.15, live=True)
    sphere_close_force: float = param(30.0, 'sphere: closing force', unit='N', min=0.0,
                                      max=500.0, live=True)
    # --- state 5: grasp ------------------------------------------------------------------------
    gripper_open_position: float = param(0.0, 'gripper command for open (0 open .. 1 closed)',
                                         min=0.0, max=1.0, live=True)
    gripper_closed_position: float = param(1.0, 'gripper command for closed', min=0.0, max=1.0,
                                           live=True)
    close_timeout: float = param(2.0, 'to reach contact', unit='s', min=0.01, max=60.0,
                                 live=True)
    stall_rate: float = param(0.05, 'opening change below which the fingers have stalled',
                              unit='1/s', min=0.0, max=10.0, live=True)
    grip_squeeze: float = param(0.15, 'closure (0..1) held past the contact point; 0: full '
                                'close', min=0.0, max=1.0, live=True)
    contact_settle_time: float = param(0.05, 'all fingers touch this long before the closing '
                                       'stops', unit='s', min=0.0, max=10.0, live=True)
    contact_min_travel: float = param(0.05, 'closure (0..1) the fingers travel after the '
                                      'closing began before a load counts as contact (a load '
                                      'before is not the object: e.g. open fingertips on the '
                                      'table)', min=0.0, max=1.0, live=True)
    contact_min_force: float = param(1.0, 'finger force that counts as contact', unit='N',
                                     min=0.0, max=500.0, live=True)
    min_fingers_in_contact: int = param(3, 'fingers that must touch for a firm grasp (contact '
                                        'sensing)', min=1, max=10, live=True)
    # once lifted, what carries the object is what counts: a sphere off-centre in the hand (a
    # camera a few mm off its calibration) rides on two fingers; opening on it dropped it
    min_fingers_holding: int = param(2, 'loaded fingers after the lift for the object to count '
                                     'as held (fewer: it slipped)', min=1, max=10, live=True)
    # a finger closing freely needs < 0.1 N m, one squeezing an object its limit of 1.2-2.4 N m.
    # A real hand cannot tell the object from the table by contact, so the grasp check counts
    # loaded fingers; 0 uses the contact flags instead (a simulator's "touches an object")
    finger_contact_effort: float = param(0.4, 'finger motor effort that means "this finger '
                                         'pushes on something"; 0 uses the contact flags',
                                         unit='N m', min=0.0, max=100.0, live=True)
    # a parallel-jaw gripper (the xArm's) reports its jaw position, not an effort per finger:
    # the jaws stopping apart on the full closing command is the grasp, closing through is a miss
    grasp_check: str = param('effort', 'how a closed gripper is judged to hold: effort or '
                             'contacts (loaded fingers, finger_contact_effort) or width (the '
                             "jaws stop apart); the robot description's, with robot:=",
                             live=True)
    closed_empty_opening: float = param(0.05, 'opening (0 closed .. 1 open) below which the hand '
                                        'is empty', min=0.0, max=1.0, live=True)
    lift_height: float = param(0.12, 'lift after closing', unit='m', min=0.0, max=1.0,
                               live=True)
    lift_check_time: float = param(0.3, 'held still after the lift before checking', unit='s',
                                   min=0.0, max=10.0, live=True)
    grasp_retries: int = param(1, 're-grasps after a slip or a missed closure', min=0, max=10,
                               live=True)
    grasp_hold_time: float = param(0.5, 'after a good check before returning (paper: several '
                                   's)', unit='s', min=0.0, max=60.0, live=True)
    # --- state 6: return to start --------------------------------------------------------------
    return_gain: float = param(1.0, 'joint velocity = gain * (home - position)', unit='1/s',
                               min=0.01, max=100.0, live=True)
    return_tolerance: float = param(0.05, 'home reached, per joint', unit='rad', min=0.001,
                                    max=1.0, live=True)
    return_timeout: float = param(20.0, 'to reach home', unit='s', min=0.1, max=600.0,
                                  live=True)
    return_velocity_holding: float = param(0.5, 'per-joint velocity limit while carrying an '
                                           'object', unit='rad/s', min=0.01, max=3.0, live=True)
    return_acceleration: float = param(1.0, 'speed-up limit per joint during the return (no '
                                       'jerk; lower of this and max_joint_acceleration)',
                                       unit='rad/s^2', min=0.01, max=100.0, live=True)
    return_lift_height: float = param(0.25, 'carrying, the hand first rises straight to this '
                                      'height', unit='m', min=0.0, max=2.0, live=True)

    def __post_init__(self) -> None:
        if self.robot:
            self.apply_robot()
        self.validate()

    def apply_robot(self) -> None:
        """Set the robot parameters (:data:`ROBOT_PARAMETERS`) and ``grasp_check`` from the
        robot description ``robot``; a bad description raises its one-line error."""
        description = load_robot(self.robot)
        # the description's package:// URI as it is (the node resolves it), else the file
        self.urdf_file = description.urdf_uri if description.urdf_uri.startswith('package://') \
            else str(description.urdf)
        self.tool_link = description.tcp.link
        self.camera_link = description.camera.link
        self.joint_names = list(description.arm_joints)
        self.home_position = list(description.home_pose)
        self.joint_lower_limits = list(description.lower)
        self.joint_upper_limits = list(description.upper)
        self.max_joint_velocity = list(description.max_velocity)
        if len(self.max_joint_acceleration) != len(self.joint_names) \
                and len(set(self.max_joint_acceleration)) == 1:
            # one limit for every joint (the default): as many entries as the arm has joints
            self.max_joint_acceleration = self.max_joint_acceleration[:1] * len(self.joint_names)
        self.grasp_check = description.gripper.grasp_check
        for name, value in description.grasp:
            self._set_grasp(name, value, description.name)

    def _set_grasp(self, name: str, value: float, robot: str) -> None:
        """One per-shape parameter from a robot's ``grasp:`` (its hand's way of holding). It
        replaces the default only: a value given otherwise (a parameter file, -p, a live change)
        wins over the hand's."""
        fields = {f.name: f for f in dataclasses.fields(self)}
        if name.split('_', 1)[0] not in SHAPES or name not in fields:
            msg = (f"The robot {robot!r} sets the grasp parameter {name!r}, which the controller "
                   f"does not have; use a per-shape parameter <{'|'.join(SHAPES)}>_<name> of "
                   'config/param/fsm.yaml (e.g. sphere_grasp_height_fraction).')
            raise FsmError(msg)
        try:
            check_value(type(self), name, value)
        except ParameterError as exc:
            msg = f"The robot {robot!r}'s grasp: section: {exc}"
            raise FsmError(msg) from None
        if getattr(self, name) == fields[name].default:
            setattr(self, name, value)

    # ---------------------------------------------------------------------------------------
    def shape_value(self, shape: str, name: str) -> float:
        """The per-shape parameter ``<shape>_<name>``; unknown shapes use the cube's value."""
        key = f'{shape}_{name}' if shape in SHAPES else f'cube_{name}'
        return float(getattr(self, key))

    def validate(self) -> None:
        """Raise :class:`FsmError` naming the first bad parameter and how to fix it."""
        check_command_interface(self.command_interface)
        if self.grasp_check not in GRASP_CHECKS:
            msg = (f"The parameter 'grasp_check' is {self.grasp_check!r}; use one of "
                   f"{', '.join(GRASP_CHECKS)}.")
            raise FsmError(msg)
        n = len(self.joint_names)
        if n not in (6, 7):
            msg = (f"The parameter 'joint_names' lists {n} joints; the controller drives arms of "
                   '6 or 7 joints: list them base to wrist (or set robot:= a description).')
            raise FsmError(msg)
        for name in ('home_position', 'joint_lower_limits', 'joint_upper_limits',
                     'max_joint_velocity', 'max_joint_acceleration'):
            values = getattr(self, name)
            if len(values) != n:
                msg = (f"The parameter '{name}' must have {n} entries (one per arm joint in "
                       f"'joint_names'), got {len(values)}; give one per joint.")
                raise FsmError(msg)
        for i, (lo, hi) in enumerate(zip(self.joint_lower_limits, self.joint_upper_limits,
                                         strict=True)):
            if not lo < hi:
                msg = (f'Joint {i + 1} has lower limit {lo} >= upper limit {hi} rad; set '
                       "'joint_lower_limits' below 'joint_upper_limits'.")
                raise FsmError(msg)
        positive = ('lock_duration', 'watchdog_timeout', 'camera_timeout', 'center_tolerance',
                    'ik_gain', 'cartesian_speed', 'return_gain', 'return_tolerance',
                    'control_period', 'joint_tolerance', 'close_timeout', 'segment_timeout')
        for name in positive:
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                msg = f"The parameter '{name}' must be a positive number, {value!r} is invalid."
                raise FsmError(msg)
        for name, unit in (('max_joint_velocity', 'rad/s'), ('max_joint_acceleration',
                                                             'rad/s^2')):
            values = getattr(self, name)
            if not all(math.isfinite(v) and v > 0 for v in values):
                msg = f"Every entry of '{name}' must be > 0 {unit}, got {values}."
                raise FsmError(msg)
        if not 1 <= self.approach_joint <= n:
            msg = (f"The parameter 'approach_joint' must be a joint number 1..{n}, got "
                   f'{self.approach_joint}.')
            raise FsmError(msg)
        if self.recenter_threshold <= self.center_tolerance:
            msg = (f"'recenter_threshold' ({self.recenter_threshold}) must exceed "
                   f"'center_tolerance' ({self.center_tolerance}), or the controller would "
                   'oscillate between centring and approaching.')
            raise FsmError(msg)
        if self.measure_frames < 1:
            msg = (f"'measure_frames' must be >= 1 camera frame, got {self.measure_frames}; "
                   'use 3 with a noisy depth camera.')
            raise FsmError(msg)
        if self.resume_after_stale not in RESUME_MODES:
            msg = (f"'resume_after_stale' is {self.resume_after_stale!r}; use one of "
                   f"{', '.join(RESUME_MODES)}.")
            raise FsmError(msg)
        if self.answer_pair != 'auto':
            from mindgrasp_common.answer_pair import answer_pair
            from mindgrasp_common.errors import CommonError

            try:
                answer_pair(self.answer_pair)
            except CommonError as exc:
                raise FsmError(f"The parameter 'answer_pair': {exc}") from None
        if self.grasp_retries < 0:
            msg = f"'grasp_retries' must be >= 0, got {self.grasp_retries}."
            raise FsmError(msg)

    # ---------------------------------------------------------------------------------------
    @classmethod
    def names(cls) -> list[str]:
        """All parameter names, in declaration order."""
        return [f.name for f in dataclasses.fields(cls)]

    def to_dict(self) -> dict[str, Any]:
        """Parameters as a plain dict (lists copied)."""
        return {k: (list(v) if isinstance(v, list) else v)
                for k, v in dataclasses.asdict(self).items()}

    @classmethod
    def from_dict(cls, values: Mapping[str, Any]) -> FsmParams:
        """Build from a name -> value mapping; unknown names raise :class:`FsmError`."""
        known = set(cls.names())
        unknown = sorted(set(values) - known)
        if unknown:
            msg = (f'Unknown controller parameter(s) {unknown}; check the spelling against '
                   'config/param/fsm.yaml.')
            raise FsmError(msg)
        defaults = cls()
        kwargs: dict[str, Any] = {}
        for name, value in values.items():
            default = getattr(defaults, name)
            if isinstance(default, bool):
                kwargs[name] = bool(value)
            elif isinstance(default, int):
                kwargs[name] = int(value)
            elif isinstance(default, float):
                kwargs[name] = float(value)
            elif isinstance(default, list):
                kwargs[name] = [type(default[0])(v) if default else v for v in value]
            else:
                kwargs[name] = value
        return cls(**kwargs)

    @classmethod
    def from_yaml(cls, path: str | Path, node_name: str = 'fsm') -> FsmParams:
        """Load ``<node_name>: ros__parameters:`` (or ``/**``) from a ROS parameter file."""
        import yaml

        path = Path(path)
        try:
            data = yaml.safe_load(path.read_text(encoding='utf-8')) or {}
        except (OSError, yaml.YAMLError) as exc:
            msg = (f'Cannot read the controller parameter file {path}: '
                   f'{yaml_error_text(exc)}. Give a ROS YAML file.')
            raise FsmError(msg) from exc
        for key in (node_name, f'/{node_name}', '/**'):
            section = data.get(key)
            if isinstance(section, dict) and 'ros__parameters' in section:
                return cls.from_dict(section['ros__parameters'] or {})
        msg = (f"{path} has no '{node_name}: ros__parameters:' section; add one (see "
               'config/param/fsm.yaml).')
        raise FsmError(msg)


def default_params_path() -> Path:
    """This package's ``param/fsm.yaml``."""
    return resource_path('mindgrasp_fsm', 'param', 'fsm.yaml')
