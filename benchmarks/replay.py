"""Replay speed and agreement on a recorded run.

Run: ``.venv/bin/python benchmarks/replay.py runs/<time>_demo [--controller]``
(record one first: ``mindgrasp launch demo duration:=60``).

Prints, for the classifier alone and (with ``--controller``) the classifier and the controller:
seconds of recording replayed, wall time of the replay itself (reading the bag, lock-step
feeding, comparison and report; the node modules are imported before), speed as a multiple of
real time, and the agreement per topic.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from mindgrasp_bringup.replay import ReplayConfig, run_replay


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('run', help='run directory (runs/<run>) or its bag folder')
    parser.add_argument('--controller', action='store_true', help='also with the controller')
    args = parser.parse_args()
    variants = [False, True] if args.controller else [False]
    t0 = time.perf_counter()
    import mindgrasp_classifier.classifier_node  # noqa: F401 - pyRiemann imports torch: seconds
    import mindgrasp_fsm.fsm_node  # noqa: F401
    print(f'importing the node modules: {time.perf_counter() - t0:.1f} s (once per process)',
          flush=True)
    with tempfile.TemporaryDirectory(prefix='replay-bench-') as tmp:
        for controller in variants:
            out = Path(tmp) / ('controller' if controller else 'classifier')
            t0 = time.perf_counter()
            result = run_replay(ReplayConfig(args.run, controller=controller, output=out,
                                             progress=False))
            wall = time.perf_counter() - t0
            span = (result.end_ns - result.start_ns) / 1e9
            s = result.summary
            pred = s['topics']['/bci/prediction']
            line = (f'{", ".join(result.nodes):<22} {span:6.1f} s of recording in {wall:6.1f} s '
                    f'({span / wall:5.1f} x real time); predictions {pred["agree"]}/'
                    f'{pred["comparable"]} agree ({100 * (pred["agreement"] or 0):.1f} %)')
            state = s['topics'].get('/fsm/state')
            if state is not None:
                line += f'; controller states {100 * (state["agreement"] or 0):.1f} % (open loop)'
            print(line, flush=True)


if __name__ == '__main__':
    main()
