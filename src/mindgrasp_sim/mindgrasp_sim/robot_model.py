"""URDF of the simulated assistive arm: a 6-DoF arm of the Hamlyn Active Arm kind with a
Jaco-like three-finger gripper and an eye-in-palm RGB-D camera.

No public model of the paper's arm exists, so this module writes one from a few dimensions
(:class:`ArmSpec`). The committed file ``config/robots/urdf/mindgrasp_arm.urdf`` is this module's
output (``python -m mindgrasp_sim.robot_model >
config/robots/urdf/mindgrasp_arm.urdf``); the arm and the hand also come apart
(``mindgrasp_arm_arm.urdf``, ``mindgrasp_hand.urdf``: ``python -m mindgrasp_sim.robot_model
--write config/robots/urdf``), the description ``mindgrasp_arm`` joins them again, and a test
checks that all three agree with this module.
Researchers can edit the spec, or load any URDF with the same link names.

Kinematics (all angles zero = arm pointing straight up, the x axis is "forward"):

- ``joint_1`` base yaw (z), shoulder ``joint_2`` pitch (y) at 0.20 m height,
- long arm 0.40 m to ``joint_3`` (pitch), 0.10 m to the elbow ``joint_4`` (pitch),
- short arm 0.28 m to the wrist pitch ``joint_5``, 0.05 m to the wrist roll ``joint_6``,
- palm (0.035 m) with three fingers on its face: a thumb on the +x side opposing two fingers on
  the -x side, each a rigid two-segment (0.055 m + 0.045 m, distal bent 0.5 rad inward) finger on
  one revolute joint that closes towards the palm axis, as in the Jaco's three-finger hand.
- ``camera_color_optical_frame`` in the palm centre, looking along the gripper (ROS optical
  convention: z forward, x right, y down); ``tcp`` 0.07 m in front of the palm face.

Positive pitch angles tilt the chain forward/down. Reach from the shoulder to the wrist is 0.78 m.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field

from mindgrasp_common.robot import (
    ARM_EFFORT,
    ARM_JOINTS,
    ARM_LOWER_LIMITS,
    ARM_MAX_VELOCITY,
    ARM_UPPER_LIMITS,
    FINGER_JOINTS,
    FINGER_LOWER_LIMIT,
    FINGER_UPPER_LIMIT,
)

__all__ = ['ARM_JOINTS', 'FILES', 'FINGER_JOINTS', 'ArmSpec', 'build_arm_urdf', 'build_hand_urdf',
           'build_urdf']


@dataclass
class ArmSpec:
    """Dimensions (m), masses (kg) and limits (rad, rad/s, N m) of the arm and gripper."""

    base_height: float = 0.10
    turret_height: float = 0.10
    long_arm: float = 0.40
    link3: float = 0.10
    short_arm: float = 0.28
    wrist: float = 0.05
    palm: float = 0.035
    palm_radius: float = 0.045
    finger_offset_x: float = 0.04     # finger joints from the palm axis
    finger_offset_y: float = 0.022    # the two opposing fingers sit at +/- this
    finger_proximal: float = 0.055
    finger_distal: float = 0.045
    finger_bend: float = 0.5          # distal segment bent inward (rad)
    finger_width: float = 0.018
    finger_thickness: float = 0.012
    tcp_offset: float = 0.07
    masses: tuple[float, ...] = (4.0, 1.2, 1.8, 0.5, 0.9, 0.3, 0.45, 0.04)
    lower: tuple[float, ...] = ARM_LOWER_LIMITS
    upper: tuple[float, ...] = ARM_UPPER_LIMITS
    velocity: tuple[float, ...] = ARM_MAX_VELOCITY
    effort: tuple[float, ...] = ARM_EFFORT
    finger_lower: float = FINGER_LOWER_LIMIT
    finger_upper: float = FINGER_UPPER_LIMIT
    finger_velocity: float = 1.5
    finger_effort: float = 1.2         # per finger (N m); the thumb gets twice this
    colour: tuple[float, float, float, float] = (0.85, 0.85, 0.88, 1.0)
    dark: tuple[float, float, float, float] = (0.18, 0.18, 0.2, 1.0)
    extra: dict = field(default_factory=dict)


def _cyl_inertia(m: float, r: float, h: float) -> tuple[float, float, float]:
    ixx = m * (3 * r * r + h * h) / 12.0
    return ixx, ixx, 0.5 * m * r * r


def _box_inertia(m: float, x: float, y: float, z: float) -> tuple[float, float, float]:
    return m * (y * y + z * z) / 12, m * (x * x + z * z) / 12, m * (x * x + y * y) / 12


def _f(v: float) -> str:
    return f'{v:.6g}'


def _vec(*vals: float) -> str:
    return ' '.join(_f(v) for v in vals)


def _inertial(m: float, com: tuple[float, float, float], diag: tuple[float, float, float]) -> str:
    return (
        f'    <inertial><origin xyz="{_vec(*com)}" rpy="0 0 0"/><mass value="{_f(m)}"/>'
        f'<inertia ixx="{_f(diag[0])}" ixy="0" ixz="0" iyy="{_f(diag[1])}" iyz="0" '
        f'izz="{_f(diag[2])}"/></inertial>\n'
    )


def _shape(kind: str, geom: str, xyz: tuple, rpy: tuple = (0, 0, 0), material: str = '') -> str:
    mat = f'<material name="{material}"/>' if material and kind == 'visual' else ''
    return (
        f'    <{kind}><origin xyz="{_vec(*xyz)}" rpy="{_vec(*rpy)}"/>'
        f'<geometry>{geom}</geometry>{mat}</{kind}>\n'
    )


def _cyl(r: float, h: float) -> str:
    return f'<cylinder radius="{_f(r)}" length="{_f(h)}"/>'


def _box(x: float, y: float, z: float) -> str:
    return f'<box size="{_vec(x, y, z)}"/>'


def _cyl_link(name: str, m: float, r: float, h: float, material: str = 'arm') -> str:
    """A link that is a cylinder of length h along +z from its joint, with a joint housing."""
    out = f'  <link name="{name}">\n'
    out += _inertial(m, (0, 0, h / 2), _cyl_inertia(m, r, h))
    out += _shape('visual', _cyl(r, h), (0, 0, h / 2), material=material)
    out += _shape('collision', _cyl(r * 0.9, max(h - 2.2 * r, 0.01)), (0, 0, h / 2))
    out += '  </link>\n'
    return out


def _joint(name: str, parent: str, child: str, xyz: tuple, axis: tuple, lo: float, hi: float,
           vel: float, eff: float, rpy: tuple = (0, 0, 0)) -> str:
    return (
        f'  <joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{_vec(*xyz)}" rpy="{_vec(*rpy)}"/><axis xyz="{_vec(*axis)}"/>'
        f'<limit lower="{_f(lo)}" upper="{_f(hi)}" velocity="{_f(vel)}" effort="{_f(eff)}"/>'
        f'<dynamics damping="0.05" friction="0.0"/></joint>\n'
    )


def _fixed(name: str, parent: str, child: str, xyz: tuple, rpy: tuple = (0, 0, 0)) -> str:
    return (
        f'  <joint name="{name}" type="fixed"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{_vec(*xyz)}" rpy="{_vec(*rpy)}"/></joint>\n'
    )


def _finger_link(spec: ArmSpec, name: str, inward: float) -> str:
    """A rigid two-segment finger; ``inward`` is +1 when closing moves the tip towards +x."""
    t, w = spec.finger_thickness, spec.finger_width
    lp, ld, bend = spec.finger_proximal, spec.finger_distal, spec.finger_bend
    m = spec.masses[7]
    dist_c = (inward * ld / 2 * math.sin(bend), 0.0, lp + ld / 2 * math.cos(bend))
    dist_rpy = (0.0, inward * bend, 0.0)
    out = f'  <link name="{name}">\n'
    out += _inertial(m, (0, 0, (lp + ld) / 2), _box_inertia(m, t, w, lp + ld))
    for kind in ('visual', 'collision'):
        out += _shape(kind, _box(t, w, lp), (0, 0, lp / 2), material='finger')
        out += _shape(kind, _box(t, w, ld), dist_c, dist_rpy, material='finger')
    out += '  </link>\n'
    return out


def _header(name: str, materials: tuple[str, ...], s: ArmSpec) -> str:
    colours = {'arm': _vec(*s.colour), 'dark': _vec(*s.dark), 'finger': '0.3 0.3 0.32 1'}
    out = '<?xml version="1.0"?>\n<!-- generated by mindgrasp_sim.robot_model; edit there -->\n'
    out += f'<robot name="{name}">\n'
    for m in materials:
        out += f'  <material name="{m}"><color rgba="{colours[m]}"/></material>\n'
    return out


def _arm_body(s: ArmSpec, last: str) -> str:
    """The arm's links and joints, base to the wrist roll ``joint_6``, whose child is ``last``."""
    m = s.masses
    # base: a pedestal on the ground
    out = '  <link name="base_link">\n'
    out += _inertial(m[0], (0, 0, s.base_height / 2), _cyl_inertia(m[0], 0.09, s.base_height))
    out += _shape('visual', _cyl(0.09, s.base_height), (0, 0, s.base_height / 2), material='dark')
    out += _shape('collision', _cyl(0.09, s.base_height), (0, 0, s.base_height / 2))
    out += '  </link>\n'
    out += _joint('joint_1', 'base_link', 'link_1', (0, 0, s.base_height), (0, 0, 1),
                  s.lower[0], s.upper[0], s.velocity[0], s.effort[0])
    out += '  <link name="link_1">\n'
    out += _inertial(m[1], (0, 0, s.turret_height / 2), _cyl_inertia(m[1], 0.065, s.turret_height))
    out += _shape('visual', _cyl(0.065, s.turret_height), (0, 0, s.turret_height / 2),
                  material='arm')
    out += _shape('visual', _cyl(0.05, 0.12), (0, 0, s.turret_height), (math.pi / 2, 0, 0),
                  material='dark')
    out += _shape('collision', _cyl(0.065, s.turret_height - 0.03), (0, 0, s.turret_height / 2 -
                                                                         0.015))
    out += '  </link>\n'
    out += _joint('joint_2', 'link_1', 'link_2', (0, 0, s.turret_height), (0, 1, 0),
                  s.lower[1], s.upper[1], s.velocity[1], s.effort[1])
    out += _cyl_link('link_2', m[2], 0.04, s.long_arm)
    out += _joint('joint_3', 'link_2', 'link_3', (0, 0, s.long_arm), (0, 1, 0),
                  s.lower[2], s.upper[2], s.velocity[2], s.effort[2])
    out += _cyl_link('link_3', m[3], 0.036, s.link3, material='dark')
    out += _joint('joint_4', 'link_3', 'link_4', (0, 0, s.link3), (0, 1, 0),
                  s.lower[3], s.upper[3], s.velocity[3], s.effort[3])
    out += _cyl_link('link_4', m[4], 0.032, s.short_arm)
    out += _joint('joint_5', 'link_4', 'link_5', (0, 0, s.short_arm), (0, 1, 0),
                  s.lower[4], s.upper[4], s.velocity[4], s.effort[4])
    out += _cyl_link('link_5', m[5], 0.03, s.wrist, material='dark')
    out += _joint('joint_6', 'link_5', last, (0, 0, s.wrist), (0, 0, 1),
                  s.lower[5], s.upper[5], s.velocity[5], s.effort[5])
    return out


