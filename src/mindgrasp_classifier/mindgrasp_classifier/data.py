"""Labelled continuous EEG for training and evaluation: EDF files and recorded run bags.

Every loader returns :class:`Recording` objects: continuous EEG in volts plus cue events
(onset sample, MIndGrasp class), so training and evaluation window the data exactly as the online
decoder does.
"""

from __future__ import annotations

import dataclasses
import itertools
import logging
import os
import re
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np

from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import CLASS_NAMES, class_index
from mindgrasp_common.errors import CommonError
from mindgrasp_common.mi import NO_CLASS, REST
from mindgrasp_common.mi import class_index as mi_class_index
from mindgrasp_common.types import Recording
from mindgrasp_ros.topics import EEG_MARKERS, EEG_RAW, TRAINER_PROMPT, VIRTUAL_SUBJECT_INTENT

#: EEGMMIDB run -> {annotation: MIndGrasp class} (../shared/data/EEGMMIDB-README.md).
EEGMMIDB_RUNS: dict[int, dict[str, int]] = {
    # PhysioNet: runs 3, 7, 11 (executed) and 4, 8, 12 (imagined) are left / right fist;
    # 5, 9, 13 and 6, 10, 14 both fists / both feet (run 12 was labelled hands/feet until
    # 2026-11-28)
    **{r: {'T1': 0, 'T2': 1} for r in (3, 4, 7, 8, 11, 12)},   # left / right fist
    **{r: {'T1': 2, 'T2': 3} for r in (5, 6, 9, 10, 13, 14)},  # both fists / both feet
}
EEGMMIDB_IMAGERY_RUNS = (4, 6, 8, 10, 12, 14)
#: EEGMMIDB's rest annotation (between every two cues, ~4.2 s), labelled :data:`REST` on request
EEGMMIDB_REST = 'T0'
_EEGMMIDB_NAME = re.compile(r'^S(\d{3})R(\d{2})\.edf$', re.IGNORECASE)


def parse_event_map(text: str) -> dict[str, int]:
    """Parse ``'T1=left_hand,T2=right_hand'`` into ``{'T1': 0, 'T2': 1}``."""
    out: dict[str, int] = {}
    for item in filter(None, (s.strip() for s in text.split(','))):
        if '=' not in item:
            msg = (f'The event map entry {item!r} has no "="; write entries as '
                   'annotation=class, e.g. T1=left_hand,T2=right_hand.')
            raise ClassifierError(msg)
        key, value = (s.strip() for s in item.split('=', 1))
        out[key] = class_index(value)
    if not out:
        msg = 'The event map is empty; give entries such as T1=left_hand,T2=right_hand.'
        raise ClassifierError(msg)
    return out


def eegmmidb_run(path: str | Path) -> tuple[int, int] | None:
    """(subject, run) if ``path`` is named like an EEGMMIDB file (SxxxRyy.edf), else None."""
    m = _EEGMMIDB_NAME.match(Path(path).name)
    return (int(m.group(1)), int(m.group(2))) if m else None


