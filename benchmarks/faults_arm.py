"""How fast the arm stops, and how far it moves, when a node of a live demo dies or a second
publisher sends NaN joint states (issue 31): a real ``mindgrasp launch demo`` per scenario, the
fault injected once the arm moves, the arm watched on /joint_states over DDS.

    python benchmarks/faults_arm.py                          # every scenario, then p50 / max
    python benchmarks/faults_arm.py --scenario nan_joint_states --scenario kill_fsm

The fault comes once a joint has moved faster than 0.2 rad/s for 0.5 s. Per scenario: the time
from the fault to the first joint state from which the arm stays still
(every |joint velocity| < 0.01 rad/s for the rest of the 4 s window), and the largest joint
displacement after the fault (rad). The NaN publisher also counts how often the controller's
command switched between stop and move while it ran (it was 20 times in 3.2 s), and whether and
when the arm moved again after the NaN stopped. Prints figures; asserts nothing. A scenario
takes a demo start-up (about a minute on a loaded machine). ``benchmarks/faults.py`` calls the
scenario functions (each returns a dict) through :data:`SCENARIOS`.
"""

from __future__ import annotations

import argparse
import contextlib
import itertools
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Callable
from pathlib import Path

import numpy as np

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')

STILL = 0.01        # rad/s: every joint slower than this is "stopped"
WINDOW = 4.0        # s watched after the fault
_STARTED = re.compile(r'process started with pid \[(\d+)\]: (\S+)')


class Demo:
    """A live ``mindgrasp launch demo`` in its own process group, its output collected."""

    def __init__(self, run_dir: Path) -> None:
        cmd = [sys.executable, '-m', 'mindgrasp_cli', 'launch', 'demo', 'trials:=1',
               'duration:=600', 'live_view:=false', 'record:=false',
               f'eeg_stream:=mg-faults-{uuid.uuid4().hex[:8]}', '--run-dir', str(run_dir)]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True, start_new_session=True)
        self.lines: list[str] = []
        self.pids: dict[str, int] = {}
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.append(line.rstrip())
            m = _STARTED.search(line)
            if m:
                self.pids[m.group(2)] = int(m.group(1))

    def kill(self, label: str) -> None:
        """SIGKILL the node ``label`` (as a crash would end it)."""
        os.kill(self.pids[label], signal.SIGKILL)

    def stop(self) -> int | None:
        """Ctrl-C the launch; SIGKILL its group if it has not ended within 60 s."""
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.proc.pid, signal.SIGINT)
        try:
            return self.proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(self.proc.pid, signal.SIGKILL)
            return self.proc.wait(timeout=30)


class ArmWatch:
    """A ROS node that keeps every finite joint state (receipt time s, positions, velocities)
    and every velocity command (receipt time s, moving or not)."""

    def __init__(self) -> None:
        from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState
        from mindgrasp_ros.interfaces.std_msgs.msg import Float64MultiArray

        from mindgrasp_ros import rclpy
        from mindgrasp_ros.topics import ARM_COMMANDS, JOINT_STATES

        self.rclpy = rclpy
        self.node = rclpy.node.Node(f'faults_arm_{uuid.uuid4().hex[:6]}')
        self.states: list[tuple[float, np.ndarray, np.ndarray]] = []
        self.commands: list[tuple[float, bool]] = []
        self.node.create_subscription(JointState, JOINT_STATES.name, self._state,
                                      JOINT_STATES.qos)
        self.node.create_subscription(Float64MultiArray, ARM_COMMANDS.name, self._command,
                                      ARM_COMMANDS.qos)
        self.nan_pub = self.node.create_publisher(JointState, JOINT_STATES.name,
                                                  JOINT_STATES.qos)
        self._JointState = JointState

    def _state(self, msg: object) -> None:
        q = np.asarray(msg.position, dtype=float)
        v = np.asarray(msg.velocity, dtype=float)
        if q.size == 6 and np.isfinite(q).all() and np.isfinite(v).all():   # not our NaN
            self.states.append((time.monotonic(), q, v))

    def _command(self, msg: object) -> None:
        self.commands.append((time.monotonic(), bool(np.any(np.asarray(msg.data) != 0))))

    def publish_nan(self) -> None:
        msg = self._JointState(name=[f'joint_{i}' for i in range(1, 7)],
                               position=np.full(6, np.nan), velocity=np.zeros(6))
        msg.header.stamp = self.node.get_clock().now().to_msg()
        self.nan_pub.publish(msg)

    def spin_until(self, predicate: Callable[[], bool], timeout: float,
                   every: Callable[[], None] | None = None, period: float = 0.05) -> bool:
        """Spin until ``predicate()`` or ``timeout`` s; ``every()`` each ``period`` s."""
        deadline = time.monotonic() + timeout
        next_call = time.monotonic()
        while time.monotonic() < deadline:
            if predicate():
                return True
            if every is not None and time.monotonic() >= next_call:
                every()
                next_call += period
            self.rclpy.spin_once(self.node, timeout_sec=0.01)
        return predicate()

    def moving(self) -> bool:
        """The arm has moved steadily for the last 0.5 s (a joint faster than 0.2 rad/s in every
        joint state), so that a fault meets it in motion, not as it starts."""
        now = time.monotonic()
        recent = [v for t, _q, v in self.states[-100:] if now - t < 0.5]
        return len(recent) >= 10 and now - self.states[-1][0] < 0.1 and \
            all(float(np.max(np.abs(v))) > 0.2 for v in recent)

    def close(self) -> None:
        self.node.destroy_node()


