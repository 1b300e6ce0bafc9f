"""A plain Python process for launcher tests: prints ``tick <i>`` lines, then exits.

    python -m launch_fixtures.ticker [--count N] [--period S] [--exit-code C] [--ignore-sigint]
        [--crash-once FILE] [--ros-args ...]

Prints its ROS arguments and the parameter file it got (``params <json>``), stops on SIGINT with
exit code 0 (``stopping on SIGINT``), ``--ignore-sigint`` ignores it (the launcher must escalate),
``--keyboard-interrupt`` relies on Python's own SIGINT handling (as rclpy nodes do),
``--crash-once FILE`` exits with code 3 when FILE does not exist yet (and creates it), so a
respawned process runs normally the second time. ``--count 0`` ticks until stopped.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import time

import yaml


def _ros_args(argv: list[str]) -> tuple[list[str], list[str]]:
    if '--ros-args' in argv:
        i = argv.index('--ros-args')
        return argv[:i], argv[i + 1:]
    return argv, []


def main() -> int:
    own, ros = _ros_args(sys.argv[1:])
    parser = argparse.ArgumentParser()
    parser.add_argument('--count', type=int, default=3)
    parser.add_argument('--period', type=float, default=0.05)
    parser.add_argument('--exit-code', type=int, default=0)
    parser.add_argument('--ignore-sigint', action='store_true')
    parser.add_argument('--crash-once')
    parser.add_argument('--label', default='ticker')
    parser.add_argument('--keyboard-interrupt', action='store_true',
                        help="rely on Python's default SIGINT handling, as rclpy nodes do")
    args = parser.parse_args(own)
    stop = {'flag': False}

    def on_sigint(signum: int, frame: object) -> None:
        stop['flag'] = True

    if args.ignore_sigint:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    elif not args.keyboard_interrupt:
        signal.signal(signal.SIGINT, on_sigint)
    print(f'ros-args {json.dumps(ros)}')
    if '--params-file' in ros:
        with open(ros[ros.index('--params-file') + 1], encoding='utf-8') as f:
            print(f'params {json.dumps(yaml.safe_load(f))}')
    print(f'env MINDGRASP_RUN_DIR={os.environ.get("MINDGRASP_RUN_DIR", "")}')
    if args.crash_once and not os.path.exists(args.crash_once):
        open(args.crash_once, 'w').close()
        print('crashing once on purpose', file=sys.stderr)
        return 3
    try:
        return _tick(args, stop)
    except KeyboardInterrupt:
        print('stopping on KeyboardInterrupt')
        return 0


def _tick(args: argparse.Namespace, stop: dict[str, bool]) -> int:
    i = 0
    while args.count == 0 or i < args.count:
        if stop['flag']:
            print('stopping on SIGINT')
            return 0
        print(f'{args.label} tick {i}', flush=True)
        i += 1
        time.sleep(args.period)
    print(f'{args.label} done, exit code {args.exit_code}', file=sys.stderr if args.exit_code
          else sys.stdout)
    return args.exit_code


if __name__ == '__main__':
    sys.exit(main())