def load_edf(path: str | Path, event_map: dict[str, int] | None = None,
             rest: bool = False) -> Recording:
    """Load an EDF/BDF/GDF file (through MNE) with cue events from its annotations.

    EEGMMIDB files (SxxxRyy.edf) are labelled with the dataset's run/class mapping and their
    channel names standardised; other files need ``event_map`` (annotation -> class, which may
    map an annotation to ``rest``). ``rest`` labels EEGMMIDB's T0 annotations as rest epochs
    (class :data:`~mindgrasp_common.mi.REST`). The file's annotations are kept in
    ``Recording.annotations`` (onset s from the first sample, duration s, description), so
    evaluations can label windows by the annotation they lie in.
    """
    import mne

    path = Path(path)
    if not path.is_file():
        msg = f'The EEG file {path} does not exist; check the path.'
        raise ClassifierError(msg)
    run = eegmmidb_run(path)
    if event_map is None:
        if run is None:
            msg = (f'{path.name} is not an EEGMMIDB file (SxxxRyy.edf), so its annotations have '
                   'no known classes; pass --event-map, e.g. T1=left_hand,T2=right_hand.')
            raise ClassifierError(msg)
        if run[1] not in EEGMMIDB_RUNS:
            msg = (f'{path.name} is EEGMMIDB run {run[1]}, a baseline run without MI cues; use '
                   'runs 4, 8, 12 (left/right) or 6, 10, 14 (hands/feet).')
            raise ClassifierError(msg)
        event_map = dict(EEGMMIDB_RUNS[run[1]])
        if rest:
            event_map[EEGMMIDB_REST] = REST
    elif rest and REST not in event_map.values():
        msg = (f'Rest epochs of {path.name} need an event-map entry for its rest annotation, '
               'e.g. --event-map T0=rest,T1=left_hand,T2=right_hand (--rest alone labels '
               "EEGMMIDB's T0).")
        raise ClassifierError(msg)
    try:
        raw = mne.io.read_raw(path, preload=True, verbose='error')
    except Exception as exc:  # MNE raises many types for unreadable files
        msg = f'MNE cannot read {path} ({type(exc).__name__}: {exc}); check that it is EDF/BDF/GDF.'
        raise ClassifierError(msg) from None
    if run is not None:
        mne.datasets.eegbci.standardize(raw)
    raw.pick('eeg')
    rate = float(raw.info['sfreq'])
    events, annotations = [], []
    for ann in raw.annotations:
        label = ann['description']
        onset = int(raw.time_as_index(ann['onset'], use_rounding=True)[0])
        annotations.append((onset / rate, float(ann['duration']), str(label)))
        if label in event_map:
            events.append((onset, event_map[label]))
    return Recording(data=raw.get_data().T, rate=rate, channels=list(raw.ch_names),
                     events=np.array(events, dtype=int).reshape(-1, 2),
                     annotations=annotations, source=str(path))


def add_rest_events(rec: Recording, description: str = EEGMMIDB_REST) -> Recording:
    """``rec`` with its ``description`` annotations (EEGMMIDB: T0) added as rest events.

    Returns ``rec`` itself when it already has rest events; raises when it has no such
    annotation (recorded runs and synthetic recordings have none).
    """
    if np.any(rec.events[:, 1] == REST):
        return rec
    onsets = sorted({round(onset * rec.rate) for onset, _, name in rec.annotations
                     if name == description})
    if not onsets:
        msg = (f'{rec.source or "The recording"} has no {description!r} annotations to label as '
               'rest; rest epochs come from EEGMMIDB files (T0) or an event map such as '
               'T0=rest.')
        raise ClassifierError(msg)
    events = np.concatenate([rec.events, [(o, REST) for o in onsets]]).astype(int)
    events = events[np.argsort(events[:, 0], kind='stable')]
    return dataclasses.replace(rec, events=events)


def eegbci_files(subject: int, runs: Sequence[int], path: str | None = None) -> list[Path]:
    """Paths of EEGMMIDB runs through MNE's loader (``MNE_DATASETS_EEGBCI_PATH`` by default)."""
    import mne

    path = path or os.environ.get('MNE_DATASETS_EEGBCI_PATH')
    try:
        files = mne.datasets.eegbci.load_data(subject, list(runs), path=path, update_path=False)
    except Exception as exc:  # network or file errors from pooch/MNE
        msg = (f'MNE could not provide EEGMMIDB subject {subject} runs {list(runs)} from {path} '
               f'({type(exc).__name__}: {exc}); set MNE_DATASETS_EEGBCI_PATH to the data folder.')
        raise ClassifierError(msg) from None
    return [Path(f) for f in files]


# --------------------------------------------------------------------------- bags
LABELS = ('prompt', 'intent', 'markers')
#: a phase that ends this much before its planned end was cut short (s)
_CUT_TOLERANCE = 0.25   # prompts are stamped when published (timer ticks, load)


def aborted_trials(prompts: Sequence[object]) -> set[int]:
    """Trials cut short (a robot reset or the session's end during the trial), from the prompts.

    A trial's classed phases (``cue``/``move``/``wait``) each announce their planned duration;
    when the next prompt arrives before the current classed phase has run its planned time, the
    trainer cut the trial short (it logs such trials as aborted). ``prompts`` sorted by stamp.
    """
    def stamp(p: object) -> float:
        return p.header.stamp.sec + 1e-9 * p.header.stamp.nanosec  # type: ignore[attr-defined]

    out: set[int] = set()
    for cur, nxt in itertools.pairwise(prompts):
        if int(cur.class_index) == NO_CLASS or cur.phase not in ('cue', 'move', 'wait'):
            continue
        if stamp(nxt) < stamp(cur) + float(cur.duration) - _CUT_TOLERANCE:
            out.add(int(cur.trial))
    return out


