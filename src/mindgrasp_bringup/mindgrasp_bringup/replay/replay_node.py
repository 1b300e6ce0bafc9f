"""The replay as a launchable node: ``mindgrasp launch replay bag:=RUN`` runs it.

    python -m mindgrasp_bringup.replay.replay_node --ros-args -p bag:=runs/<run> \
        -p controller:=true

Parameters: :class:`ReplayParams`. The re-run nodes run lock-step on the bag's clock in this
process (see :mod:`mindgrasp_bringup.replay.engine`); the node ends when the report is written
(exit 0) and logs the summary line. A missing bag or one the replay cannot use ends it with exit
code 2 and one line; a damaged bag is replayed as far as it is readable and ends it with exit
code 1 unless ``allow_damaged:=true``; Ctrl-C stops it (0).
"""

from __future__ import annotations

from dataclasses import dataclass

from mindgrasp_bag.errors import BagError
from mindgrasp_bag.paths import resolve_bag
from mindgrasp_bringup.replay import ReplayConfig, damage_lines, run_replay, summary_line
from mindgrasp_common.robot_description import RobotDescriptionError, load_robot
from mindgrasp_ros import rclpy
from mindgrasp_ros.node_main import EXIT_OK, EXIT_REFUSED, fail, run_node
from mindgrasp_ros.params import ParameterError, declare_params, param


@dataclass
class ReplayParams:
    """Parameters of the replay node (the arguments of ``mindgrasp launch replay``)."""

    bag: str = param('', 'the run directory (runs/<run>) or its bag folder (runs/<run>/bag)')
    controller: bool = param(False, 're-run the controller too (open loop)')
    model: str = param('', "classifier model (.json); '': the one the run used")
    output: str = param('', "report directory; '': <run>/replays/<time>")
    robot: str = param('', "the arm of the re-run controller: a shipped robot or a robot "
                       "description YAML path; '': the one the run used")
    progress: bool = param(True, 'show a progress bar on stderr')
    allow_damaged: bool = param(False, 'end with exit code 0 after replaying the readable part '
                                'of a damaged bag (default: 1)')


class ReplayNode(rclpy.node.Node):
    """Replays once (from a one-shot timer, so Ctrl-C stops it) and ends with the report."""

    def __init__(self, **kwargs: object) -> None:
        super().__init__('replay', **kwargs)
        self.params = declare_params(self, ReplayParams)
        self.done = rclpy.task.Future()
        if not self.params.bag:
            raise ParameterError('No bag given: mindgrasp launch replay bag:=runs/<run>.')
        if self.params.robot:          # a bad description refuses to start (exit 2)
            load_robot(self.params.robot)
        resolve_bag(self.params.bag)   # a missing bag refuses to start (BagError, exit 2)
        self.timer = self.create_timer(0.0, self.replay_callback)

    def replay_callback(self) -> None:
        """Replay and write the report; a bag the replay cannot use ends the node with exit 2."""
        self.timer.cancel()
        p = self.params
        cfg = ReplayConfig(p.bag, controller=p.controller, model=p.model,
                           output=p.output or None, progress=p.progress,
                           params={'controller': {'robot': p.robot}} if p.robot else {})
        try:
            result = run_replay(cfg)
        except BagError as exc:   # bad input found while reading the run: as a bad argument
            self.get_logger().error(str(exc))
            self.done.set_result(EXIT_REFUSED)
            return
        self.get_logger().info(summary_line(result))
        lines = damage_lines(result, p.allow_damaged)
        for line in lines:
            self.get_logger().warning(line)
        if lines and not p.allow_damaged:
            fail(self, 'The bag is damaged (see above); the report covers its readable part.')
            return
        self.done.set_result(EXIT_OK)


def main(args: list[str] | None = None) -> int:
    """Replay once and end: 0 with the report written, 2 on a bad bag or parameter."""
    return run_node(ReplayNode, args, errors=(BagError, RobotDescriptionError))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
