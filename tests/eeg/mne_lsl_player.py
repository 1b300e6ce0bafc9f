"""Play an EDF with MNE-LSL's PlayerLSL (the usual Python LSL player), for the interop test.

    python tests/eeg/mne_lsl_player.py FILE.edf STREAM_NAME

Prints READY once the outlet exists, then plays until killed.
"""

from __future__ import annotations

import contextlib
import sys
import time

from mne_lsl.player import PlayerLSL


def main() -> None:
    path, name = sys.argv[1], sys.argv[2]
    with contextlib.redirect_stdout(sys.stderr):      # stdout carries READY only
        player = PlayerLSL(path, chunk_size=16, name=name, source_id=name)
        player.start()
    print('READY', flush=True)
    while True:
        time.sleep(1.0)


if __name__ == '__main__':
    main()