def intent_events(changes: Sequence[tuple[float, str]], end: float, tmin: float,
                  tmax: float) -> list[tuple[float, int]]:
    """Epoch onsets labelled by the subject's intent, epochs ``[onset + tmin, onset + tmax]``
    tiling each intent without overlap (onsets ``tmax - tmin`` apart, the first at the change).

    Parameters
    ----------
    changes : sequence of (time s, class name)
        ``/virtual_subject/intent`` messages (published on change) with their receive times.
    end : float
        End of the recording (s).
    tmin, tmax : float
        Epoch limits after an onset (s), as for cue-labelled trials; an intent shorter than
        ``tmax`` gives no epoch (``--tmax 1.5`` takes shorter ones).
    """
    period = tmax - tmin
    events: list[tuple[float, int]] = []
    for (t0, name), t1 in zip(changes, [t for t, _ in changes[1:]] + [end], strict=True):
        try:
            k = mi_class_index(name)
        except CommonError:
            continue                      # 'rest' and other non-MI states
        t = t0
        while t + tmax <= t1:
            events.append((t, k))
            t += period
    return events


def load_bag(path: str | Path, eeg_topic: str = EEG_RAW.name,
             prompt_topic: str = TRAINER_PROMPT.name, *, labels: str = 'prompt',
             keep_aborted: bool = False, intent_topic: str = VIRTUAL_SUBJECT_INTENT.name,
             tmin: float = 0.5, tmax: float = 2.5,
             event_map: dict[str, int] | None = None) -> Recording:
    """Load a recorded run (rosbag2 folder) with EEG chunks and its labels.

    ``labels='prompt'``: the label of a trial is the prompt class; its onset is the first prompt
    of the trial that carries a class (the Graz ``cue`` or the trainer's ``move`` phase). Trials
    cut short (:func:`aborted_trials`) are left out unless ``keep_aborted``; their number is in
    ``n_aborted``. ``labels='intent'``: demo and experiment runs, labelled by the virtual
    subject's intent (``intent_topic``), epochs ``[tmin, tmax]`` tiling each intent
    (:func:`intent_events`). ``labels='markers'``: the amplifier's (or a stimulus PC's) LSL
    markers the acquisition node relayed to ``/eeg/markers`` (``marker_stream``), each named in
    ``event_map`` an epoch onset of its class (``{'T1': 0, 'T2': 1}``), as in an EDF or XDF file.
    Lost samples (gaps in ``first_sample_index``) are NaN, and windows over them are skipped.
    """
    if labels not in LABELS:
        msg = f"--labels must be one of {', '.join(LABELS)}; {labels!r} is invalid."
        raise ClassifierError(msg)
    if labels == 'markers' and not event_map:
        msg = ("--labels markers needs --event-map naming the markers' classes, e.g. "
               'T1=left_hand,T2=right_hand.')
        raise ClassifierError(msg)
    from mindgrasp_bag.reader import BagReader
    from mindgrasp_ros.typesupport import typestore

    path = Path(path)
    if not path.exists():
        msg = f'The bag {path} does not exist; give a run directory or its rosbag2 folder.'
        raise ClassifierError(msg)
    bag_dir = _find_bag_dir(path)
    store = typestore()
    chunks, prompts, intents, markers = [], [], [], []
    label_topic = {'prompt': prompt_topic, 'intent': intent_topic,
                   'markers': EEG_MARKERS.name}[labels]
    try:
        # every bag tool's reader: a damaged chunk costs only its own messages (their samples
        # are NaN, and windows over them are skipped)
        with BagReader(bag_dir) as reader:
            topics = set(reader.topics)
            if eeg_topic not in topics:
                msg = (f'The bag {bag_dir} has no {eeg_topic} topic (it has {sorted(topics)}); '
                       'record the EEG stream or name the EEG topic.')
                raise ClassifierError(msg)
            if labels == 'intent' and intent_topic not in topics:
                msg = (f'The bag {bag_dir} has no {intent_topic} topic, so --labels intent has '
                       'nothing to label with; it needs a run with the virtual subject (demo, '
                       'experiment), or use --labels prompt for trainer/graz runs.')
                raise ClassifierError(msg)
            if labels == 'markers' and label_topic not in topics:
                msg = (f'The bag {bag_dir} has no {label_topic} topic, so --labels markers has '
                       'nothing to label with; record with the acquisition node relaying the '
                       'marker stream (marker_stream:=auto or its name).')
                raise ClassifierError(msg)
            wanted = {eeg_topic, label_topic} & topics
            for topic, t_ns, raw in reader.messages(wanted):
                msg_obj = store.deserialize_cdr(raw, reader.topics[topic].type)
                if topic == eeg_topic:
                    chunks.append(msg_obj)
                elif labels == 'prompt':
                    prompts.append(msg_obj)
                elif labels == 'markers':
                    stamp = msg_obj.header.stamp
                    markers.append((stamp.sec + 1e-9 * stamp.nanosec, str(msg_obj.data)))
                else:
                    intents.append((t_ns * 1e-9, str(msg_obj.data)))
    except ClassifierError:
        raise
    except Exception as exc:  # rosbags raises its own error types for sqlite3 bags
        msg = f'Cannot read the bag {bag_dir} ({type(exc).__name__}: {exc}); is it a rosbag2?'
        raise ClassifierError(msg) from None
    if not chunks:
        msg = f'The bag {bag_dir} has no EEG messages on {eeg_topic}; record a run with EEG.'
        raise ClassifierError(msg)
    rate = float(chunks[0].sample_rate)
    channels = list(chunks[0].channel_names)
    n_ch = len(channels)
    base = min(int(c.first_sample_index) for c in chunks)
    stop = max(int(c.first_sample_index) + int(c.n_samples) for c in chunks)
    data = np.full((stop - base, n_ch), np.nan)
    offsets = []
    for c in chunks:
        if list(c.channel_names) != channels or float(c.sample_rate) != rate:
            msg = (f'The EEG stream in {bag_dir} changes channels or rate mid-run; split the bag '
                   'at the change.')
            raise ClassifierError(msg)
        block = np.asarray(c.data, dtype=float).reshape(int(c.n_samples), n_ch)
        if c.unit and c.unit not in ('V', 'volt', 'volts'):
            scale = {'uV': 1e-6, 'µV': 1e-6, 'mV': 1e-3}.get(c.unit)
            if scale is None:
                msg = f'Unknown EEG unit {c.unit!r} in {bag_dir}; record in V, mV or uV.'
                raise ClassifierError(msg)
            block = block * scale
        i0 = int(c.first_sample_index) - base
        data[i0:i0 + block.shape[0]] = block
        t0 = c.header.stamp.sec + 1e-9 * c.header.stamp.nanosec
        offsets.append(t0 - int(c.first_sample_index) / rate)
    # Stream time of stream index i: offset + i / rate (median over chunks: robust to jitter).
    offset = float(np.median(offsets))
    events, seen = [], set()
    timed: list[tuple[float, int]] = []
    prompts.sort(key=lambda m: (m.header.stamp.sec, m.header.stamp.nanosec))
    aborted = aborted_trials(prompts)
    n_aborted = 0
    for p in prompts:
        if int(p.class_index) == NO_CLASS or p.phase not in ('cue', 'move') or p.trial in seen:
            continue
        seen.add(p.trial)
        if int(p.trial) in aborted:
            n_aborted += 1
            if not keep_aborted:
                continue
        timed.append((p.header.stamp.sec + 1e-9 * p.header.stamp.nanosec, int(p.class_index)))
    if labels == 'intent':
        end = offset + (base + data.shape[0]) / rate
        timed = intent_events(sorted(intents), end, tmin, tmax)
    elif labels == 'markers':
        timed = [(t, event_map[text]) for t, text in sorted(markers) if text in event_map]
    for t, k in timed:
        onset = round((t - offset) * rate) - base
        if 0 <= onset < data.shape[0] and k < len(CLASS_NAMES):
            events.append((onset, k))
    return Recording(data=data, rate=rate, channels=channels,
                     events=np.array(events, dtype=int).reshape(-1, 2), source=str(bag_dir),
                     first_sample_index=base, n_aborted=n_aborted,
                     start_ns=round((offset + base / rate) * 1e9))


