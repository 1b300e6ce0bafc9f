"""mindgrasp_sim: PyBullet simulation of the MIndGrasp assistive arm.

Layers: :mod:`~mindgrasp_sim.robot_model` (URDF of the arm and three-finger gripper),
:mod:`~mindgrasp_sim.scene` (scene files), :mod:`~mindgrasp_sim.simulation` (the ROS-free
``Simulation``, composed from :mod:`~mindgrasp_sim.world`, :mod:`~mindgrasp_sim.arm_control`,
:mod:`~mindgrasp_sim.camera`, :mod:`~mindgrasp_sim.kinematics` and
:mod:`~mindgrasp_sim.bullet_client`), :mod:`~mindgrasp_sim.scripted` (scripted motions and grasps),
:mod:`~mindgrasp_sim.task` (grasp success / drop detection) and the ROS node
:mod:`~mindgrasp_sim.sim_node`.
"""

from mindgrasp_sim.errors import SimError

__all__ = ['SimError']
