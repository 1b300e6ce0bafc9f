"""The replay as a launchable node: ``mindgrasp launch replay bag:=RUN`` runs it.

    python -m mindgrasp_bringup.replay.replay_node --ros-args -p bag:=runs/<run> \
        -p controller:=true

Parameters: ``bag`` (run directory or its bag folder), ``controller`` (re-run the controller,
open loop), ``model`` (classifier model; '' = the run's), ``output`` (report directory; '' =
``<run>/replays/<time>``), ``progress``. The re-run nodes run lock-step on the bag's clock in
this process (see :mod:`mindgrasp_bringup.replay.engine`); the node ends when the report is
written, and logs the summary line.
"""

from __future__ import annotations

import sys

from mindgrasp_bringup.bag.errors import BagError
from mindgrasp_bringup.replay import ReplayConfig, run_replay, summary_line
from mindgrasp_ros import rclpy

PARAMETERS = [('bag', ''), ('controller', False), ('model', ''), ('output', ''),
              ('progress', True)]


class ReplayNode(rclpy.node.Node):
    """Holds the replay's parameters; :meth:`run` replays and writes the report."""

    def __init__(self, **kwargs: object) -> None:
        super().__init__('replay', **kwargs)
        self.declare_parameters('', PARAMETERS)
        self.p = {name: self.get_parameter(name).value for name, _ in PARAMETERS}

    def run(self) -> int:
        """Replay; 0 when the report is written, 2 on a bad bag argument."""
        if not self.p['bag']:
            self.get_logger().error('No bag given: mindgrasp launch replay bag:=runs/<run>.')
            return 2
        cfg = ReplayConfig(self.p['bag'], controller=bool(self.p['controller']),
                           model=str(self.p['model']), output=self.p['output'] or None,
                           progress=bool(self.p['progress']))
        try:
            result = run_replay(cfg)
        except BagError as exc:
            self.get_logger().error(str(exc))
            return 2
        self.get_logger().info(summary_line(result))
        return 0


def main(args: list[str] | None = None) -> int:
    """Replay once and end."""
    rclpy.init(args=args)
    node = ReplayNode()
    try:
        return node.run()
    except KeyboardInterrupt:
        return 130
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    sys.exit(main())
