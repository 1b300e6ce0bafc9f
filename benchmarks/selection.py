"""How often the default decoder would select an object the subject did not ask for.

    .venv/bin/python benchmarks/selection.py [--minutes 5] [--seed 7]

The controller selects the object in view after ``bci_select_dwell`` seconds of unbroken
both-hands predictions. This streams the virtual subject's synthetic EEG (head_seed 0, the
default model's subject, a session seed other than the model's) holding one intent at a time
through the default model's online decoder (1 s windows every 1/16 s) and prints, per intent:
the share of windows decoded as each class, and how many unbroken both-hands runs of at least
0.5, 1.0, 1.5 and 2.0 s occur per minute. For a left/right intent every such run is a false
selection at that dwell; for both hands it is how often the intended selection is reached.

The last line is a JSON object with every figure.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from mindgrasp_classifier.decoder import MiDecoder
from mindgrasp_classifier.model import MiModel
from mindgrasp_common.resources import resolve_path
from mindgrasp_eeg.montage import BOTH_HANDS, NAUTILUS_32, NAUTILUS_RATE
from mindgrasp_eeg.synthetic import SyntheticEEG

MODEL = 'package://mindgrasp_classifier/models/default_classifier.json'
DWELLS = (0.5, 1.0, 1.5, 2.0)
INTENTS = {'left_hand': 0, 'right_hand': 1, 'both_hands': 2, 'both_feet': 3, 'rest': None}


def both_hands_runs(classes: np.ndarray, step_s: float) -> np.ndarray:
    """Lengths (s) of the unbroken runs of both-hands predictions in ``classes``."""
    runs, n = [], 0
    for c in classes:
        if c == BOTH_HANDS:
            n += 1
        elif n:
            runs.append(n)
            n = 0
    if n:
        runs.append(n)
    return np.asarray(runs, dtype=float) * step_s


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--minutes', type=float, default=5.0, help='minutes per intent')
    parser.add_argument('--seed', type=int, default=7, help='EEG session seed')
    args = parser.parse_args()
    model = MiModel.load(resolve_path(MODEL, 'mindgrasp_classifier'))
    figures: dict[str, dict] = {}
    chunk = 16
    for name, intent in INTENTS.items():
        gen = SyntheticEEG(NAUTILUS_32, NAUTILUS_RATE, seed=args.seed, head_seed=0)
        decoder = MiDecoder(model, list(NAUTILUS_32), NAUTILUS_RATE)
        classes = []
        for _ in range(int(args.minutes * 60 * NAUTILUS_RATE) // chunk):
            classes += [r.class_index for r in decoder.push(gen.generate(chunk, intent))
                        if hasattr(r, 'class_index')]
        # the first second of windows still holds the filter's start-up
        c = np.asarray(classes[int(1.0 / model.step):])
        runs = both_hands_runs(c, model.step)
        minutes = len(c) * model.step / 60.0
        figures[name] = {
            'decoded_share': {n: round(float(np.mean(c == i)), 3)
                              for n, i in INTENTS.items() if i is not None},
            'both_hands_runs_per_min': {f'>={d:g}s': round(float((runs >= d).sum() / minutes), 2)
                                        for d in DWELLS},
        }
        share = ', '.join(f'{k} {v:.1%}' for k, v in figures[name]['decoded_share'].items())
        per_min = ', '.join(f'{k} {v:.1f}'
                            for k, v in figures[name]['both_hands_runs_per_min'].items())
        print(f'{name:>10}: decoded {share}\n{"":>12}both-hands runs per minute: {per_min}')
    print(json.dumps({'model': MODEL, 'minutes_per_intent': args.minutes, 'seed': args.seed,
                      'intents': figures}))


if __name__ == '__main__':
    main()
