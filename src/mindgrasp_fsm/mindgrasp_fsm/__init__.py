"""mindgrasp_fsm: the six-state semi-autonomous grasp controller of MIndGrasp.

Layers (no ROS below the node):

- :mod:`~mindgrasp_fsm.types`, :mod:`~mindgrasp_fsm.params`: inputs/outputs and every gain and
  threshold (``config/param/fsm.yaml``).
- :mod:`~mindgrasp_fsm.grasp_fsm`: :class:`GraspFsm`, the paper's six states, locks, watchdog,
  joint-limit clamping.
- :mod:`~mindgrasp_fsm.grasp_policy`: the autonomous final approach and grasp (depth + camera model
  + inverse kinematics, force-limited closing, contact and lift checks, one retry).
- :mod:`~mindgrasp_fsm.kinematics`: forward/inverse kinematics from the robot's URDF.
- :mod:`~mindgrasp_fsm.fsm_node`: the ROS node.
"""

from mindgrasp_fsm.errors import FsmError
from mindgrasp_fsm.grasp_fsm import GraspFsm, clamp_to_limits
from mindgrasp_fsm.params import FsmParams
from mindgrasp_fsm.types import FsmInputs, FsmOutput, State

__all__ = ['FsmError', 'FsmInputs', 'FsmOutput', 'FsmParams', 'GraspFsm', 'State',
           'clamp_to_limits']