def _find_bag_dir(path: Path) -> Path:
    """The rosbag2 folder (with metadata.yaml) at or below ``path``."""
    if (path / 'metadata.yaml').is_file():
        return path
    if (path / 'bag' / 'metadata.yaml').is_file():   # a run directory (it may hold replays too)
        return path / 'bag'
    for cand in (path / 'bag', path):   # a recorder killed before metadata.yaml: its .mcap files
        if cand.is_dir() and any(cand.glob('*.mcap')):
            return cand
    found = sorted(p.parent for p in path.rglob('metadata.yaml'))
    if len(found) == 1:
        return found[0]
    if not found:
        msg = f'{path} holds no rosbag2 (no metadata.yaml); give the run directory of a recording.'
    else:
        msg = f'{path} holds several bags ({[str(f) for f in found]}); give one of them.'
    raise ClassifierError(msg)


def load_xdf(path: str | Path, event_map: dict[str, int] | None = None) -> Recording:
    """Load an XDF recording (LabRecorder: the amplifier's EEG and a marker stream) with cues.

    Without ``event_map`` the cues are MIndGrasp's LSL markers (``prompt/<phase>/<class>``, from
    the ``lsl_markers`` node), labelled as :func:`load_bag` labels prompts: each trial's first
    class-bearing ``cue`` or ``move`` prompt. With ``event_map`` (marker -> class) the markers it
    names are the cues (stimulus software of another lab). EEG in volts; the markers are kept
    in ``Recording.annotations``.
    """
    from mindgrasp_eeg import EEGError
    from mindgrasp_eeg.player import load_recording

    path = Path(path)
    if not path.is_file():
        msg = f'The XDF file {path} does not exist; check the path.'
        raise ClassifierError(msg)
    # pyxdf logs a warning per stream of a file without clock offsets (nothing to correct): not
    # a problem of the recording, and no line for the user
    logging.getLogger('pyxdf').setLevel(logging.ERROR)
    try:
        rec = load_recording(path)
    except EEGError as exc:
        raise ClassifierError(str(exc)) from None
    if not rec.annotations:
        msg = (f'{path.name} has no marker stream (an LSL stream of type Markers); record '
               'MIndGrasp-Markers (or your stimulus software\'s markers) beside the EEG, as '
               'LabRecorder does.')
        raise ClassifierError(msg)
    events, in_cue = [], False
    for onset, _duration, marker in rec.annotations:
        if event_map is not None:
            k = event_map.get(marker)
        else:
            parts = marker.split('/')
            if len(parts) != 3 or parts[0] != 'prompt':
                continue
            cue = parts[1] in ('cue', 'move') and parts[2] in CLASS_NAMES
            k, in_cue = (class_index(parts[2]) if cue and not in_cue else None), cue
        if k is not None:
            events.append((round(onset * rec.rate), k))
    if not events:
        msg = (f'{path.name} has markers but no cues: expected MIndGrasp prompt markers '
               '(prompt/cue/<class>); for other marker names pass --event-map, e.g. '
               'T1=left_hand,T2=right_hand.')
        raise ClassifierError(msg)
    return dataclasses.replace(rec, events=np.array(events, dtype=int).reshape(-1, 2))