def _after(watch: ArmWatch, t_fault: float) -> dict[str, float | None]:
    """Stop time (s after the fault, None: still moving at the end of the window or no joint
    states after it) and the largest displacement after the fault (rad)."""
    before = [s for s in watch.states if s[0] < t_fault]
    after = [s for s in watch.states if s[0] >= t_fault]
    if not before or not after:
        return {'stop_s': None, 'moved_rad': None, 'joint_states_after': len(after)}
    q0 = before[-1][1]
    moving = [float(np.max(np.abs(v))) >= STILL for _t, _q, v in after]
    last_moving = max((i for i, m in enumerate(moving) if m), default=-1)
    stop_s = None if last_moving == len(after) - 1 else after[last_moving + 1][0] - t_fault
    moved = max(float(np.max(np.abs(q - q0))) for _t, q, _v in after)
    return {'stop_s': stop_s, 'moved_rad': moved, 'joint_states_after': len(after)}


def _with_moving_demo(inject: Callable[[Demo, ArmWatch], dict]) -> dict:
    """Start a demo, wait until the arm moves (at most 300 s), run ``inject``, stop the demo."""
    from mindgrasp_ros import rclpy

    rclpy.init()
    watch = ArmWatch()
    run_dir = Path(tempfile.mkdtemp(prefix='faults_arm_')) / 'run'
    demo = Demo(run_dir)
    try:
        if not watch.spin_until(watch.moving, 300.0):
            return {'error': 'the arm did not move within 300 s of the start',
                    'log_tail': demo.lines[-5:]}
        result = inject(demo, watch)
    finally:
        code = demo.stop()
        watch.close()
        rclpy.shutdown()
    result['launch_exit_code'] = code
    result['run_dir'] = str(run_dir)
    return result


def kill_node(label: str) -> dict:
    """SIGKILL ``label`` of a demo while the arm moves; the arm's stop and movement after it."""
    def inject(demo: Demo, watch: ArmWatch) -> dict:
        t_fault = time.monotonic()
        demo.kill(label)
        watch.spin_until(lambda: False, WINDOW)
        reported = any(label in line and ('died' in line or 'killed' in line)
                       for line in demo.lines)
        return {'scenario': f'kill {label}', **_after(watch, t_fault), 'reported': reported}

    return _with_moving_demo(inject)


def kill_virtual_amp() -> dict:
    return kill_node('virtual_amp')


def kill_eeg_acquisition() -> dict:
    return kill_node('eeg_acquisition')


def kill_classifier() -> dict:
    return kill_node('classifier')


def kill_vision() -> dict:
    return kill_node('vision')


def kill_fsm() -> dict:
    return kill_node('fsm')


