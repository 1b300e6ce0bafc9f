"""Every fault of issue 31 on a real demo, and what it cost: the arm and the records.

    python benchmarks/faults.py                  # all: ~20 min (each scenario starts a demo)
    python benchmarks/faults.py --only arm       # node kills and the NaN joint-state publisher
    python benchmarks/faults.py --only records   # full disk (needs root) and the damaged bag

The arm part (:mod:`faults_arm`): each node of a live demo killed in turn, and a second
publisher sending NaN joint states; prints how fast the arm stopped and how far it moved after
the fault. The records part (:mod:`faults_records`): the demo's run directory on a 3 MB and a
20 MB tmpfs, and its bag cut in half and with three damaged chunks; prints what was kept,
written, sent to the fallback folder and dropped, and what each bag tool reported. Prints
figures; asserts nothing (the tests check the behaviour).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import faults_arm
import faults_records


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--only', choices=('arm', 'records'), default=None,
                        help='run one part (default: both)')
    parser.add_argument('--duration', type=float, default=60.0,
                        help='length of each records demo run in s (default: 60)')
    args = parser.parse_args(argv)
    code = 0
    if args.only in (None, 'arm'):
        print('== the arm: node kills and NaN joint states', flush=True)
        code |= faults_arm.main([])
    if args.only in (None, 'records'):
        print('\n== the records: full disk and damaged bags', flush=True)
        code |= faults_records.main(['--duration', str(args.duration)])
    return code


if __name__ == '__main__':
    sys.exit(main())