def _hand_body(s: ArmSpec) -> str:
    """The three-finger hand: the palm (its root link), fingers, camera and TCP frames."""
    m = s.masses
    out = '  <link name="palm">\n'
    out += _inertial(m[6], (0, 0, s.palm / 2), _cyl_inertia(m[6], s.palm_radius, s.palm))
    out += _shape('visual', _cyl(s.palm_radius, s.palm), (0, 0, s.palm / 2), material='dark')
    out += _shape('collision', _cyl(s.palm_radius, s.palm), (0, 0, s.palm / 2))
    out += '  </link>\n'
    fx, fy, z = s.finger_offset_x, s.finger_offset_y, s.palm
    fingers = (
        # the thumb opposes two fingers, so it gets twice their torque (balanced squeeze)
        ('finger_thumb', (fx, 0.0, z), (0, -1, 0), -1.0, 2.0),
        ('finger_left', (-fx, fy, z), (0, 1, 0), 1.0, 1.0),
        ('finger_right', (-fx, -fy, z), (0, 1, 0), 1.0, 1.0),
    )
    for fname, xyz, axis, inward, gain in fingers:
        out += _joint(f'{fname}_joint', 'palm', fname, xyz, axis, s.finger_lower, s.finger_upper,
                      s.finger_velocity, s.finger_effort * gain)
        out += _finger_link(s, fname, inward)
    # camera: a small housing in the palm centre and the optical frame (x right, y down, z out)
    out += _fixed('camera_joint', 'palm', 'camera_color_optical_frame', (0, 0, z + 0.001),
                  (0, 0, -math.pi / 2))
    out += '  <link name="camera_color_optical_frame">\n'
    out += _inertial(0.01, (0, 0, 0), (1e-6, 1e-6, 1e-6))
    out += '  </link>\n'
    out += _fixed('tcp_joint', 'palm', 'tcp', (0, 0, z + s.tcp_offset))
    out += '  <link name="tcp">\n'
    out += _inertial(0.001, (0, 0, 0), (1e-7, 1e-7, 1e-7))
    out += '  </link>\n'
    return out


