"""The shipped MIndGrasp arm as module constants, read from its robot description
(``config/robots/mindgrasp_arm.yaml`` and the URDF beside it; see
:mod:`mindgrasp_common.robot_description`), so there is one definition of each value.

Code that works with any arm takes a :class:`~mindgrasp_common.robot_description.RobotDescription`
(``robot:=NAME|path.yaml``); these constants remain for the shipped arm's defaults while the rest
of the code moves to the description object. Angles in rad, velocities in rad/s, efforts in N m.
"""

from __future__ import annotations

from mindgrasp_common.robot_description import RobotDescription, load_robot

__all__ = [
    'ARM_EFFORT', 'ARM_JOINTS', 'ARM_LOWER_LIMITS', 'ARM_MAX_VELOCITY', 'ARM_UPPER_LIMITS',
    'DEFAULT_ROBOT', 'FINGER_CLOSED', 'FINGER_JOINTS', 'FINGER_LOWER_LIMIT', 'FINGER_OPEN',
    'FINGER_UPPER_LIMIT', 'HOME_POSE', 'SHIPPED_ARM', 'URDF_URI',
]

#: name of the robot used when none is given (``robot:=mindgrasp_arm``)
DEFAULT_ROBOT = 'mindgrasp_arm'
#: the shipped arm's description
SHIPPED_ARM: RobotDescription = load_robot(DEFAULT_ROBOT)

#: names of the six arm joints, base to wrist
ARM_JOINTS: tuple[str, ...] = SHIPPED_ARM.arm_joints
#: names of the three finger joints (thumb first)
FINGER_JOINTS: tuple[str, ...] = SHIPPED_ARM.gripper.joints

#: position limits of the arm joints (rad), in the order of :data:`ARM_JOINTS` (the URDF's)
ARM_LOWER_LIMITS: tuple[float, ...] = SHIPPED_ARM.lower
ARM_UPPER_LIMITS: tuple[float, ...] = SHIPPED_ARM.upper
#: velocity limits of the arm joints (rad/s)
ARM_MAX_VELOCITY: tuple[float, ...] = SHIPPED_ARM.max_velocity
#: effort limits of the arm joints (N m)
ARM_EFFORT: tuple[float, ...] = SHIPPED_ARM.effort

#: position limits of each finger joint (rad); the three fingers share them
FINGER_LOWER_LIMIT: float = SHIPPED_ARM.gripper.limits[0].lower
FINGER_UPPER_LIMIT: float = SHIPPED_ARM.gripper.limits[0].upper
#: finger joint angles (rad) of the open (closure 0) and closed (closure 1) hand, inside the limits
FINGER_OPEN: float = SHIPPED_ARM.gripper.open[0]
FINGER_CLOSED: float = SHIPPED_ARM.gripper.closed[0]

#: home pose (rad): long arm up, short arm forward, wrist pitched so the camera looks down at the
#: objects 0.5 m in front of the base (the paper: "all joints straight except joint 5")
HOME_POSE: tuple[float, ...] = SHIPPED_ARM.home_pose

#: the robot description's URDF (written by ``python -m mindgrasp_sim.robot_model``)
URDF_URI: str = SHIPPED_ARM.urdf_uri
