"""Train the demo's default MI model on the virtual subject's calibration session.

    .venv/bin/python scripts/train_default_classifier.py [--out my_models/default_classifier]

The virtual subject (mindgrasp_eeg.synthetic + mindgrasp_eeg.subject, the same generator and head
model as ``mindgrasp_eeg.virtual_amp_node`` with its default ``head_seed`` 0) follows a Graz-BCI
calibration: per trial 2 s fixation, a 4 s cue of a random class, 2 s rest; 20 trials per class
in random order. The model (MDM, motor-strip channels of the 32-channel 10-20 montage, 250 Hz,
8-30 Hz, 1 s windows every 1/16 s) is written as mindgrasp_classifier's
models/default_classifier.{json,npz}, with the cross-validated accuracy in its provenance. Same
seeds, same model.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from mindgrasp_classifier.commands._common import format_report
from mindgrasp_classifier.data import Recording
from mindgrasp_classifier.training import TrainingConfig, train
from mindgrasp_common.resources import resource_path
from mindgrasp_eeg.montage import NAUTILUS_32, NAUTILUS_RATE, NO_CLASS
from mindgrasp_eeg.subject import VirtualSubject
from mindgrasp_eeg.synthetic import SyntheticEEG


def calibration_session(trials_per_class: int = 20, seed: int = 100, head_seed: int = 0,
                        rate: float = NAUTILUS_RATE, channels: tuple[str, ...] = NAUTILUS_32,
                        fixation: float = 2.0, cue: float = 4.0, rest: float = 2.0,
                        chunk: float = 1.0 / 32.0) -> Recording:
    """A Graz-BCI calibration of the virtual subject as a labelled :class:`Recording` (volts)."""
    rng = np.random.default_rng(seed)
    gen = SyntheticEEG(channels, rate, seed=seed, head_seed=head_seed)
    subject = VirtualSubject('follow', accuracy=1.0, reaction_delay=0.5, seed=seed)
    order = rng.permutation(np.repeat(np.arange(4), trials_per_class))
    # prompt schedule: (time s, class, phase, trial)
    prompts, t, events = [], 0.0, []
    for trial, cls in enumerate(order, start=1):
        prompts.append((t, NO_CLASS, 'fixation', trial))
        prompts.append((t + fixation, int(cls), 'cue', trial))
        prompts.append((t + fixation + cue, NO_CLASS, 'rest', trial))
        events.append((round((t + fixation) * rate), int(cls)))
        t += fixation + cue + rest
    n_total = round(t * rate)
    n_chunk = max(1, round(chunk * rate))
    blocks, k, p = [], 0, 0
    while k < n_total:
        n = min(n_chunk, n_total - k)
        while p < len(prompts) and prompts[p][0] <= k / rate:
            subject.on_prompt(prompts[p][0], prompts[p][1], prompts[p][2], prompts[p][3])
            p += 1
        blocks.append(gen.generate(n, subject.intent(k / rate)))
        k += n
    return Recording(data=np.concatenate(blocks), rate=rate, channels=list(channels),
                     events=np.array(events, dtype=int),
                     source=f'virtual subject calibration (seed {seed}, head_seed {head_seed}, '
                            f'{trials_per_class} trials/class)')


def main(argv: list[str] | None = None) -> int:
    """Generate the calibration, train, write the model."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--out', default=str(resource_path('mindgrasp_classifier', 'models')
                                             / 'default_classifier'))
    parser.add_argument('--trials-per-class', type=int, default=20)
    parser.add_argument('--seed', type=int, default=100)
    parser.add_argument('--head-seed', type=int, default=0)
    parser.add_argument('--pipeline', default='mdm')
    parser.add_argument('--window', type=float, default=1.0, help='decoder window (s)')
    parser.add_argument('--tmax', type=float, default=2.5,
                        help='training epoch end after the cue (s); > window + 0.5')
    args = parser.parse_args(argv)
    rec = calibration_session(args.trials_per_class, args.seed, args.head_seed)
    model, report = train([rec], TrainingConfig(pipeline=args.pipeline, channels='motor',
                                                window=args.window, tmax=args.tmax))
    model.provenance['generator'] = 'scripts/train_default_classifier.py'
    path = model.save(args.out)
    print(format_report(report, f'Cross-validation on the calibration ({rec.source}):'))
    print(f'Wrote {path} ({len(model.channels)} channels: {model.channels}).')
    return 0


if __name__ == '__main__':
    sys.exit(main())
