"""ROS parameters of the sim node (``config/param/sim.yaml``; tests/ros/test_node_params.py checks
the file against the defaults)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from mindgrasp_common.robot_description import robot_choices
from mindgrasp_ros.params import param
from mindgrasp_sim.errors import SimError

__all__ = ['TIME_MODES', 'SimParams']

TIME_MODES = ('realtime', 'fast', 'lockstep')

@dataclass
class SimParams:
    """ROS parameters of the sim node (``param/sim.yaml``); read-only: the simulation is built at
    start, restart the node (or call /sim/load_scene) to change them."""

    scene: str = param('set_locations', 'scene name in config/scenes/ '
                       '(set_locations, random_locations) or a path')
    seed: int = param(0, 'random scenes: layout seed (same seed, same layout)', min=0)
    n_objects: int = param(-1, "random scenes: number of objects, -1 = the scene file's",
                           min=-1, max=100)
    physics_hz: float = param(240.0, 'physics rate; contacts are tuned for 240 Hz', unit='Hz',
                              min=10.0, max=10000.0)
    solver_iterations: int = param(50, "PyBullet's constraint solver iterations per physics "
                                   'step (contacts, joint motors)', min=1, max=1000)
    camera_width: int = param(128, 'eye-in-hand RGB-D camera width', unit='px', min=1, max=8192)
    camera_height: int = param(128, 'eye-in-hand RGB-D camera height', unit='px', min=1,
                               max=8192)
    camera_rate: float = param(10.0, 'camera frame rate (simulated time)', unit='Hz', min=0.1,
                               max=1000.0)
    camera_fov_deg: float = param(60.0, 'vertical field of view', unit='deg', min=1.0,
                                  max=179.0)
    camera_renderer: str = param('tiny', 'tiny (CPU TinyRenderer) or egl (OpenGL via EGL)',
                                 choices=('tiny', 'egl'))
    joint_state_rate: float = param(100.0, '/joint_states, /ee_pose, /gripper/* rate (simulated '
                                    'time)', unit='Hz', min=0.1, max=10000.0)
    objects_rate: float = param(2.0, '/sim/objects rate', unit='Hz', min=0.01, max=1000.0)
    time_mode: str = param('realtime', 'realtime, fast (publishes /clock) or lockstep '
                           '(/sim/step)')
    command_timeout: float = param(0.25, 'a velocity command older than this means zero '
                                   'velocity', unit='s', min=0.001, max=60.0)
    bad_command_hold: float = param(1.0, 'after a refused velocity command (NaN/inf, wrong '
                                    'length) the arm holds until none came for this long; also '
                                    'the gap that ends a burst of bad commands (one warning '
                                    'each)', unit='s', min=0.0, max=60.0)
    trainer_robot: bool = param(False, 'also simulate the green training robot under '
                                '/trainer_robot/')
    gui: bool = param(False, 'PyBullet window (needs a display)')
    duration: float = param(0.0, 'end after this long of the node\'s ROS time, as every node\'s '
                            'duration (the simulator is the clock, so wall time unless a '
                            'lock-step host sets its time); 0 = run until stopped',
                            unit='s', min=0.0)
    sim_duration: float = param(0.0, 'end after this many simulated seconds; 0 = no limit',
                                unit='s', min=0.0)
    success_height: float = param(0.22, '/task/result success: held object centre above this '
                                  'height', unit='m', min=0.0, max=10.0)
    frame_id: str = param('world', 'frame of /ee_pose and /sim/objects (the arm base is at its '
                          'origin)')
    max_catch_up: float = param(0.1, 'realtime: lag beyond this is skipped, not raced through '
                                '(the joint states are never older than this plus a stall; a '
                                'skip beyond 0.25 s, a stall, is warned)', unit='s', min=0.0,
                                max=60.0)
    tf_publish_frequency: float = param(20.0, 'most /tf messages per second, as '
                                        "robot_state_publisher's publish_frequency", unit='Hz',
                                        min=0.1, max=10000.0)
    scene_camera_rate: float = param(0.0, '/scene/image_raw, third-person view for the '
                                     'participant display; 0 = off', unit='Hz', min=0.0)
    scene_camera_width: int = param(320, 'scene camera width', unit='px', min=1, max=8192)
    scene_camera_height: int = param(240, 'scene camera height', unit='px', min=1, max=8192)
    realism: str = param('none', 'none, default or the path of a realism profile YAML (sensor '
                         'noise, physical spread)')
    realism_seed: int = param(0, 'seed of the realism draws (same seed, same noise)', min=0)
    robot: str = param('mindgrasp_arm', f'the arm: {robot_choices()} '
                       '(mindgrasp_common.robot_description)')

    def __post_init__(self) -> None:
        _check_params(dataclasses.asdict(self))


def _check_params(p: dict) -> None:
    if p['time_mode'] not in TIME_MODES:
        msg = f"Parameter 'time_mode' is {p['time_mode']!r}; use one of {list(TIME_MODES)}."
        raise SimError(msg)
    rate = p['scene_camera_rate']
    if not (isinstance(rate, (int, float)) and 0 <= rate <= p['physics_hz']):
        msg = (f"Parameter 'scene_camera_rate' must be 0 (off) or a rate up to 'physics_hz' "
               f'({p["physics_hz"]} Hz), got {rate!r}; the participant display uses 5-10 Hz.')
        raise SimError(msg)
    for name in ('joint_state_rate', 'objects_rate', 'command_timeout', 'physics_hz',
                 'tf_publish_frequency'):
        if not (isinstance(p[name], (int, float)) and p[name] > 0):
            msg = f"Parameter '{name}' must be a positive number, got {p[name]!r}."
            raise SimError(msg)
    if p['joint_state_rate'] > p['physics_hz']:
        msg = (f"Parameter 'joint_state_rate' ({p['joint_state_rate']} Hz) cannot exceed "
               f"'physics_hz' ({p['physics_hz']} Hz); lower it or raise physics_hz.")
        raise SimError(msg)
