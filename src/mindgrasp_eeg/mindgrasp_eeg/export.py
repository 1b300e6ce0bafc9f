"""Export the EEG of a recorded session (rosbag2) to a file MNE reads: FIF or EDF (ROS-free).

The bag is read with :class:`mindgrasp_bag.reader.BagReader` and the project's typestore (which
registers ``mindgrasp_msgs`` from its ``.msg`` files). Samples are placed by
``EEGChunk.first_sample_index``, so the exported time axis is the amplifier's: sample ``i`` lies
``i / sample_rate`` seconds after the first one, whose ROS stamp becomes the file's measurement
date. Samples the acquisition never received (drops, a lost stream) are written as zeros and
covered by a ``BAD_gap`` annotation.

Annotations (onset in seconds from the first sample, from the message header stamps):

- ``/trainer/prompt`` -> ``prompt/<phase>/<class>`` with the phase's planned duration
  (e.g. ``prompt/cue/left_hand``, ``prompt/fixation/rest``),
- ``/task/target`` -> ``target/<colour> <shape>``, lasting until the next target,
- ``/virtual_subject/intent`` (virtual amplifier ground truth) -> ``intent/<class>``,
- ``/task/result`` -> ``result/success/<desired object>`` or ``result/failure/<desired object>``
  spanning the trial (onset = result stamp - trial duration),
- ``/fsm/state`` -> ``state/<n> <name>`` at each change of the controller state, lasting until the
  next change,
- ``/eeg/markers`` (the amplifier's or a stimulus PC's LSL markers, relayed by the acquisition
  node with ``marker_stream``) -> the marker string as sent (e.g. ``T1``), duration 0.

MNE selects annotations by their ``/``-separated tags, so ``epochs['success']`` or
``epochs['target']`` epoch by trial outcome or target. The raw data get the standard 10-20
montage (:func:`~.montage.standard_montage`: positions of the channels it knows; others stay
without position); FIF keeps it, EDF has no field for positions
(``raw.set_montage(standard_montage())`` after reading).

Units: EEGChunk data are volts; MNE keeps volts (FIF float32; EDF scales to 16-bit per channel).
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np

from mindgrasp_common.types import Recording
from mindgrasp_ros.topics import (
    EEG_MARKERS,
    EEG_RAW,
    FSM_STATE,
    TASK_RESULT,
    TASK_TARGET,
    TRAINER_PROMPT,
    VIRTUAL_SUBJECT_INTENT,
)

from . import EEGError
from .event_markers import prompt_marker, result_marker, state_marker, target_marker
from .montage import standard_montage

FORMATS = ('fif', 'edf')


def find_bag(path: str | Path) -> Path:
    """The rosbag2 folder of a run directory (``<run>/bag``) or the bag folder itself."""
    p = Path(path)
    for cand in (p / 'bag', p):
        if (cand / 'metadata.yaml').is_file():
            return cand
    for cand in (p / 'bag', p):      # a recorder killed before metadata.yaml: its .mcap files
        if cand.is_dir() and any(cand.glob('*.mcap')):
            return cand
    msg = f'{str(p)!r} is neither a run directory with a bag nor a rosbag2 folder; check the path.'
    raise EEGError(msg)


def _typestore():
    from mindgrasp_ros.typesupport import typestore

    return typestore()


def _stamp_ns(header: object) -> int:
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def read_session(path: str | Path, eeg_topic: str = EEG_RAW.name) -> Recording:
    """Read EEG and annotation topics of a run directory or bag: a :class:`Recording` (volts, NaN
    where samples were lost, ``start_ns`` the ROS time of sample 0) with the annotations above.

    Raises
    ------
    EEGError
        No bag, no EEG on ``eeg_topic``, or an unreadable bag.
    """
    from mindgrasp_bag.reader import BagReader

    bag = find_bag(path)
    store = _typestore()
    chunks: list[tuple[int, int, np.ndarray]] = []          # (first index, stamp ns, data)
    events: list[tuple[int, float, str]] = []              # (stamp ns, duration s, description)
    layout: tuple[float, tuple[str, ...]] | None = None
    states: list[tuple[int, str]] = []                    # (stamp ns, description)
    targets: list[tuple[int, str]] = []                   # (stamp ns, description)
    skipped = 0
    try:
        # every bag tool's reader: a damaged chunk costs only its own messages (their samples
        # become a BAD_gap), a recorder killed mid-run leaves its complete records readable
        with BagReader(bag) as reader:
            wanted = {eeg_topic, TRAINER_PROMPT.name, TASK_TARGET.name,
                      VIRTUAL_SUBJECT_INTENT.name, TASK_RESULT.name, FSM_STATE.name,
                      EEG_MARKERS.name} & set(reader.topics)
            if eeg_topic not in wanted:
                wanted = set()    # no EEG: reported below
            for topic, t_log, raw in (reader.messages(wanted) if wanted else ()):
                msg = store.deserialize_cdr(raw, reader.topics[topic].type)
                if topic == eeg_topic:
                    this = (float(msg.sample_rate), tuple(msg.channel_names))
                    layout = layout or this
                    if this != layout:
                        skipped += 1                     # a reconnection to another layout
                        continue
                    data = np.asarray(msg.data, dtype=np.float64).reshape(
                        int(msg.n_samples), len(this[1]))
                    chunks.append((int(msg.first_sample_index), _stamp_ns(msg.header), data))
                elif topic == TRAINER_PROMPT.name:
                    events.append((_stamp_ns(msg.header), float(msg.duration),
                                   prompt_marker(msg.phase, msg.class_index)))
                elif topic == TASK_TARGET.name:
                    targets.append((_stamp_ns(msg.header) or t_log,
                                    target_marker(msg.colour, msg.shape)))
                elif topic == TASK_RESULT.name:
                    end = _stamp_ns(msg.header) or t_log
                    events.append((end - round(float(msg.duration) * 1e9), float(msg.duration),
                                   result_marker(msg.success, msg.desired_object)))
                elif topic == FSM_STATE.name:
                    states.append((_stamp_ns(msg.header) or t_log,
                                   state_marker(msg.state, msg.state_name)))
                elif topic == EEG_MARKERS.name:
                    events.append((_stamp_ns(msg.header), 0.0, msg.data or 'marker'))
                else:
                    events.append((t_log, 0.0, f'intent/{msg.data}'))
    except EEGError:
        raise
    except Exception as exc:
        msg = (f'Cannot read the bag {str(bag)!r} ({type(exc).__name__}: {exc}); check that it '
               f'is a complete rosbag2 recording.')
        raise EEGError(msg) from exc
    if not chunks or layout is None:
        msg = (f'The bag {str(bag)!r} holds no EEG on {eeg_topic!r}; record the acquisition '
               f'node (or pass the topic the EEG was recorded on).')
        raise EEGError(msg)
    fs, names = layout
    # controller states: one annotation per change, lasting until the next change (s)
    states.sort()
    changes = [st for k, st in enumerate(states) if k == 0 or st[1] != states[k - 1][1]]
    for (t, desc), nxt in zip(changes, [c[0] for c in changes[1:]] + [None] * bool(changes),
                               strict=True):  # no states (no controller): no annotation
        events.append((t, 1e9 if nxt is None else (nxt - t) * 1e-9, desc))  # last: to the end
    # a target is in force until the next one
    targets.sort()
    for (t, desc), nxt in zip(targets, [c[0] for c in targets[1:]] + [None] * bool(targets),
                               strict=True):
        events.append((t, 1e9 if nxt is None else (nxt - t) * 1e-9, desc))
    chunks.sort(key=lambda c: c[0])
    i0 = chunks[0][0]
    n_total = chunks[-1][0] + len(chunks[-1][2]) - i0
    data = np.full((n_total, len(names)), np.nan)
    have = np.zeros(n_total, dtype=bool)
    for first, _stamp, block in chunks:
        data[first - i0:first - i0 + len(block)] = block
        have[first - i0:first - i0 + len(block)] = True
    start_ns = chunks[0][1]
    end = n_total / fs
    # an interval that began before the first sample (a target named, or a state entered, while
    # the EEG was starting) is kept from sample 0 on: it is in force when the EEG begins
    ann = []
    for t, d, desc in sorted(events):
        on = (t - start_ns) * 1e-9
        if on < 0 and on + d > 0:
            on, d = 0.0, on + d
        if 0 <= on < end:
            ann.append((on, min(d, end - on), desc))
    # gaps as BAD_ annotations so MNE excludes them from epochs
    edges = np.flatnonzero(np.diff(np.concatenate([[1], have.astype(np.int8), [1]])))
    for a, b in zip(edges[::2], edges[1::2], strict=True):
        ann.append((a / fs, (b - a) / fs, 'BAD_gap'))
    if skipped:
        ann.append((0.0, 0.0, f'note/{skipped} chunks with another channel layout skipped'))
    return Recording(data, fs, list(names), annotations=sorted(ann), source=str(bag),
                     first_sample_index=i0, start_ns=start_ns)


def to_raw(recording: Recording):
    """An ``mne.io.RawArray`` (volts, EEG channels; lost samples as zeros, under their
    ``BAD_gap`` annotations) with annotations and measurement date."""
    import mne

    info = mne.create_info(recording.channels, recording.rate, 'eeg')
    raw = mne.io.RawArray(np.nan_to_num(recording.data, nan=0.0).T, info, verbose='error')
    raw.set_meas_date(dt.datetime.fromtimestamp(recording.start_ns * 1e-9, tz=dt.timezone.utc))
    # electrode positions for topographies and source analysis; channels outside 10-20 keep none
    raw.set_montage(standard_montage(), on_missing='ignore', match_case=False, verbose='error')
    if recording.annotations:
        onset, duration, desc = zip(*recording.annotations, strict=True)
        raw.set_annotations(mne.Annotations(onset, duration, desc,
                                            orig_time=raw.info['meas_date']))
    return raw


def default_output(path: str | Path, fmt: str) -> Path:
    """``<run dir>/eeg_raw.fif`` (or ``eeg.edf``), next to the bag of ``path``."""
    bag = find_bag(path)
    base = bag.parent if bag.name == 'bag' else bag
    return base / ('eeg_raw.fif' if fmt == 'fif' else 'eeg.edf')


def write_recording(recording: Recording, out: str | Path, fmt: str = 'fif',
                    overwrite: bool = False) -> Path:
    """Write ``recording`` (as :func:`read_session` returns it) as FIF or EDF to ``out``."""
    if fmt not in FORMATS:
        msg = f'The export format must be one of {FORMATS}; {fmt!r} is not supported.'
        raise EEGError(msg)
    out = Path(out)
    if out.exists() and not overwrite:
        msg = f'{str(out)!r} exists already; pass --overwrite or another --output.'
        raise EEGError(msg)
    raw = to_raw(recording)
    if fmt == 'fif':
        raw.save(out, overwrite=True, verbose='error')
    else:
        import mne

        mne.export.export_raw(out, raw, fmt='edf', overwrite=True, verbose='error')
    return out


def export_session(path: str | Path, output: str | Path | None = None, fmt: str = 'fif',
                   eeg_topic: str = EEG_RAW.name, overwrite: bool = False) -> Path:
    """Write the EEG of a run directory or bag as FIF or EDF; returns the file written.

    The default output is ``<run dir>/eeg_raw.fif`` (or ``eeg.edf``) next to the bag.
    """
    if fmt not in FORMATS:
        msg = f'The export format must be one of {FORMATS}; {fmt!r} is not supported.'
        raise EEGError(msg)
    recording = read_session(path, eeg_topic)
    return write_recording(recording, output or default_output(path, fmt), fmt, overwrite)
