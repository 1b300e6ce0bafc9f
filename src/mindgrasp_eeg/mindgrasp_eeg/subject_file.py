"""Replay subjects: the recordings of one person, in a calibration set and a play set (ROS-free).

A replay subject (:class:`~mindgrasp_eeg.replay_eeg.ReplayEEG`) streams real imagery epochs of
the class it intends; the classifier that decodes it is calibrated on *other* recordings of the
same person. :class:`SubjectFiles` says which recordings are which and how their annotations map
to our classes. It comes from one of two sources (:func:`replay_subject`):

``eegmmidb:<n>``
    The built-in description of EEGMMIDB subject ``n`` (:func:`eegmmidb_subject`): calibration
    on imagery runs :data:`EEGMMIDB_CALIBRATION_RUNS`, play of :data:`EEGMMIDB_PLAY_RUNS`
    (T1/T2 of runs 4, 8, 12 -> left/right hand, of 6, 10, 14 -> both hands/feet, T0 rest), files
    through MNE's EEGMMIDB loader (``MNE_DATASETS_EEGBCI_PATH``, else it downloads).
``path/to/subject.yaml``
    A subject file (:func:`load_subject_file`) naming any EDF/BDF/GDF/FIF/XDF recordings::

        # a replay subject: recordings of one person
        events: {T0: rest, T1: left_hand, T2: right_hand}   # default annotation -> class map
        channels: motor             # optional: the classifier's channels (motor, all or names)
        calibration:                # the classifier is calibrated on these, never streamed
          - eegbci:1:4
          - {file: eegbci:1:6, events: {T0: rest, T1: both_hands, T2: both_feet}}
        play:                       # streamed in the loop when the subject imagines a class
          - session1.xdf            # paths are relative to this file
          - {file: eegbci:1:10, events: {T0: rest, T1: both_hands, T2: both_feet}}

    A recording is a path (relative to the subject file) or ``eegbci:<subject>:<run>[,<run>]``
    (EEGMMIDB runs through MNE's loader). ``events`` maps annotation descriptions (EDF/GDF
    annotations, FIF annotations, XDF string markers; GDF cue codes such as ``769`` too) to
    ``left_hand``, ``right_hand``, ``both_hands``, ``both_feet`` or ``rest``; an entry's own
    ``events`` replaces the default map, and annotations not in the map are ignored. An epoch runs
    for the annotation's duration or, for markers without one, up to the next annotation (at most
    :data:`~mindgrasp_eeg.replay_eeg.MAX_EPOCH_S`).

Every recording of a subject must have the same channels and sample rate, and no recording may
be in both sets: the classifier must never see the epochs played in the loop. Bad input raises
:class:`~mindgrasp_eeg.EEGError` with one line naming the problem and the fix.

    >>> subject = replay_subject('eegmmidb:1')             # doctest: +SKIP
    >>> [f.entry for f in subject.calibration]              # doctest: +SKIP
    ['eegbci:1:4', 'eegbci:1:6']
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from mindgrasp_common.cli_checks import yaml_error_text
from mindgrasp_common.errors import CommonError
from mindgrasp_common.mi import CLASS_NAMES, class_index
from mindgrasp_common.types import Recording

from . import EEGError

__all__ = ['EEGMMIDB_CALIBRATION_RUNS', 'EEGMMIDB_EVENTS', 'EEGMMIDB_PLAY_RUNS', 'ReplayFile',
           'SubjectFiles', 'check_layout', 'eegmmidb_subject', 'is_replay_source',
           'load_subject_file', 'parse_replay_source', 'replay_subject']

#: EEGMMIDB imagery run -> {annotation: class index, None = rest}
EEGMMIDB_EVENTS: dict[int, dict[str, int | None]] = {
    **{r: {'T0': None, 'T1': 0, 'T2': 1} for r in (4, 8, 12)},    # left fist, right fist
    **{r: {'T0': None, 'T1': 2, 'T2': 3} for r in (6, 10, 14)},   # both fists, both feet
}
#: runs the classifier is calibrated on / runs played in the loop (disjoint) of a subject with
#: the imagery runs 4, 6, 8, 10 (S001 here); :func:`eegmmidb_runs` chooses them per subject
EEGMMIDB_CALIBRATION_RUNS = (4, 6)
EEGMMIDB_PLAY_RUNS = (8, 10)
#: EEGMMIDB's imagery runs: left/right fist, both fists/feet
EEGMMIDB_LR_RUNS = (4, 8, 12)
EEGMMIDB_HF_RUNS = (6, 10, 14)
#: the names an event map may use: our classes, and rest
EVENT_NAMES = (*CLASS_NAMES, 'rest')
SUBJECT_SUFFIXES = ('.yaml', '.yml')
_KEYS = ('events', 'channels', 'calibration', 'play')
_SETS = ('calibration', 'play')


@dataclass(frozen=True)
class ReplayFile:
    """One recording of a replay subject.

    Attributes
    ----------
    path : Path
        The EEG file (resolved; ``eegbci:`` references through MNE's loader).
    events : mapping str -> int or None
        Annotation description -> class index (0..3), None for rest.
    entry : str
        The recording as the subject description names it (for messages and provenance).
    """

    path: Path
    events: Mapping[str, int | None]
    entry: str


@dataclass(frozen=True)
class SubjectFiles:
    """A replay subject: which recordings calibrate the classifier and which are played.

    Attributes
    ----------
    name : str
        Short name for files (``eegmmidb_s001``, or the subject file's stem).
    source : str
        What selects this subject: ``eegmmidb:<n>`` or the subject file's absolute path (the
        virtual amplifier node's ``eeg_source``).
    calibration, play : tuple of ReplayFile
        Disjoint sets of recordings.
    channels : str or tuple of str
        The classifier's channels: ``motor`` (default), ``all`` or names.
    """

    name: str
    source: str
    calibration: tuple[ReplayFile, ...]
    play: tuple[ReplayFile, ...]
    channels: str | tuple[str, ...] = 'motor'

    def recordings(self, which: str) -> list[Recording]:
        """Load the ``'calibration'`` or ``'play'`` recordings (volts), checked: one channel
        layout and rate (:func:`check_layout`), and every event map entry matching an annotation
        of the files it applies to."""
        from .player import load_recording

        files = getattr(self, which)
        recs = [load_recording(f.path) for f in files]
        check_layout(recs, self.source)
        seen = {label for rec in recs for _o, _d, label in rec.annotations}
        for key in sorted({k for f in files for k in f.events} - seen):
            labels = sorted(seen)
            shown = labels[:12] + (['...'] if len(labels) > 12 else [])
            msg = (f'{self.source}: the event map entry {key!r} matches no annotation of the '
                   f'{which} recordings (they have {shown}); fix the annotation name or drop '
                   'the entry.')
            raise EEGError(msg)
        return recs

    def calibration_digest(self) -> str:
        """SHA-256 (hex) of what the calibrated classifier depends on: the channel selection and,
        per calibration recording, its event map and file content. A model cached under this
        digest is stale as soon as any of these changes."""
        h = hashlib.sha256(repr(self.channels).encode())
        for f in self.calibration:
            h.update(repr(sorted(f.events.items(), key=str)).encode())
            with f.path.open('rb') as stream:
                for block in iter(lambda: stream.read(1 << 20), b''):
                    h.update(block)
        return h.hexdigest()


def check_layout(recordings: Sequence[Recording], source: str) -> None:
    """Raise :class:`EEGError` unless all ``recordings`` have the first one's channels and rate."""
    if not recordings:
        return
    first = recordings[0]
    for rec in recordings[1:]:
        if rec.rate != first.rate:
            msg = (f'{source}: {rec.source} is sampled at {rec.rate:g} Hz but {first.source} at '
                   f'{first.rate:g} Hz; all recordings of a replay subject need one sample rate '
                   '(resample it or leave it out).')
            raise EEGError(msg)
        if rec.channels != first.channels:
            extra = [c for c in rec.channels if c not in first.channels]
            missing = [c for c in first.channels if c not in rec.channels]
            what = (f'lacks {missing[:6]} and has {extra[:6]}' if missing or extra
                    else 'has them in another order')
            msg = (f'{source}: {rec.source} has other channels than {first.source} (it {what}); '
                   'all recordings of a replay subject need the same channels in the same order '
                   '(re-export it or leave it out).')
            raise EEGError(msg)


def parse_replay_source(text: str) -> int:
    """``'eegmmidb:1'`` -> subject 1 (raises :class:`EEGError` naming the form)."""
    kind, _, subject = text.partition(':')
    if kind.lower() != 'eegmmidb' or not subject.strip().lstrip('Ss').isdigit():
        msg = (f'{text!r} is not a replay subject; write eegmmidb:<subject>, e.g. eegmmidb:1 '
               '(EEGMMIDB subjects 1-109), or the path of a subject file (.yaml).')
        raise EEGError(msg)
    number = int(subject.strip().lstrip('Ss'))
    if not 1 <= number <= 109:
        msg = f'{text!r}: EEGMMIDB has subjects 1-109; write e.g. eegmmidb:1.'
        raise EEGError(msg)
    return number


#: what the virtual amplifier's ``eeg_source`` may be, for messages
EEG_SOURCE_FORMS = ('synthetic (the head model), eegmmidb:<subject> (EEGMMIDB subjects 1-109) or '
                    'the path of a subject file (.yaml)')


def check_eeg_source(text: str) -> None:
    """Raise :class:`EEGError` unless ``text`` is a valid ``eeg_source`` (:data:`EEG_SOURCE_FORMS`):
    launch profiles check it before any node starts. Reads no recording."""
    if text == 'synthetic':
        return
    if text.lower().endswith(SUBJECT_SUFFIXES):
        if not Path(text).expanduser().is_file():
            msg = f'the subject file {text!r} does not exist; give {EEG_SOURCE_FORMS}.'
            raise EEGError(msg)
        return
    if not text.lower().startswith('eegmmidb:'):
        msg = f'{text!r} is not an EEG source; give {EEG_SOURCE_FORMS}.'
        raise EEGError(msg)
    parse_replay_source(text)   # its message names the subject range


def is_replay_source(text: str) -> bool:
    """A replay subject (``eegmmidb:<n>`` or a subject file ``*.yaml``/``*.yml``)?"""
    return text.lower().startswith('eegmmidb:') or text.lower().endswith(SUBJECT_SUFFIXES)


def replay_subject(text: str) -> SubjectFiles:
    """The replay subject named by ``text``: ``eegmmidb:<n>`` or a subject file's path."""
    if text.lower().endswith(SUBJECT_SUFFIXES):
        return load_subject_file(text)
    return eegmmidb_subject(parse_replay_source(text))


def eegmmidb_local_runs(number: int) -> tuple[int, ...] | None:
    """The imagery runs of EEGMMIDB subject ``number`` present in ``MNE_DATASETS_EEGBCI_PATH``
    (MNE's folder layout); None when that folder is not set or holds none of them (MNE may
    then download all six)."""
    import os

    root = os.environ.get('MNE_DATASETS_EEGBCI_PATH')
    if not root:
        return None
    folder = Path(root) / 'MNE-eegbci-data' / 'files' / 'eegmmidb' / '1.0.0' / f'S{number:03d}'
    runs = tuple(r for r in sorted((*EEGMMIDB_LR_RUNS, *EEGMMIDB_HF_RUNS))
                 if (folder / f'S{number:03d}R{r:02d}.edf').is_file())
    return runs or None


def eegmmidb_runs(present: Sequence[int] | None) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """(calibration runs, play runs) of an EEGMMIDB subject with the imagery runs ``present``
    (None: all six).

    The play runs are the last left/right run and the last hands/feet run, each only when the
    subject has another run of its kind left to calibrate on; every other imagery run
    calibrates. Runs 4, 6, 8, 10 (S001 here) give calibration 4, 6 and play 8, 10; all six
    give 4, 6, 8, 10 and 12, 14; runs 4, 6, 8, 12 (S006-S012 here) give 4, 6, 8 and 12 only,
    so such a subject's play data hold no both hands / both feet epochs.
    """
    runs = tuple(sorted(present)) if present else (*EEGMMIDB_LR_RUNS, *EEGMMIDB_HF_RUNS)
    play = []
    for kind in (EEGMMIDB_LR_RUNS, EEGMMIDB_HF_RUNS):
        have = [r for r in runs if r in kind]
        if len(have) >= 2:
            play.append(have[-1])
    calibration = tuple(r for r in sorted(runs) if r not in play)
    return calibration, tuple(sorted(play))


def eegmmidb_subject(number: int) -> SubjectFiles:
    """The built-in description of EEGMMIDB subject ``number`` (files through MNE's loader;
    runs by :func:`eegmmidb_runs` of the runs at hand)."""
    def files(runs: Sequence[int]) -> tuple[ReplayFile, ...]:
        return tuple(ReplayFile(_eegbci_paths(f'eegbci:{number}:{r}')[0], EEGMMIDB_EVENTS[r],
                                f'eegbci:{number}:{r}') for r in runs)

    calibration, play = eegmmidb_runs(eegmmidb_local_runs(number))
    if not play:
        msg = (f'eegmmidb:{number}: the imagery runs at hand ({list(calibration)}) leave none to '
               'play (a subject needs two runs of one kind: 4/8/12 or 6/10/14); give a subject '
               'file instead.')
        raise EEGError(msg)
    return SubjectFiles(name=f'eegmmidb_s{number:03d}', source=f'eegmmidb:{number}',
                        calibration=files(calibration), play=files(play))


def _eegbci_paths(reference: str) -> list[Path]:
    """Files of ``eegbci:<subject>:<run>[,<run>]`` through MNE's loader (errors as EEGError)."""
    from .player import expand_sources

    return [Path(p).resolve() for p in expand_sources([reference])]


def load_subject_file(path: str | Path) -> SubjectFiles:
    """Read a subject file (format in the module docstring) and resolve its recordings.

    Raises
    ------
    EEGError
        Missing file, bad YAML or structure, a missing recording, an unknown class name, a
        recording in both sets; one line naming the problem and the fix.
    """
    import yaml

    path = Path(path).expanduser().resolve()
    if not path.is_file():
        msg = (f'The subject file {str(path)!r} does not exist; give the path of a YAML subject '
               'file (format: mindgrasp_eeg.subject_file) or eegmmidb:<subject>.')
        raise EEGError(msg)
    try:
        doc = yaml.safe_load(path.read_text())
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        problem = yaml_error_text(exc)
        msg = f'The subject file {path} is not valid YAML ({problem}); fix its syntax.'
        raise EEGError(msg) from None
    where = str(path)
    if not isinstance(doc, dict):
        msg = (f'{where}: a subject file is a YAML mapping with the keys calibration, play and '
               'optionally events and channels; see mindgrasp_eeg.subject_file.')
        raise EEGError(msg)
    unknown = sorted(set(map(str, doc)) - set(_KEYS))
    if unknown:
        msg = f'{where}: unknown key(s) {unknown}; a subject file has the keys {list(_KEYS)}.'
        raise EEGError(msg)
    default = _event_map(doc['events'], where) if doc.get('events') is not None else None
    sets = {which: _entries(doc.get(which), which, default, path) for which in _SETS}
    play_paths = {f.path: f.entry for f in sets['play']}
    for f in sets['calibration']:
        if f.path in play_paths:
            msg = (f'{where}: {f.path} is in both calibration and play; the classifier must '
                   'never see the epochs played in the loop (keep it in one of them).')
            raise EEGError(msg)
    return SubjectFiles(name=re.sub(r'[^A-Za-z0-9_-]+', '_', path.stem) or 'subject',
                        source=where, calibration=sets['calibration'], play=sets['play'],
                        channels=_channels(doc.get('channels', 'motor'), where))


def _channels(value: object, where: str) -> str | tuple[str, ...]:
    if isinstance(value, str) and value.strip():
        return value.strip()
    if isinstance(value, list) and value and all(isinstance(v, str) for v in value):
        return tuple(value)
    msg = (f'{where}: channels must be motor, all or a list of channel names; '
           f'{value!r} is invalid.')
    raise EEGError(msg)


def _event_map(value: object, where: str) -> dict[str, int | None]:
    """``{annotation: class name or 'rest'}`` -> ``{annotation: class index or None}``."""
    if not isinstance(value, dict) or not value:
        msg = (f'{where}: an event map is a mapping of annotations to classes, e.g. '
               f'{{T0: rest, T1: left_hand, T2: right_hand}}; {value!r} is not one.')
        raise EEGError(msg)
    out: dict[str, int | None] = {}
    for key, name in value.items():
        if str(name).strip().lower() == 'rest':
            out[str(key)] = None
            continue
        try:
            out[str(key)] = class_index(str(name))
        except CommonError:
            msg = (f'{where}: unknown class {name!r} for the annotation {str(key)!r}; use one of '
                   f'{", ".join(EVENT_NAMES)}.')
            raise EEGError(msg) from None
    return out


def _entries(value: object, which: str, default: dict[str, int | None] | None,
             path: Path) -> tuple[ReplayFile, ...]:
    """The recordings of one set, resolved (``eegbci:`` through MNE, paths next to the file)."""
    where = str(path)
    if not isinstance(value, list) or not value:
        msg = (f'{where}: {which} must be a non-empty list of recordings (paths relative to the '
               'subject file, or eegbci:<subject>:<run>).')
        raise EEGError(msg)
    out: list[ReplayFile] = []
    for item in value:
        entry, events = item, default
        if isinstance(item, dict):
            if not isinstance(item.get('file'), str) or set(item) - {'file', 'events'}:
                msg = (f'{where}: the {which} entry {item!r} must be a path or '
                       '{file: PATH, events: {ANNOTATION: CLASS, ...}}.')
                raise EEGError(msg)
            entry = item['file']
            if item.get('events') is not None:
                events = _event_map(item['events'], where)
        if not isinstance(entry, str) or not entry.strip():
            msg = f'{where}: the {which} entry {item!r} is not a recording path; fix the entry.'
            raise EEGError(msg)
        if events is None:
            msg = (f'{where}: the {which} recording {entry!r} has no event map; give the file '
                   'a top-level events: mapping or the entry its own events:.')
            raise EEGError(msg)
        if entry.startswith('eegbci:'):
            paths = _eegbci_paths(entry)
        else:
            paths = [(path.parent / entry).expanduser().resolve()]
            if not paths[0].is_file():
                msg = (f'{where}: the {which} recording {entry!r} ({paths[0]}) does not exist; '
                       'fix its path (relative to the subject file) or remove it.')
                raise EEGError(msg)
        out += [ReplayFile(p, events, entry) for p in paths]
    return tuple(out)