def build_urdf(spec: ArmSpec | None = None, name: str = 'mindgrasp_arm') -> str:
    """Return the URDF text of the arm with its hand described by ``spec`` (default
    :class:`ArmSpec`), in one file."""
    s = spec or ArmSpec()
    return (_header(name, ('arm', 'dark', 'finger'), s) + _arm_body(s, 'palm') + _hand_body(s)
            + '</robot>\n')


def build_arm_urdf(spec: ArmSpec | None = None, name: str = 'mindgrasp_arm') -> str:
    """The arm alone (``config/robots/urdf/mindgrasp_arm_arm.urdf``): ``joint_6`` ends at the
    empty link ``flange``, which the hand's root (the palm) replaces when a hand is mounted."""
    s = spec or ArmSpec()
    return (_header(name, ('arm', 'dark'), s) + _arm_body(s, 'flange')
            + '  <link name="flange"/>\n</robot>\n')


def build_hand_urdf(spec: ArmSpec | None = None, name: str = 'mindgrasp_hand') -> str:
    """The three-finger hand alone (``config/robots/urdf/mindgrasp_hand.urdf``), root ``palm``."""
    s = spec or ArmSpec()
    return _header(name, ('dark', 'finger'), s) + _hand_body(s) + '</robot>\n'


FILES = {'mindgrasp_arm.urdf': build_urdf, 'mindgrasp_arm_arm.urdf': build_arm_urdf,
         'mindgrasp_hand.urdf': build_hand_urdf}


def main(argv: list[str] | None = None) -> int:
    """Print the default URDF (to regenerate ``config/robots/urdf/mindgrasp_arm.urdf``), or with
    ``--write FOLDER`` write the three files of :data:`FILES` there."""
    args = sys.argv[1:] if argv is None else argv
    if args[:1] == ['--write'] and len(args) == 2:
        for file, build in FILES.items():
            with open(f'{args[1]}/{file}', 'w', encoding='utf-8') as f:
                f.write(build())
        return 0
    sys.stdout.write(build_urdf())
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
