"""Replay subjects from subject files (mindgrasp_eeg.subject_file): the loader, epochs of markers
without duration (XDF), EEGMMIDB through a subject file (S001 from MNE_DATASETS_EEGBCI_PATH,
../shared/data) and every bad input as one line naming the fix."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from mindgrasp_common.types import Recording
from mindgrasp_eeg import EEGError
from mindgrasp_eeg.player import expand_sources, load_recording
from mindgrasp_eeg.replay_eeg import MAX_EPOCH_S, ReplayEEG, epochs_of, segments
from mindgrasp_eeg.subject_file import load_subject_file, replay_subject
from mindgrasp_testing import write_graz_xdf, write_recording_xdf

HANDS_FEET = '{T0: rest, T1: both_hands, T2: both_feet}'
#: the built-in eegmmidb:1 written as a subject file: the README's example
EXAMPLE = Path(__file__).resolve().parents[2] / 'docs' / 'subjects' / 'eegmmidb_s001.yaml'
GRAZ_EVENTS = '{rest: rest, left: left_hand, right: right_hand, hands: both_hands, feet: both_feet}'


def subject_file(folder: Path, text: str, name: str = 'subject.yaml') -> Path:
    path = folder / name
    path.write_text(text)
    return path


def s001_run_as_xdf(path: Path, run: int) -> tuple[Recording, Path]:
    """EEGMMIDB S001 ``run`` (through MNE's loader) written as XDF with its annotations as string
    markers without duration; returns the EDF recording and the XDF path."""
    edf = load_recording(expand_sources([f'eegbci:1:{run}'])[0])
    markers = [(onset, label) for onset, _duration, label in edf.annotations]
    return edf, write_recording_xdf(path, edf.data, edf.rate, edf.channels, markers)


def test_a_subject_file_resolves_its_recordings_and_event_maps(tmp_path: Path) -> None:
    (tmp_path / 'data').mkdir()
    write_graz_xdf(tmp_path / 'data' / 'session1.xdf')
    path = subject_file(tmp_path, f"""
# comments are fine
events: {{T0: rest, T1: left_hand, T2: right_hand}}
calibration:
  - eegbci:1:4
  - {{file: 'eegbci:1:6', events: {HANDS_FEET}}}
play:
  - {{file: data/session1.xdf, events: {GRAZ_EVENTS}}}
""", name='my subject.yaml')
    subject = replay_subject(str(path))
    assert subject.source == str(path.resolve()) and subject.name == 'my_subject'
    assert subject.channels == 'motor'
    assert [f.entry for f in subject.calibration] == ['eegbci:1:4', 'eegbci:1:6']
    assert [f.path.name for f in subject.calibration] == ['S001R04.edf', 'S001R06.edf']
    assert subject.calibration[0].events == {'T0': None, 'T1': 0, 'T2': 1}
    assert subject.calibration[1].events == {'T0': None, 'T1': 2, 'T2': 3}
    (play,) = subject.play
    assert play.path == (tmp_path / 'data' / 'session1.xdf').resolve()
    assert play.events == {'rest': None, 'left': 0, 'right': 1, 'hands': 2, 'feet': 3}


def test_markers_without_duration_last_until_the_next_annotation_at_most_4_s() -> None:
    fs = 100.0
    rec = Recording(data=np.zeros((round(20 * fs), 2)), rate=fs, channels=['C3', 'C4'],
                    annotations=[(-0.5, 0.0, 'R'), (1.0, 0.0, 'L'), (3.0, 0.0, 'R'),
                                 (9.0, 0.0, 'end'), (10.0, 6.0, 'L'), (16.0, 0.0, 'rest'),
                                 (17.5, 0.0, 'R'), (19.6, 0.0, 'L')])
    events = {'L': 0, 'R': 1, 'rest': None}
    assert MAX_EPOCH_S == 4.0
    assert segments(rec, events) == [    # 'R' at -0.5 s: before the first sample
        (100, 300, 0),       # to the next marker (2 s)
        (300, 700, 1),       # capped at 4 s before 'end' at 9 s
        (1000, 1600, 0),     # an annotation with a duration keeps it (6 s)
        (1600, 1750, None),  # rest: to the next marker too
        (1750, 1960, 1),     # to the next marker (2.1 s)
    ]                        # 'L' at 19.6 s: 0.4 s to the end of the data, a fragment


def test_eegmmidb_through_a_subject_file_gives_the_epochs_of_eegmmidb_1() -> None:
    built_in = ReplayEEG.from_source('eegmmidb:1')
    from_file = ReplayEEG.from_source(str(EXAMPLE))
    # as before subject files existed: runs 8 and 10, every T0/T1/T2 annotation of >= 1 s
    assert {c: len(e) for c, e in built_in.epochs.items()} == {None: 30, 0: 8, 1: 7, 2: 7, 3: 8}
    assert {len(e) for c, eps in built_in.epochs.items() for e in eps if c is not None} == {656}
    assert {len(e) for e in built_in.epochs[None]} == {672}
    assert from_file.epochs.keys() == built_in.epochs.keys()
    for cls, epochs in built_in.epochs.items():
        assert all(np.array_equal(a, b) for a, b in zip(epochs, from_file.epochs[cls],
                                                        strict=True))
    assert from_file.channel_names == built_in.channel_names and from_file.sample_rate == 160.0
    # the same calibration, so the same cached classifier
    assert (replay_subject(str(EXAMPLE)).calibration_digest()
            == replay_subject('eegmmidb:1').calibration_digest())


def test_xdf_string_markers_give_the_epochs_of_the_edf_annotations(tmp_path: Path) -> None:
    """S001 run 8 as XDF: the markers have no duration, so class epochs end 4 s after their
    marker (the EDF's last 0.1 s left out) and rest ends at the next marker (4 s cap)."""
    edf, xdf_path = s001_run_as_xdf(tmp_path / 's001r08.xdf', 8)
    xdf = load_recording(xdf_path)
    assert xdf.channels == edf.channels and xdf.rate == edf.rate
    assert all(d == 0.0 for _o, d, _l in xdf.annotations)
    events = {'T0': None, 'T1': 0, 'T2': 1}
    from_edf, from_xdf = epochs_of(edf, events), epochs_of(xdf, events)
    assert {c: len(e) for c, e in from_xdf.items()} == {c: len(e) for c, e in from_edf.items()}
    for cls in (None, 0, 1):
        for a, b in zip(from_edf[cls], from_xdf[cls], strict=True):
            assert len(b) == 640                     # 4 s at 160 Hz
            # the same samples (float32 microvolts in the XDF); the means differ with the length
            np.testing.assert_allclose(np.diff(b, axis=0), np.diff(a[:640], axis=0), atol=1e-10)


def test_the_calibration_digest_follows_the_files_and_the_event_maps(tmp_path: Path) -> None:
    (edf,) = expand_sources(['eegbci:1:4'])
    shutil.copy(edf, tmp_path / 'r04.edf')
    write_graz_xdf(tmp_path / 'play.xdf')
    text = f'events: {{T0: rest, T1: left_hand, T2: right_hand}}\ncalibration: [r04.edf]\n' \
           f'play: [{{file: play.xdf, events: {GRAZ_EVENTS}}}]\n'
    digest = load_subject_file(subject_file(tmp_path, text)).calibration_digest()
    assert load_subject_file(tmp_path / 'subject.yaml').calibration_digest() == digest
    swapped = text.replace('T1: left_hand, T2: right_hand', 'T1: right_hand, T2: left_hand')
    assert load_subject_file(subject_file(tmp_path, swapped)).calibration_digest() != digest
    data = bytearray((tmp_path / 'r04.edf').read_bytes())
    data[-1] ^= 0xFF                                  # one sample of the last record
    (tmp_path / 'r04.edf').write_bytes(bytes(data))
    assert load_subject_file(subject_file(tmp_path, text)).calibration_digest() != digest


GOOD = f'events: {GRAZ_EVENTS}\ncalibration: [cal.xdf]\nplay: [play.xdf]\n'


@pytest.mark.parametrize(('text', 'message'), [
    (None, r"The subject file '.*missing\.yaml' does not exist; give the path of a YAML subject "
           r'file'),
    ('calibration: [cal.xdf\nplay: [', r'subject\.yaml is not valid YAML \(.*line 2.*\); fix its '
                                       'syntax'),
    ('- cal.xdf\n', 'a subject file is a YAML mapping with the keys calibration, play'),
    (GOOD.replace('calibration', 'calbration'), r"unknown key\(s\) \['calbration'\]; a subject "
                                                "file has the keys"),
    (GOOD.replace('play.xdf', 'gone.xdf'), r"the play recording 'gone\.xdf' \(.*gone\.xdf\) does "
                                           r'not exist; fix its path \(relative to the subject'),
    (GOOD.replace('left_hand', 'left_fist'),
     "unknown class 'left_fist' for the annotation 'left'; use one of left_hand, right_hand, "
     'both_hands, both_feet, rest'),
    (GOOD.replace('play.xdf', 'cal.xdf'), r'cal\.xdf is in both calibration and play; the '
                                          'classifier must never see the epochs played in the '
                                          'loop'),
    ('calibration: [cal.xdf]\nplay: [play.xdf]\n', "the calibration recording 'cal.xdf' has no "
                                                   'event map; give the file a top-level events'),
    (GOOD.replace('play: [play.xdf]', 'play: []'), 'play must be a non-empty list of recordings'),
    (GOOD.replace('cal.xdf', 'eegbci:one:4'), "'eegbci:one:4' is not an EEGMMIDB reference; "
                                              'write eegbci:<subject>:<run>'),
])
def test_bad_subject_files_are_one_line_naming_the_fix(tmp_path: Path, text: str | None,
                                                       message: str) -> None:
    write_graz_xdf(tmp_path / 'cal.xdf', seed=1)
    write_graz_xdf(tmp_path / 'play.xdf', seed=2)
    path = tmp_path / 'missing.yaml' if text is None else subject_file(tmp_path, text)
    with pytest.raises(EEGError, match=message) as info:
        replay_subject(str(path))
    assert '\n' not in str(info.value)


@pytest.mark.parametrize(('play', 'message'), [
    ({'trials': 2}, r'subject\.yaml has 2 recorded epoch\(s\) of class 0, fewer than 3; give '
                    'recordings with more trials of every class'),
    ({'fs': 200.0}, r'play2\.xdf is sampled at 200 Hz but .*play\.xdf at 100 Hz; all recordings '
                    'of a replay subject need one sample rate'),
    ({'names': ('C3', 'Cz', 'C2')}, r"play2\.xdf has other channels than .*play\.xdf \(it lacks "
                                    r"\['C4'\] and has \['C2'\]\); all recordings of a replay "
                                    'subject need the same channels'),
])
def test_bad_play_recordings_are_one_line_naming_the_fix(tmp_path: Path, play: dict,
                                                         message: str) -> None:
    write_graz_xdf(tmp_path / 'play.xdf', **{'trials': play.get('trials', 5)})
    entries = ['play.xdf']
    if 'trials' not in play:
        write_graz_xdf(tmp_path / 'play2.xdf', **play)
        entries.append('play2.xdf')
    write_graz_xdf(tmp_path / 'cal.xdf')
    path = subject_file(tmp_path, f"events: {GRAZ_EVENTS}\ncalibration: [cal.xdf]\n"
                                  f"play: [{', '.join(entries)}]\n")
    with pytest.raises(EEGError, match=message):
        ReplayEEG.from_source(str(path))


def test_an_event_map_entry_matching_no_annotation_is_named(tmp_path: Path) -> None:
    write_graz_xdf(tmp_path / 'play.xdf')
    path = subject_file(tmp_path, f"events: {GRAZ_EVENTS[:-1]}, T9: both_feet}}\n"
                                  'calibration: [eegbci:1:4]\nplay: [play.xdf]\n')
    with pytest.raises(EEGError, match=r"the event map entry 'T9' matches no annotation of the "
                                       r"play recordings \(they have \['feet', 'hands', 'left', "
                                       r"'rest', 'right'\]\); fix the annotation name"):
        ReplayEEG.from_source(str(path))
