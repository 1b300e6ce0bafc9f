"""Where an arm points, read from its first joint's angle and its robot description (a subject
that watches the arm reads its heading this way)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from scipy.spatial.transform import Rotation

from mindgrasp_common.robot_description import load_robot
from mindgrasp_common.robot_types import RobotDescription, RobotDescriptionError
from mindgrasp_common.urdf import read_urdf

__all__ = ['ArmHeading', 'base_turn_direction']


@dataclass(frozen=True)
class ArmHeading:
    """Where the arm points (rad, counter-clockwise seen from above, 0 along the base's x axis)
    from the angle of one joint, its first: ``direction * (angle - home)``.

    Exact for the turn of a vertical first joint from a home pose that looks straight ahead, as
    every shipped robot's does (``tests/common/test_robot_description.py`` checks the camera).
    A subject that watches the arm reads its heading this way: the Jaco's first joint turns the
    other way round and sits at 2.93 rad at home, so its angle alone is no heading.
    """

    joint: str = ''          # '' = the first joint of /joint_states
    direction: float = 1.0   # base_turn_direction
    home: float = 0.0        # the joint's angle at home (rad)

    @classmethod
    def of_robot(cls, robot: str | Path | RobotDescription) -> ArmHeading:
        """The heading of ``robot`` (a :func:`load_robot` spec)."""
        robot = load_robot(robot)
        return cls(robot.arm_joints[0], base_turn_direction(robot), robot.home_pose[0])

    def __call__(self, angle: float) -> float:
        """Heading (rad) at the joint ``angle`` (rad)."""
        return self.direction * (angle - self.home)


def base_turn_direction(robot: RobotDescription) -> float:
    """+1.0 when a positive angle of the arm's first joint turns the arm counter-clockwise seen
    from above (its axis points up, in the base frame), -1.0 when the axis points down (the
    Jaco's). The axis is taken through the fixed and first-joint origins from the URDF's root."""
    _, joints = read_urdf(robot.urdf, f'robot {robot.name!r}')
    by_child = {j.child: j for j in joints.values()}
    joint = joints.get(robot.arm_joints[0])
    if joint is None:
        msg = (f'robot {robot.name!r}: the joint {robot.arm_joints[0]!r} is not in '
               f'{robot.urdf}; check the arm joints.')
        raise RobotDescriptionError(msg)
    rotation = Rotation.from_euler('xyz', joint.rpy)     # URDF rpy: fixed axes
    link = joint.parent
    while link in by_child:                              # up to the root (fixed joints)
        above = by_child[link]
        rotation = Rotation.from_euler('xyz', above.rpy) * rotation
        link = above.parent
    return 1.0 if float(rotation.apply(joint.axis)[2]) >= 0.0 else -1.0