def load_inputs(edf: Iterable[str] = (), bags: Iterable[str] = (), event_map: str | None = None,
                eegbci_subject: int | None = None, eegbci_runs: Sequence[int] = (),
                eeg_topic: str = EEG_RAW.name,
                prompt_topic: str = TRAINER_PROMPT.name, *, labels: str = 'prompt',
                keep_aborted: bool = False, intent_topic: str = VIRTUAL_SUBJECT_INTENT.name,
                tmin: float = 0.5, tmax: float = 2.5, rest: bool = False,
                xdf: Iterable[str] = ()) -> list[Recording]:
    """Load every input named on a command line; raises if none is given.

    ``rest`` labels rest epochs of EDF files (:func:`load_edf`); recorded runs have no rest
    labels, so it refuses bags.
    """
    bags = list(bags)
    if rest and bags:
        msg = ('Rest epochs come from EDF files (EEGMMIDB T0, or an event map entry such as '
               'T0=rest); recorded runs have no rest labels, so train rest on EDF data or leave '
               'out --rest.')
        raise ClassifierError(msg)
    emap = parse_event_map(event_map) if event_map else None
    recs = [load_edf(p, emap, rest=rest) for p in edf]
    recs += [load_xdf(p, emap) for p in xdf]
    if eegbci_subject is not None:
        recs += [load_edf(p, rest=rest)
                 for p in eegbci_files(eegbci_subject, eegbci_runs or (4, 6, 8, 10))]
    recs += [load_bag(p, eeg_topic, prompt_topic, labels=labels, keep_aborted=keep_aborted,
                      intent_topic=intent_topic, tmin=tmin, tmax=tmax, event_map=emap)
             for p in bags]
    if not recs:
        msg = 'No input data; give --edf FILES, --xdf FILES, --bag RUNS or --eegbci SUBJECT.'
        raise ClassifierError(msg)
    return recs
