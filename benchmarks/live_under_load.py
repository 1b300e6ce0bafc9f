"""The live demo beside busy processes: grasp outcomes, latency per hop, the simulator's
real-time factor and every sensor-fault stop (issue 39: a loaded machine changes the timing,
never the outcome).

    python benchmarks/live_under_load.py --load 2 --trials 10
    python benchmarks/live_under_load.py --load 0 --trials 10
    python benchmarks/live_under_load.py --run runs/<run>      # the report of a run made before

The demo runs as a user starts it (``mindgrasp launch demo``: a process per node over DDS and
LSL, the set locations' three objects named in turn) with ``--load`` processes spinning beside it
for the whole run. Printed from the run directory: correct / wrong / no grasp
(``trials/records.csv``), the latency of each hop and end to end (``mindgrasp bag latency`` of
its bag, the same code), the simulator's real-time factor (its last log line), every sensor-fault
stop and every other warning of the controller and the simulator, and whether a warning came
before the first trial began (a clean start has none). The machine's load average is printed
beside the figures: this host is shared. Targets: every trial correct, no wrong grasp, end to
end p99 <= 50 ms, no warning before the first trial.
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing
import os
import re
import shutil
import subprocess
import sys
import tempfile
import uuid
from pathlib import Path

TARGET_P99_MS = 50.0
_WARN = re.compile(r'\[(WARN|WARNING|ERROR)\]')
_RTF = re.compile(r'real-time factor ([0-9.]+)x')
_STAMP = re.compile(r'\[\w+\] \[([0-9.]+)\]')


def _burn() -> None:
    """A busy process: the load added with --load."""
    while True:
        pass


def run_demo(run_dir: Path, trials: int, seed: int, timeout: float) -> int:
    """``mindgrasp launch demo`` with ``trials`` grasp trials, recorded to ``run_dir``; its exit
    code (the run directory is reported either way)."""
    cmd = [sys.executable, '-m', 'mindgrasp_cli', 'launch', 'demo', f'trials:={trials}',
           f'seed:={seed}', 'live_view:=false',
           f'eeg_stream:=mg-load-{uuid.uuid4().hex[:8]}', '--run-dir', str(run_dir)]
    try:
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        print(f'the demo did not end within {timeout:.0f} s', file=sys.stderr)
        return 124
    if res.returncode != 0:
        print(res.stderr[-3000:], file=sys.stderr)
    return res.returncode


def outcomes(run_dir: Path) -> dict[str, int]:
    """correct_grasp / wrong_grasp / no_grasp counts of the run's trial records."""
    from mindgrasp_experiments.records import OUTCOMES, read_records

    counts = dict.fromkeys(OUTCOMES, 0)
    try:
        records = read_records(run_dir / 'trials')
    except FileNotFoundError:
        return counts
    for rec in records:
        if rec.failure != 'interrupted':
            counts[rec.outcome] = counts.get(rec.outcome, 0) + 1
    return counts


def latency(run_dir: Path) -> dict | None:
    """``mindgrasp bag latency`` of the run (its report dict), None when it has none: the
    ``latency.json`` the launch wrote when it ended, else computed from the bag."""
    saved = run_dir / 'latency.json'
    if saved.exists():
        return json.loads(saved.read_text(encoding='utf-8'))
    from mindgrasp_bag import BagError
    from mindgrasp_bag.latency import LatencyError, latency_report
    from mindgrasp_bag.paths import resolve_bag
    from mindgrasp_bag.run_stamps import read_run_stamps

    try:
        return latency_report(read_run_stamps(resolve_bag(str(run_dir))))
    except (BagError, LatencyError, OSError) as exc:
        print(f'no latency figures: {exc}', file=sys.stderr)
        return None


def log_lines(run_dir: Path) -> list[str]:
    """Every line of the run's node logs, in file order per node (``logs/*.log``)."""
    lines: list[str] = []
    for path in sorted((run_dir / 'logs').glob('*.log')):
        lines += path.read_text(encoding='utf-8', errors='replace').splitlines()
    return lines


def warnings_before_first_trial(run_dir: Path) -> list[str]:
    """WARN/ERROR lines of any node logged before the trial manager named the first target
    (by the stamps of the node log lines, ``[LEVEL] [seconds] [node]: ...``)."""
    stamped = [(float(m.group(1)), line) for line in log_lines(run_dir)
               if (m := _STAMP.match(line))]
    first = min((t for t, line in stamped if 'Trial 1: grasp the' in line), default=math.inf)
    return [line for t, line in sorted(stamped) if t < first and _WARN.search(line)]


