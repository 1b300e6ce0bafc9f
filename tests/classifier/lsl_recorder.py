"""A LabRecorder stand-in for the tests: its own LSL inlets on an EEG stream and a marker stream,
written to one XDF file (XDF 1.0, as LabRecorder writes; pyxdf reads it).

    python tests/classifier/lsl_recorder.py --eeg NAME --markers NAME --out FILE.xdf

Prints ``READY`` once both inlets are open (the streams are awaited up to 120 s), records until
SIGINT or SIGTERM, then writes the file and exits 0. Timestamps are the inlets' (clock
synchronisation and dejitter on, as LabRecorder's files give them after pyxdf's processing).
"""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

import numpy as np
import pylsl

import mindgrasp_eeg  # noqa: F401  (LSL discovery on this host, as every MIndGrasp process)

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from mindgrasp_testing import write_xdf

_stop = False


def _on_signal(_signum: int, _frame: object) -> None:
    global _stop
    _stop = True


def _inlet(name: str, flags: int) -> pylsl.StreamInlet:
    found = pylsl.resolve_byprop('name', name, 1, 120.0)
    if not found:
        sys.exit(f'lsl_recorder: no LSL stream named {name!r} within 120 s')
    inlet = pylsl.StreamInlet(found[0], max_buflen=360, processing_flags=flags)
    inlet.open_stream(timeout=30.0)
    return inlet


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--eeg', required=True)
    parser.add_argument('--markers', required=True)
    parser.add_argument('--out', type=Path, required=True)
    args = parser.parse_args()
    signal.signal(signal.SIGINT, _on_signal)
    signal.signal(signal.SIGTERM, _on_signal)
    eeg = _inlet(args.eeg, pylsl.proc_clocksync | pylsl.proc_dejitter)
    markers = _inlet(args.markers, pylsl.proc_clocksync)
    info = eeg.info(timeout=30.0)
    ch = info.desc().child('channels').child('channel')
    names = []
    for _ in range(info.channel_count()):
        names.append(ch.child_value('label'))
        ch = ch.next_sibling()
    print('READY', flush=True)
    samples, stamps, marks = [], [], []
    while True:
        stopping = _stop                     # one more pull after the signal: nothing is lost
        data, ts = eeg.pull_chunk(timeout=0.1)
        samples += data
        stamps += ts
        values, mts = markers.pull_chunk(timeout=0.0)
        marks += [(t, v[0]) for t, v in zip(mts, values, strict=True)]
        if stopping:
            break
    write_xdf(args.out, np.asarray(samples, dtype=np.float32), info.nominal_srate(), stamps[0],
              marks, names)
    print(f'wrote {len(samples)} samples and {len(marks)} markers to {args.out}', flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
