"""The virtual amplifier: synthetic EEG driven by a virtual subject, streamed over LSL (ROS-free).

:class:`VirtualAmplifier` owns a :class:`~mindgrasp_eeg.synthetic.SyntheticEEG`, a
:class:`~mindgrasp_eeg.subject.VirtualSubject` and an :class:`~mindgrasp_eeg.lsl.EEGOutlet`.
Call :meth:`VirtualAmplifier.step` with the pacing clock (s): it generates every sample due by then,
in blocks of at most ``block`` samples so imagery onsets are resolved to ``block / rate`` seconds,
and pushes them. With real-time stamps (an LSL stream) only whole blocks go out, as an amplifier
sends them: ``/eeg/raw`` then carries ``rate / block`` chunks a second (31.25 at 250 Hz, 8).

Timestamps: in real-time pacing, sample ``k`` gets the LSL timestamp ``t0 + k / rate``, where
``t0`` is ``local_clock()`` at the first step, like an amplifier with its own sample clock. In
simulated-time pacing (``/clock``) samples are pushed with the push time (LSL's default), since LSL
has no notion of simulated time.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pylsl

from .lsl import EEGOutlet
from .subject import VirtualSubject
from .synthetic import SyntheticEEG


def run_source_id(stream_name: str) -> str:
    """The source id of an amplifier whose ``source_id`` is not given: ``<stream_name>@<run>``
    in a launch, ``<run>`` the run directory's name (``$MINDGRASP_RUN_DIR``), so two runs never
    share it and a respawned amplifier keeps it; outside a launch the stream name, so that an
    amplifier started again by hand is the same sender (the acquisition takes back only the
    sender it connected to first)."""
    run_dir = os.environ.get('MINDGRASP_RUN_DIR', '')
    return f'{stream_name}@{Path(run_dir).name}' if run_dir else stream_name


class VirtualAmplifier:
    """Synthetic EEG + virtual subject + LSL outlet.

    Parameters
    ----------
    generator : SyntheticEEG
    subject : VirtualSubject
    outlet : EEGOutlet or None
        None generates without streaming (offline use, tests).
    realtime_stamps : bool
        Stamp samples on the amplifier's own sample clock (real-time pacing) instead of push time.
    block : int
        Largest block generated with one imagery decision (samples).
    max_catch_up : float or None
        When the pacing clock jumps (simulated time starting, a reset going backwards, a jump
        ahead of more than this many seconds), re-anchor instead of generating the whole gap at
        once. None (real-time pacing) always catches up, as an amplifier delivers its backlog.
    """

    def __init__(self, generator: SyntheticEEG, subject: VirtualSubject,
                 outlet: EEGOutlet | None = None, *, realtime_stamps: bool = True,
                 block: int = 8, max_catch_up: float | None = None) -> None:
        self.generator, self.subject, self.outlet = generator, subject, outlet
        self.realtime_stamps, self.block = realtime_stamps, max(1, int(block))
        self.max_catch_up = max_catch_up
        self.n_skipped = 0                       # samples skipped by re-anchoring
        self.t_start: float | None = None        # pacing clock at the first step (s)
        self.lsl_start = 0.0
        self.current_class: int | None = None

    @property
    def n_samples(self) -> int:
        """Samples generated (and pushed) so far."""
        return self.generator.n_generated

    def step(self, now: float) -> np.ndarray:
        """Generate and push all samples due at pacing time ``now`` (s).

        Returns
        -------
        data : ndarray, shape (n_new, n_channels), volts (what was pushed)
        """
        if self.t_start is None:
            self.t_start = now
            self.lsl_start = pylsl.local_clock()
        fs = self.generator.sample_rate
        due = math.floor((now - self.t_start) * fs + 1e-9) + 1   # sample 0 is due at t_start
        if self.max_catch_up is not None and (
                due < self.n_samples - fs * self.max_catch_up
                or due - self.n_samples > fs * self.max_catch_up):
            # the clock jumped: continue from now as if the gap had not happened
            self.n_skipped += max(0, due - self.n_samples)
            self.t_start = now - self.n_samples / fs
            due = self.n_samples + 1
        out = []
        # on the amplifier's own sample clock (LSL, wall time) only whole blocks leave, as an
        # amplifier sends them: a partial block (a push between block ends) sent its samples
        # as two LSL chunks, and /eeg/raw ran at 38.6 chunks/s instead of rate / block (31.25)
        whole = self.block if self.realtime_stamps else 1
        while due - self.n_samples >= whole:
            k = self.n_samples
            n = min(self.block, due - k)
            self.current_class = self.subject.intent(self.t_start + k / fs)
            data = self.generator.generate(n, self.current_class)
            if self.outlet is not None:
                stamp = self.lsl_start + (k + n - 1) / fs if self.realtime_stamps else 0.0
                self.outlet.push_volts(data, stamp)
            out.append(data)
        if not out:
            return np.zeros((0, self.generator.n_channels))
        return np.vstack(out)