def nan_joint_states(seconds: float = 3.0, rate_hz: float = 20.0) -> dict:
    """A second publisher sends NaN /joint_states at ``rate_hz`` for ``seconds`` beside the
    simulator: the arm's stop, its movement, the controller's stop/move switches while the NaN
    ran, and when it moved again after the NaN ended (s; None: not within 10 s)."""
    def inject(_demo: Demo, watch: ArmWatch) -> dict:
        t_fault = time.monotonic()
        watch.spin_until(lambda: time.monotonic() - t_fault >= seconds, seconds + 1.0,
                         every=watch.publish_nan, period=1.0 / rate_hz)
        t_end = time.monotonic()
        watch.spin_until(lambda: time.monotonic() - t_fault >= WINDOW, WINDOW)
        during = [moving for t, moving in watch.commands if t_fault <= t <= t_end]
        switches = sum(1 for a, b in itertools.pairwise(during) if a != b)
        watch.spin_until(lambda: any(m for t, m in watch.commands if t > t_end), 10.0)
        resumed = next((t - t_end for t, m in watch.commands if t > t_end and m), None)
        return {'scenario': f'NaN joint states at {rate_hz:g} Hz for {seconds:g} s',
                **_after(watch, t_fault), 'stop_move_switches': switches,
                'moved_again_s_after_nan_end': resumed}

    return _with_moving_demo(inject)


#: scenario name -> function returning its figures (for benchmarks/faults.py)
SCENARIOS: dict[str, Callable[[], dict]] = {
    'kill_virtual_amp': kill_virtual_amp,
    'kill_eeg_acquisition': kill_eeg_acquisition,
    'kill_classifier': kill_classifier,
    'kill_vision': kill_vision,
    'kill_fsm': kill_fsm,
    'nan_joint_states': nan_joint_states,
}


def summary(results: list[dict]) -> dict[str, float | None]:
    """p50 / max of the stop times (s) and displacements (rad) over the scenarios."""
    stops = [r['stop_s'] for r in results if r.get('stop_s') is not None]
    moved = [r['moved_rad'] for r in results if r.get('moved_rad') is not None]
    return {'stop_s_p50': float(np.median(stops)) if stops else None,
            'stop_s_max': max(stops) if stops else None,
            'moved_rad_p50': float(np.median(moved)) if moved else None,
            'moved_rad_max': max(moved) if moved else None,
            'not_stopped': sum(1 for r in results if r.get('stop_s') is None)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--scenario', action='append', choices=sorted(SCENARIOS),
                        help='run only these (repeatable); default: all')
    parser.add_argument('--json', action='store_true', help='also print the figures as JSON')
    args = parser.parse_args(argv)
    results = []
    for name in args.scenario or list(SCENARIOS):
        result = SCENARIOS[name]()
        results.append(result)
        if 'error' in result:
            print(f'{name:22s} {result["error"]}', flush=True)
            continue
        stop = 'not stopped' if result['stop_s'] is None else f'stopped in {result["stop_s"]:.2f} s'
        moved = 'n/a' if result['moved_rad'] is None else f'{result["moved_rad"]:.3f} rad'
        extra = ''
        if 'stop_move_switches' in result:
            again = result['moved_again_s_after_nan_end']
            extra = (f', {result["stop_move_switches"]} stop/move switches during the NaN, moved '
                     'again ' + ('not within 10 s' if again is None else f'{again:.2f} s after it'))
        print(f'{name:22s} {stop}, moved {moved} after the fault{extra}; launch exit code '
              f'{result["launch_exit_code"]}', flush=True)
    s = summary(results)
    fmt = (lambda v, unit: 'n/a' if v is None else f'{v:.3f} {unit}')  # noqa: E731
    print(f'\n{len(results)} scenarios: time to stop p50 {fmt(s["stop_s_p50"], "s")}, max '
          f'{fmt(s["stop_s_max"], "s")}; movement after the fault p50 '
          f'{fmt(s["moved_rad_p50"], "rad")}, max {fmt(s["moved_rad_max"], "rad")}; '
          f'{s["not_stopped"]} not stopped within {WINDOW:g} s')
    if args.json:
        print(json.dumps({'scenarios': results, 'summary': s}, default=str))
    return 0


if __name__ == '__main__':
    sys.exit(main())
