"""Two sessions at once on one host: each grasps its own targets and hears only its own
amplifier (issue 42: one session's EEG once drove another session's arm).

    python benchmarks/two_sessions.py --trials 3
    python benchmarks/two_sessions.py --trials 3 --domains 11 12 --keep

Two ``mindgrasp launch demo`` runs start side by side as two users would start them: the same
LSL stream name (the amplifier model's), two ROS domains, two seeds. The second starts while the
first streams. Printed per session: correct / wrong / no grasp (``trials/records.csv``), the
source id of its own virtual amplifier, the source id its acquisition node took
(``eeg_stream.json``), and any log line of its acquisition node that names the other session's
amplifier. Targets: every trial correct in both, each acquisition on its own amplifier, no line
naming the other one.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import uuid
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from live_under_load import outcomes


def start_demo(run_dir: Path, stream: str, seed: int, trials: int, domain: int
               ) -> subprocess.Popen:
    """``mindgrasp launch demo`` on ROS domain ``domain`` with its amplifier named ``stream``."""
    cmd = [sys.executable, '-m', 'mindgrasp_cli', 'launch', 'demo', f'trials:={trials}',
           f'seed:={seed}', 'live_view:=false', f'eeg_stream:={stream}', '--run-dir',
           str(run_dir)]
    env = {**os.environ, 'ROS_DOMAIN_ID': str(domain)}
    return subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)


def amplifier_source_id(run_dir: Path) -> str | None:
    """The source id the launch gave the run's virtual amplifier (its parameter file), None if
    the run has none."""
    path = run_dir / 'params' / 'virtual_amp.yaml'
    if not path.exists():
        return None
    params = yaml.safe_load(path.read_text(encoding='utf-8'))
    return params['/**']['ros__parameters'].get('source_id')


def session_summary(run_dir: Path, other_source: str | None, exit_code: int) -> dict:
    """What the benchmark reports of one session."""
    heard = run_dir / 'eeg_stream.json'
    taken = json.loads(heard.read_text(encoding='utf-8')) if heard.exists() else {}
    log = run_dir / 'logs' / 'eeg_acquisition.log'
    text = log.read_text(encoding='utf-8', errors='replace') if log.exists() else ''
    crossed = [line for line in text.splitlines()
               if other_source and other_source in line]
    return {'run': str(run_dir), 'exit_code': exit_code, 'outcomes': outcomes(run_dir),
            'own_amplifier': amplifier_source_id(run_dir),
            'acquisition_source_id': taken.get('source_id'), 'lines_naming_the_other': crossed}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--trials', type=int, default=3, help='grasp trials per session (default 3)')
    ap.add_argument('--domains', type=int, nargs=2, default=(41, 42), metavar=('A', 'B'),
                    help='ROS domain of each session (default 41 42)')
    ap.add_argument('--stagger', type=float, default=20.0,
                    help='s between the two starts (the second joins a streaming first; '
                         'default 20)')
    ap.add_argument('--timeout', type=float, default=3600.0,
                    help='give up on the sessions after this long (s, default 3600)')
    ap.add_argument('--keep', action='store_true', help='keep the run directories (printed)')
    ap.add_argument('--json', action='store_true', help='also print the summary as JSON')
    args = ap.parse_args(argv)
    if args.trials < 1 or args.domains[0] == args.domains[1]:
        ap.error('give --trials >= 1 and two different --domains')
    tmp = Path(tempfile.mkdtemp(prefix='mindgrasp-two-'))
    stream = f'mg-two-{uuid.uuid4().hex[:8]}'      # one amplifier model: one stream name
    runs = {'a': tmp / 'a', 'b': tmp / 'b'}
    procs = {'a': start_demo(runs['a'], stream, 1, args.trials, args.domains[0])}
    time.sleep(args.stagger)
    procs['b'] = start_demo(runs['b'], stream, 2, args.trials, args.domains[1])
    codes = {}
    for key, proc in procs.items():
        try:
            proc.communicate(timeout=args.timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
        codes[key] = proc.returncode
    sources = {k: amplifier_source_id(run) for k, run in runs.items()}
    result = {k: session_summary(run, sources['b' if k == 'a' else 'a'], codes[k])
              for k, run in runs.items()}
    ok = True
    for key, s in result.items():
        o = s['outcomes']
        own = s['own_amplifier'] == s['acquisition_source_id'] is not None
        ok &= own and not s['lines_naming_the_other'] and o.get('correct_grasp', 0) == \
            args.trials and s['exit_code'] == 0
        print(f"session {key} (domain {args.domains[0 if key == 'a' else 1]}): correct grasp "
              f"{o.get('correct_grasp', 0)}, wrong grasp {o.get('wrong_grasp', 0)}, no grasp "
              f"{o.get('no_grasp', 0)}; its amplifier {s['own_amplifier']}, its acquisition "
              f"took {s['acquisition_source_id']}; lines naming the other amplifier: "
              f"{len(s['lines_naming_the_other'])}; exit {s['exit_code']}")
    load = ' / '.join(f'{v:.1f}' for v in os.getloadavg())
    print(f'load average (1/5/15 min) after the run: {load} on {os.cpu_count()} cores')
    print('targets (every trial correct in both, each on its own amplifier): '
          + ('met' if ok else 'missed'))
    if args.keep:
        print(f'run directories: {tmp}')
    else:
        shutil.rmtree(tmp, ignore_errors=True)
    if args.json:
        print(json.dumps(result))
    return 0


if __name__ == '__main__':
    sys.exit(main())
