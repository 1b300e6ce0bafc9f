"""A real LSL EEG outlet for tests, run as ``python tests/eeg/lsl_source.py --name X ...``.

Streams synthetic EEG (32 g.Nautilus channels) or white noise (other channel counts) in real time
with the amplifier's own sample clock, and can inject faults: NaN, a flat or a railed channel, a
gap of skipped samples, a sample out of order. With ``--markers-every S`` it also sends a marker
stream ``<name>-markers`` (type Markers), as an amplifier app sends its triggers: once inlets
are connected to both streams, every ``S`` s of samples the marker ``S<k>`` stamped with the LSL
time of sample ``k``, whose channel 0 carries a 1 mV spike, so a test can find the sample a
marker belongs to; ``--markers-until T`` closes that stream ``T`` s after the first marker (a
lost marker stream; the EEG goes on). Prints ``READY`` once the outlets exist.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
import pylsl

from mindgrasp_eeg.lsl import EEGOutlet, MarkerOutlet
from mindgrasp_eeg.montage import NAUTILUS_32
from mindgrasp_eeg.synthetic import SyntheticEEG


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument('--name', required=True)
    p.add_argument('--source-id', default='')
    p.add_argument('--n-channels', type=int, default=32)
    p.add_argument('--rate', type=float, default=250.0)
    p.add_argument('--duration', type=float, default=10.0)
    p.add_argument('--chunk', type=int, default=8)
    p.add_argument('--unit', default='microvolts')
    p.add_argument('--nan-channel', type=int, default=-1)
    p.add_argument('--flat-channel', type=int, default=-1)
    p.add_argument('--railed-channel', type=int, default=-1)
    p.add_argument('--gap-at', type=float, default=-1.0, help='skip samples from this time (s)')
    p.add_argument('--gap-samples', type=int, default=0)
    p.add_argument('--disorder-at', type=float, default=-1.0)
    p.add_argument('--stall-at', type=float, default=-1.0, help='stop sending (outlet alive)')
    p.add_argument('--stall-len', type=float, default=0.0)
    p.add_argument('--markers-every', type=float, default=0.0, help='marker period (s of samples)')
    p.add_argument('--markers-until', type=float, default=-1.0, help='close the marker stream')
    a = p.parse_args()
    names = NAUTILUS_32 if a.n_channels == 32 else [f'E{k + 1}' for k in range(a.n_channels)]
    gen = SyntheticEEG(sample_rate=a.rate, seed=1) if a.n_channels == 32 else None
    rng = np.random.default_rng(0)
    outlet = EEGOutlet(a.name, names, a.rate, source_id=a.source_id or a.name, unit=a.unit)
    markers = MarkerOutlet(f'{a.name}-markers') if a.markers_every > 0 else None
    every = round(a.markers_every * a.rate)
    first_marker_at = -1.0               # sample time (s) of the first marker sent
    listened = False                     # inlets on both streams: markers can go out
    print('READY', flush=True)
    t0_wall, t0 = time.monotonic(), pylsl.local_clock()
    k = 0
    gap_done = disorder_done = False
    while time.monotonic() - t0_wall < a.duration:
        now = time.monotonic() - t0_wall
        if 0 <= a.stall_at <= now < a.stall_at + a.stall_len:
            time.sleep(0.002)
            continue
        due = int(now * a.rate)
        while due - k >= a.chunk:
            n = a.chunk
            data = gen.generate(n) if gen else rng.normal(0, 10e-6, (n, a.n_channels))
            t = k / a.rate
            if a.nan_channel >= 0 and t >= 1.0:
                data[::2, a.nan_channel] = np.nan
            if a.flat_channel >= 0:
                data[:, a.flat_channel] = 1e-6
            if a.railed_channel >= 0:
                data[:, a.railed_channel] = 0.4
            if a.gap_at >= 0 and t >= a.gap_at and not gap_done:
                k += a.gap_samples            # those samples never leave the amplifier
                gap_done = True
            if a.disorder_at >= 0 and t >= a.disorder_at and not disorder_done:
                outlet.push_volts(data[:1], t0 + (k - 20) / a.rate)   # a stale sample
                disorder_done = True
            for i in range(n):                 # per-sample stamps from the sample clock
                listened = listened or (markers is not None and markers.have_consumers()
                                        and outlet.have_consumers())
                if markers is not None and listened and (k + i) % every == 0:
                    first_marker_at = t if first_marker_at < 0 else first_marker_at
                    data[i, 0] = 1e-3
                    markers.push(f'S{k + i}', t0 + (k + i) / a.rate)
                outlet.push_volts(data[i:i + 1], t0 + (k + i) / a.rate)
            if markers is not None and first_marker_at >= 0 and \
                    0 <= a.markers_until <= t - first_marker_at:
                markers.close()
                markers = None
            k += n
        time.sleep(0.002)
    outlet.close()
    return 0


if __name__ == '__main__':
    sys.exit(main())