def summary(run_dir: Path, load: int) -> dict:
    """Everything the benchmark reports about one run, as one dict."""
    lines = log_lines(run_dir)
    rtf = [float(m.group(1)) for line in lines if (m := _RTF.search(line))]
    faults = [line for line in lines if 'sensor fault:' in line]
    warns = [line for line in lines if _WARN.search(line)
             and ('[fsm]' in line or '[sim]' in line)]
    report = latency(run_dir)
    hops = {}
    if report is not None:
        hops = {name: {k: h.get(k) for k in ('p50_ms', 'p95_ms', 'p99_ms', 'count')}
                for name, h in {**report.get('hops', {}),
                                'end_to_end': report.get('end_to_end', {})}.items()}
    return {'load': load, 'outcomes': outcomes(run_dir), 'latency': hops,
            'sim_real_time_factor': rtf[-1] if rtf else None, 'sensor_fault_stops': faults,
            'fsm_sim_warnings': warns, 'warnings_before_first_trial':
                warnings_before_first_trial(run_dir), 'load_average': os.getloadavg()}


def print_summary(s: dict) -> None:
    o = s['outcomes']
    n = sum(o.values())
    print(f"{n} trials, {s['load']} extra busy process(es): correct grasp "
          f"{o.get('correct_grasp', 0)}, wrong grasp {o.get('wrong_grasp', 0)}, no grasp "
          f"{o.get('no_grasp', 0)}")
    for name, h in s['latency'].items():
        if h.get('count'):
            print(f"  {name}: p50 {h['p50_ms']:.1f} ms, p95 {h['p95_ms']:.1f} ms, p99 "
                  f"{h['p99_ms']:.1f} ms ({h['count']})")
    rtf = s['sim_real_time_factor']
    print(f"  simulator real-time factor: {'-' if rtf is None else f'{rtf:.2f}x'}")
    print(f"  sensor-fault stops: {len(s['sensor_fault_stops'])}")
    for line in s['sensor_fault_stops']:
        print(f'    {line}')
    print(f"  controller/simulator warnings: {len(s['fsm_sim_warnings'])}")
    for line in s['fsm_sim_warnings'][:10]:
        print(f'    {line}')
    early = s['warnings_before_first_trial']
    print(f'  warnings before the first trial: {len(early)}')
    for line in early[:10]:
        print(f'    {line}')
    la = s['load_average']
    print(f'  load average (1/5/15 min) after the run: {la[0]:.1f} / {la[1]:.1f} / {la[2]:.1f} '
          f'on {os.cpu_count()} cores')
    e2e = s['latency'].get('end_to_end', {})
    met = (o.get('correct_grasp', 0) == n > 0 and not o.get('wrong_grasp', 0)
           and e2e.get('p99_ms') is not None and e2e['p99_ms'] <= TARGET_P99_MS and not early)
    print(f"targets (every trial correct, no wrong grasp, end to end p99 <= "
          f"{TARGET_P99_MS:.0f} ms, no warning before the first trial): "
          f"{'met' if met else 'missed'}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--load', type=int, default=0,
                        help='busy processes beside the demo (default 0)')
    parser.add_argument('--trials', type=int, default=10, help='grasp trials (default 10)')
    parser.add_argument('--seed', type=int, default=0, help='seed of the demo (default 0)')
    parser.add_argument('--run', type=Path, help='report this run directory instead of a new one')
    parser.add_argument('--keep', action='store_true', help='keep the run directory (printed)')
    parser.add_argument('--timeout', type=float, default=3600.0,
                        help='give up on the demo after this long (s, default 3600)')
    parser.add_argument('--json', action='store_true',
                        help='also print the summary as one JSON object on the last line')
    args = parser.parse_args(argv)
    if args.run is not None:
        s = summary(args.run, args.load)
    else:
        tmp = Path(tempfile.mkdtemp(prefix='mindgrasp-load-'))
        run_dir = tmp / 'run'
        print(f"live demo, {args.trials} trials, {args.load} extra busy process(es); run: "
              f"{run_dir if args.keep else '(temporary)'}", flush=True)
        burners = [multiprocessing.Process(target=_burn, daemon=True) for _ in range(args.load)]
        for p in burners:
            p.start()
        try:
            code = run_demo(run_dir, args.trials, args.seed, args.timeout)
        finally:
            for p in burners:
                p.terminate()
        s = summary(run_dir, args.load)
        s['demo_exit_code'] = code
        if not args.keep:
            shutil.rmtree(tmp, ignore_errors=True)
    print_summary(s)
    if args.json:
        print(json.dumps(s))
    return 0


if __name__ == '__main__':
    sys.exit(main())
