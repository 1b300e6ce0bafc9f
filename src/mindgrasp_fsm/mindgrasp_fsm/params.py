"""Gains and thresholds of the grasp controller, loadable from a ROS-format parameter file.

Every number the controller uses lives here, with its unit; ``mindgrasp_fsm/param/fsm.yaml`` holds
the same names under ``fsm: ros__parameters:``. Per-shape values are flat names prefixed by the
shape (``cube_approach_height``), so they are plain ROS parameters.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mindgrasp_common.resources import resource_path
from mindgrasp_common.robot import (
    ARM_JOINTS,
    ARM_LOWER_LIMITS,
    ARM_MAX_VELOCITY,
    ARM_UPPER_LIMITS,
    HOME_POSE,
    URDF_URI,
)
from mindgrasp_fsm.errors import FsmError

SHAPES = ('cube', 'cylinder', 'sphere')


@dataclass
class FsmParams:
    """Parameters of :class:`mindgrasp_fsm.grasp_fsm.GraspFsm` (SI units: s, rad, rad/s, m, N)."""

    # --- general -------------------------------------------------------------------------------
    autonomous: bool = False            # no BCI: search left, approach and grasp on vision alone
    urdf_file: str = URDF_URI           # URDF for FK / IK: a path or a package:// URI
    tool_link: str = 'tcp'              # grasp point between the fingertips
    camera_link: str = 'camera_color_optical_frame'
    joint_names: list[str] = field(default_factory=lambda: list(ARM_JOINTS))
    # start pose (rad) of the URDF: long arm up, short arm forward, wrist
    # pitched so the camera looks down at the objects (the paper: all straight except joint 5)
    home_position: list[float] = field(default_factory=lambda: list(HOME_POSE))  # rad
    joint_lower_limits: list[float] = field(default_factory=lambda: list(ARM_LOWER_LIMITS))  # rad
    joint_upper_limits: list[float] = field(default_factory=lambda: list(ARM_UPPER_LIMITS))  # rad
    joint_limit_margin: float = 0.02    # rad kept clear of each limit
    max_joint_velocity: list[float] = field(default_factory=lambda: list(ARM_MAX_VELOCITY))  # rad/s
    control_period: float = 0.02        # s, nominal tick (used to stop short of joint limits)
    lock_duration: float = 1.0          # s all joints held between states (paper: locks)
    watchdog_timeout: float = 0.3       # s, oldest acceptable prediction / joint state
    camera_timeout: float = 0.5         # s without detections -> hold still
    # --- BCI -----------------------------------------------------------------------------------
    certainty_threshold: float = 0.5    # below: the default slow approach in state 3
    certainty_cap: float = 2.0          # certainty is unbounded (Eq. 1); velocities scale to this
    # --- state 1: object search ----------------------------------------------------------------
    search_gain: float = 0.3            # rad/s of joint 1 per unit certainty (left +, right -)
    autonomous_search_velocity: float = 0.8  # rad/s of joint 1 (turn left)
    # rad added to joint 5 of home for each sweep of the autonomous search (0.15: the view spans
    # 0.15-0.75 m from the base)
    autonomous_search_tilts: list[float] = field(default_factory=lambda: [0.15, 0.15, 0.3, 0.0])
    search_confirm_time: float = 0.2    # s an object must be seen before it is taken
    search_ignore_angle: float = 1.0    # rad joint 1 turns away from an object it could not centre
    # BCI mode: after an object could not be centred, both-hands MI does not select again until
    # joint 1 has turned this far (rad) or this long has passed (s); the user turns first
    bci_reselect_angle: float = 0.1
    # BCI mode: both-hands must be decoded without a break for this long (s) before it selects
    # the object in view; one misdecoded window of a left/right intent must not start a grasp
    bci_select_dwell: float = 0.5
    bci_reselect_delay: float = 3.0
    # --- state 2: center object ----------------------------------------------------------------
    center_gain_joint1: float = 1.5     # rad/s per unit normalised x error (error / width)
    center_gain_joint5: float = 1.5     # rad/s per unit normalised y error (error / height)
    center_sign_joint1: float = -1.0    # object right of centre -> turn right (joint 1 negative)
    center_sign_joint5: float = 1.0     # object below centre -> tilt camera down
    center_tolerance: float = 0.04      # normalised error counted as centred
    center_hold_time: float = 0.2       # s centred before leaving state 2
    recenter_threshold: float = 0.18    # normalised error in states 3/4 that enters state 2
    center_timeout: float = 10.0        # s; then go on anyway (object still visible)
    # --- state 3: initial approach -------------------------------------------------------------
    approach_joint: int = 2             # joint (1-based) that moves the long arm
    approach_sign: float = 1.0          # sign of the approach joint velocity that goes forward
    approach_gain: float = 0.2          # rad/s of the approach joint per unit certainty
    retreat_gain: float = 0.2           # rad/s backwards per unit certainty (both feet)
    turn_gain: float = 0.3              # rad/s of joint 1 per unit certainty (left/right)
    default_approach_velocity: float = 0.12  # rad/s, no class above threshold / autonomous
    approach_center_gain: float = 1.0   # centring gain (x joint 1, y joint 5) while approaching
    final_approach_pixel_fraction: float = 0.15  # object fills this much -> final approach
    final_approach_distance: float = 0.40  # m camera-object distance -> final approach
    object_lost_timeout: float = 1.5    # s without the object of interest -> back to search
    # --- state 4: final approach (grasp policy) ------------------------------------------------
    ik_gain: float = 4.0                # 1/s, joint velocity = gain * (IK target - position)
    joint_tolerance: float = 0.01       # rad, IK target reached
    cartesian_speed: float = 0.12       # m/s of the tool along straight segments
    settle_time: float = 0.3            # s still before a depth measurement
    refine_max_correction: float = 0.15  # m; larger top-view corrections are rejected
    max_refinements: int = 2            # top-view re-measurements before descending
    table_height: float = 0.0           # m, z of the surface the objects stand on
    min_reach: float = 0.12             # m, objects closer to the base axis are not grasped
    max_reach: float = 0.85             # m
    segment_timeout: float = 8.0        # s for one motion segment
    min_tcp_height: float = 0.03        # m above the table (the fingertips reach 0.025 m below
    # the grasp point and would stall on the table)
    # per shape: pre-grasp height above the object top, grasp height as a fraction of the
    # object height from the table plus an offset (m; a sphere is held with the fingertips at its
    # equator, not squeezed upwards from below), object size (m) used for the depth-surface
    # correction, wrist yaw offset (rad) relative to the approach direction, closing force (N)
    cube_approach_height: float = 0.10
    cube_grasp_height_fraction: float = 0.5
    cube_grasp_height_offset: float = 0.0
    cube_size: float = 0.05
    cube_wrist_yaw: float = 0.0
    cube_close_force: float = 40.0
    cylinder_approach_height: float = 0.10
    cylinder_grasp_height_fraction: float = 0.5
    cylinder_grasp_height_offset: float = 0.0
    cylinder_size: float = 0.05
    cylinder_wrist_yaw: float = 0.0
    cylinder_close_force: float = 40.0
    sphere_approach_height: float = 0.10
    sphere_grasp_height_fraction: float = 0.6
    sphere_grasp_height_offset: float = 0.015
    sphere_size: float = 0.05
    sphere_wrist_yaw: float = 0.0
    sphere_close_force: float = 30.0
    # --- state 5: grasp ------------------------------------------------------------------------
    gripper_open_position: float = 0.0   # command for open (0 open .. 1 closed)
    gripper_closed_position: float = 1.0
    close_timeout: float = 2.0          # s to reach contact
    stall_rate: float = 0.05            # 1/s opening change below which the fingers have stalled
    grip_squeeze: float = 0.15          # closure (0..1) held past the contact point; 0: full close
    contact_settle_time: float = 0.05   # s all fingers touch before the closing stops
    contact_min_force: float = 1.0      # N finger force that counts as contact
    min_fingers_in_contact: int = 3     # fingers that must touch for a firm grasp (contact sensing)
    # N m effort of a finger motor that means "this finger pushes on something" (a finger closing
    # freely needs < 0.1 N m, one squeezing an object its limit of 1.2-2.4 N m). A real hand
    # cannot tell the object from the table by contact, so the grasp check counts loaded
    # fingers; 0 uses the contact flags instead (a simulator's "touches an object")
    finger_contact_effort: float = 0.4
    closed_empty_opening: float = 0.05  # opening (0 closed .. 1 open) below which the hand is empty
    lift_height: float = 0.12           # m lift after closing
    lift_check_time: float = 0.3        # s held still after the lift before checking
    grasp_retries: int = 1              # re-grasps after a slip or a missed closure
    grasp_hold_time: float = 0.5        # s after a good check before returning (paper: several s)
    # --- state 6: return to start --------------------------------------------------------------
    return_gain: float = 1.0            # 1/s, joint velocity = gain * (home - position)
    return_tolerance: float = 0.05      # rad per joint
    return_timeout: float = 20.0        # s
    return_velocity_holding: float = 0.5  # rad/s per joint at most while carrying an object
    return_acceleration: float = 1.0    # rad/s^2 ramp at the start of the return (no jerk)
    return_lift_height: float = 0.25    # m; carrying, the hand first rises straight to this height

    def __post_init__(self) -> None:
        self.validate()

    # ---------------------------------------------------------------------------------------
    def shape_value(self, shape: str, name: str) -> float:
        """The per-shape parameter ``<shape>_<name>``; unknown shapes use the cube's value."""
        key = f'{shape}_{name}' if shape in SHAPES else f'cube_{name}'
        return float(getattr(self, key))

    def validate(self) -> None:
        """Raise :class:`FsmError` naming the first bad parameter and how to fix it."""
        for name in ('joint_names', 'home_position', 'joint_lower_limits', 'joint_upper_limits',
                     'max_joint_velocity'):
            values = getattr(self, name)
            if len(values) != 6:
                msg = (f"The parameter '{name}' must have 6 entries (one per arm joint), got "
                       f'{len(values)}; list all six joints in mindgrasp_fsm/param/fsm.yaml.')
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
        if any(v <= 0 for v in self.max_joint_velocity):
            msg = (f"Every entry of 'max_joint_velocity' must be > 0 rad/s, got "
                   f'{self.max_joint_velocity}.')
            raise FsmError(msg)
        if not 1 <= self.approach_joint <= 6:
            msg = (f"The parameter 'approach_joint' must be a joint number 1..6, got "
                   f'{self.approach_joint}.')
            raise FsmError(msg)
        if self.recenter_threshold <= self.center_tolerance:
            msg = (f"'recenter_threshold' ({self.recenter_threshold}) must exceed "
                   f"'center_tolerance' ({self.center_tolerance}), or the controller would "
                   'oscillate between centring and approaching.')
            raise FsmError(msg)
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
                   'mindgrasp_fsm/param/fsm.yaml.')
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
            msg = f'Cannot read the controller parameter file {path}: {exc}. Give a ROS YAML file.'
            raise FsmError(msg) from exc
        for key in (node_name, f'/{node_name}', '/**'):
            section = data.get(key)
            if isinstance(section, dict) and 'ros__parameters' in section:
                return cls.from_dict(section['ros__parameters'] or {})
        msg = (f"{path} has no '{node_name}: ros__parameters:' section; add one (see "
               'mindgrasp_fsm/param/fsm.yaml).')
        raise FsmError(msg)


def default_params_path() -> Path:
    """This package's ``param/fsm.yaml``."""
    return resource_path('mindgrasp_fsm', 'param', 'fsm.yaml')
