"""Latency and jitter of a live run from its recorded stamps (ROS-free; numpy only).

The BCI loop's hops, as BCI2000 and ROS-Neuro report theirs::

    EEG sample --acquisition--> /eeg/raw --classifier--> /bci/prediction --controller--> command

Times come from the bag (see :mod:`.run_stamps`): an EEG sample's acquisition time is the chunk's
``header.stamp`` (the LSL timestamp of its first sample mapped to ROS time) plus ``k / rate``; a
message's publication time is its MCAP ``publish_time`` (the DDS source timestamp, i.e. when the
publisher wrote it; the recorder's receive time only when the bag has none).

The EEG sample timed is the last sample of each decoded window (``MIPrediction.header.stamp``),
so the hops of one prediction add up to its end to end latency:

- acquisition: publication of the /eeg/raw chunk that holds that sample - the sample's
  acquisition time (the amplifier's block, the LSL transfer and the wait for the acquisition
  node's next pull; a window that ends inside a chunk also waits for the rest of the chunk).
- classifier: prediction published - publication of that chunk.
- controller: the first ``/arm_controller/commands`` published after the prediction - the
  prediction's publication (the controller acts on a timer, so this includes the wait for its
  next tick).
- end to end: that command's publication - the sample's acquisition time.

Usage::

    report = latency_report(stamps)        # stamps: RunStamps
    print(format_report(report))           # text; format_markdown(report) for report.md
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ['HOPS', 'LatencyError', 'RunStamps', 'format_markdown', 'format_report',
           'latency_report', 'summarize_ms']

#: hop key -> (from, to): the order of the loop
HOPS: dict[str, tuple[str, str]] = {
    'acquisition': ('EEG sample', '/eeg/raw'),
    'classifier': ('/eeg/raw', '/bci/prediction'),
    'controller': ('/bci/prediction', '/arm_controller/commands'),
}

# stamps further apart than this from their publication are not on the same clock (a lock-step
# run stamps messages with simulated time while DDS stamps them with the wall clock)
_SAME_CLOCK_NS = 60 * 10**9
# publication times before 2001 are simulated time (a lock-step run's clock starts at 0): its
# "latencies" would be the simulation's step, not the machine's
_WALL_CLOCK_MIN_NS = 10**18


class LatencyError(ValueError):
    """The bag cannot give latencies; the message says why and what to do."""


@dataclass
class RunStamps:
    """Stamps of one run, all in ns on the ROS clock of a live run (wall time).

    Attributes:
        chunk_first_ns: shape (n_chunks,): acquisition time of each /eeg/raw chunk's first sample.
        chunk_last_ns: shape (n_chunks,): acquisition time of its last sample.
        chunk_pub_ns: shape (n_chunks,): when each chunk was published.
        pred_stamp_ns: shape (n_predictions,): last sample of each decoded window.
        pred_pub_ns: shape (n_predictions,): when each prediction was published.
        command_pub_ns: shape (n_commands,): when each arm command was published.
        cue_ns: (trial, phase) -> the prompt's stamp (when the trainer asked for it).
        flip_ns: (trial, phase) -> the display's flip stamp (/display/flip).
        periodic_ns: topic -> shape (n,) publication times, for the jitter table.
        nominal_period_s: topic -> nominal period (s) from the run's parameters.
        notes: What the bag reader skipped or recovered (damaged chunks, unfinished files),
            as sentences; they go into the report's notes.
    """

    chunk_first_ns: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    chunk_last_ns: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    chunk_pub_ns: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    pred_stamp_ns: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    pred_pub_ns: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    command_pub_ns: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    cue_ns: dict[tuple[int, str], int] = field(default_factory=dict)
    flip_ns: dict[tuple[int, str], int] = field(default_factory=dict)
    periodic_ns: dict[str, np.ndarray] = field(default_factory=dict)
    nominal_period_s: dict[str, float] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def summarize_ms(values_ns: np.ndarray) -> dict[str, Any]:
    """``{'p50_ms', 'p95_ms', 'p99_ms', 'mean_ms', 'max_ms', 'count'}`` of durations (ns in).

    Percentiles are None when there are no values (count 0).
    """
    v = np.asarray(values_ns, dtype=np.float64) * 1e-6
    if not v.size:
        return {'p50_ms': None, 'p95_ms': None, 'p99_ms': None, 'mean_ms': None,
                'max_ms': None, 'count': 0}
    p50, p95, p99 = np.percentile(v, [50, 95, 99])
    return {'p50_ms': round(float(p50), 3), 'p95_ms': round(float(p95), 3),
            'p99_ms': round(float(p99), 3), 'mean_ms': round(float(v.mean()), 3),
            'max_ms': round(float(v.max()), 3), 'count': int(v.size)}


def latency_report(stamps: RunStamps) -> dict[str, Any]:
    """Per hop and end to end latency, cue-to-flip delay and periodic-topic jitter.

    Returns:
        ``{'end_to_end': stats, 'hops': {hop: {**stats, 'from', 'to'}}, 'cue_to_flip': stats
        or None, 'jitter': {topic: {...}}, 'notes': [str]}``; stats as :func:`summarize_ms`.

    Raises:
        LatencyError: no EEG chunks, no predictions, no commands to pair, or stamps on
            simulated time.
    """
    s = stamps
    if not s.chunk_pub_ns.size:
        msg = ('The run has no /eeg/raw messages, so there is no EEG sample to time; record a '
               'live run with EEG (e.g. `mindgrasp launch demo`).')
        raise LatencyError(msg)
    lag = np.median(np.abs(s.chunk_pub_ns - s.chunk_last_ns))
    if lag > _SAME_CLOCK_NS or np.median(s.chunk_pub_ns) < _WALL_CLOCK_MIN_NS:
        msg = ('The run\'s /eeg/raw stamps are not on the wall clock (a lock-step run on '
               'simulated time); latencies need a live run (`mindgrasp launch demo`).')
        raise LatencyError(msg)
    for missing, times in (('/bci/prediction', s.pred_pub_ns),
                           ('/arm_controller/commands', s.command_pub_ns)):
        if not times.size:
            msg = (f'The run has no {missing} messages to pair with its EEG, so there is no end '
                   'to end latency; record a run with the classifier and the controller (e.g. '
                   '`mindgrasp launch demo`).')
            raise LatencyError(msg)
    # the chunk that holds each window's last sample: the first chunk whose last sample is at or
    # after the window's end (half a microsecond of slack for the rounding of stamps)
    idx = np.searchsorted(s.chunk_last_ns, s.pred_stamp_ns - 500, side='left')
    ok = idx < s.chunk_last_ns.size
    ok[ok] &= s.chunk_first_ns[idx[ok]] <= s.pred_stamp_ns[ok] + 500
    # the controller's next command after each prediction
    nxt = np.searchsorted(s.command_pub_ns, s.pred_pub_ns, side='left')
    ok &= nxt < s.command_pub_ns.size
    if not ok.any():
        msg = (f'None of the run\'s {s.pred_stamp_ns.size} predictions pairs with a recorded '
               '/eeg/raw chunk and a later command (their stamps are on different clocks, or '
               'the recorder missed the EEG); record a live run with `mindgrasp launch demo`.')
        raise LatencyError(msg)
    notes = list(s.notes)
    if not ok.all():
        notes.append(f'{int((~ok).sum())} of {ok.size} predictions were left out: the /eeg/raw '
                     'chunk of their last sample or a later command is not in the bag (recorded '
                     'before the recorder started or after it stopped, or in a damaged chunk).')
    sample, chunk_pub = s.pred_stamp_ns[ok], s.chunk_pub_ns[idx[ok]]
    pred_pub, command_pub = s.pred_pub_ns[ok], s.command_pub_ns[nxt[ok]]
    hops = {'acquisition': summarize_ms(chunk_pub - sample),
            'classifier': summarize_ms(pred_pub - chunk_pub),
            'controller': summarize_ms(command_pub - pred_pub)}
    end_to_end = command_pub - sample
    keys = sorted(set(s.cue_ns) & set(s.flip_ns))
    cue_to_flip = (summarize_ms(np.array([s.flip_ns[k] - s.cue_ns[k] for k in keys], np.int64))
                   if s.flip_ns else None)
    return {'end_to_end': summarize_ms(end_to_end),
            'hops': {k: {'from': HOPS[k][0], 'to': HOPS[k][1], **v} for k, v in hops.items()},
            'cue_to_flip': cue_to_flip, 'jitter': _jitter(s), 'notes': notes}


def _jitter(s: RunStamps) -> dict[str, Any]:
    """Per periodic topic: nominal and measured rate, |interval - nominal period| percentiles."""
    out: dict[str, Any] = {}
    for topic, t in sorted(s.periodic_ns.items()):
        if t.size < 3:
            continue
        dt = np.diff(np.sort(t)).astype(np.float64)
        nominal = s.nominal_period_s.get(topic)
        source = 'parameter'
        if nominal is None:
            nominal, source = float(np.median(dt)) * 1e-9, 'median interval'
        dev = np.abs(dt - nominal * 1e9)
        out[topic] = {'nominal_hz': round(1.0 / nominal, 3), 'nominal_from': source,
                      'measured_hz': round(1e9 / float(dt.mean()), 3),
                      **summarize_ms(dev)}
    return out


def _fmt(v: float | None) -> str:
    return '-' if v is None else f'{v:.1f}'


def _rows(report: dict[str, Any]) -> list[tuple[str, dict[str, Any]]]:
    rows = [(f'{h["from"]} -> {h["to"]}', h) for h in report['hops'].values()]
    rows.append(('end to end (EEG sample -> command)', report['end_to_end']))
    if report.get('cue_to_flip'):
        rows.append(('cue -> display flip', report['cue_to_flip']))
    return rows


def format_report(report: dict[str, Any]) -> str:
    """Plain-text tables (latency in ms, jitter in ms) for the terminal."""
    lines = [f'{"latency (ms)":<44}{"p50":>8}{"p95":>8}{"p99":>8}{"count":>8}']
    for name, st in _rows(report):
        lines.append(f'{name:<44}{_fmt(st["p50_ms"]):>8}{_fmt(st["p95_ms"]):>8}'
                     f'{_fmt(st["p99_ms"]):>8}{st["count"]:>8}')
    if report['jitter']:
        lines += ['', f'{"jitter |interval - nominal| (ms)":<34}{"nominal Hz":>11}'
                      f'{"measured":>9}{"p50":>7}{"p95":>7}{"p99":>7}{"count":>7}']
        for topic, j in report['jitter'].items():
            lines.append(f'{topic:<34}{j["nominal_hz"]:>11.2f}{j["measured_hz"]:>9.2f}'
                         f'{_fmt(j["p50_ms"]):>7}{_fmt(j["p95_ms"]):>7}{_fmt(j["p99_ms"]):>7}'
                         f'{j["count"]:>7}')
    lines += [f'note: {n}' for n in report['notes']]
    return '\n'.join(lines)


def format_markdown(report: dict[str, Any]) -> str:
    """The ``## Timing`` section of a run's report.md."""
    lines = ['## Timing', '',
             'From the recorded stamps (publication = DDS source timestamp); see '
             '`mindgrasp bag latency RUN --json`.', '',
             '| hop | p50 ms | p95 ms | p99 ms | count |', '|---|---:|---:|---:|---:|']
    for name, st in _rows(report):
        lines.append(f'| {name} | {_fmt(st["p50_ms"])} | {_fmt(st["p95_ms"])} | '
                     f'{_fmt(st["p99_ms"])} | {st["count"]} |')
    if report['jitter']:
        lines += ['', '| topic | nominal Hz (from) | measured Hz | jitter p50 ms | p95 ms | '
                      'p99 ms | intervals |', '|---|---|---:|---:|---:|---:|---:|']
        for topic, j in report['jitter'].items():
            lines.append(f'| {topic} | {j["nominal_hz"]:.2f} ({j["nominal_from"]}) | '
                         f'{j["measured_hz"]:.2f} | {_fmt(j["p50_ms"])} | {_fmt(j["p95_ms"])} '
                         f'| {_fmt(j["p99_ms"])} | {j["count"]} |')
    lines += ['', *[f'- {n}' for n in report['notes']]]
    return '\n'.join(lines).rstrip() + '\n'
