"""``report.md`` of a launch's run directory: written when the launch ends, from its bag.

Today it holds the timing section (:mod:`mindgrasp_bag.latency`): per hop and end to end
latency of the BCI loop, the display's cue-to-flip delay, and the jitter of periodic topics. A
run that cannot give latencies (no EEG, no classifier or controller, no bag) says why in one line,
so every run directory has a report.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

from mindgrasp_bag import BagError
from mindgrasp_bag.latency import LatencyError, format_markdown, latency_report
from mindgrasp_bag.run_stamps import read_run_stamps
from mindgrasp_common.safe_files import write_atomic

__all__ = ['write_run_report']

logger = logging.getLogger('launch')


def write_run_report(run_dir: Path, title: str) -> Path | None:
    """Write ``run_dir/report.md`` (and ``latency.json`` when the run gives latencies); its
    path, or None when the disk refused it (said in one line: the report is made from the bag
    again with ``mindgrasp bag latency``).

    Never raises for a bad or missing bag: the report then says why there are no figures.
    """
    run_dir = Path(run_dir)
    bag = run_dir / 'bag'
    lines = [f'# Run {run_dir.name}: {title}', '']
    report = None
    try:
        if not bag.is_dir():
            msg = ('The run has no bag (record:=false, or the recorder ended before it opened '
                   'one), so it has no timing report; record the run to get one.')
            raise LatencyError(msg)
        report = latency_report(read_run_stamps(bag))
    except (BagError, LatencyError, OSError) as exc:
        lines += ['## Timing', '', f'No latency figures: {exc}', '']
    else:
        lines.append(format_markdown(report))
        e2e = report['end_to_end']
        logger.info('latency EEG sample -> arm command: p50 %.1f ms, p99 %.1f ms (%d); report: '
                    '%s', e2e['p50_ms'], e2e['p99_ms'], e2e['count'], run_dir / 'report.md')
    path = run_dir / 'report.md'
    text = '\n'.join(lines).rstrip() + '\n'
    try:
        if report is not None:
            latency = json.dumps(report, indent=1) + '\n'
            write_atomic(run_dir / 'latency.json', lambda p: p.write_text(latency, 'utf-8'))
        write_atomic(path, lambda p: p.write_text(text, encoding='utf-8'))
    except OSError as exc:
        logger.error('Could not write the run report %s (%s); the bag holds what it needs: '
                     'mindgrasp bag latency %s', path, exc.strerror or exc, run_dir)
        return None
    return path
