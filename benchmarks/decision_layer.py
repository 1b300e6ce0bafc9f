"""How the scan paradigm's decisions would go on a subject's EEG, without the robot.

    .venv/bin/python benchmarks/decision_layer.py --subject docs/subjects/eegmmidb_s001_swapped.yaml
    .venv/bin/python benchmarks/decision_layer.py --subject noise --offers 200

The controller's two decisions (mindgrasp_fsm.evidence, parameters of mindgrasp_fsm's FsmParams)
are simulated on the EEG the loop would stream, decoded by the decoder the loop would use (the
same MiDecoder, model and window grid), with the subject following the scan paradigm's
instructions (mindgrasp_eeg.subject.scan_class):

- an **offer** lasts at most ``offer_timeout`` s; the evidence for both hands against both feet
  counts from ``offer_delay`` s after it begins. For the *target* the subject rests ``reaction``
  s, then imagines both hands ("yes"); for any *other* object both feet ("no"). The offer ends
  with a confirmation (``confirm_threshold``), a pass (``pass_threshold`` of evidence against) or
  the timeout. A confirmed other object is a wrong grasp unless the approach is cancelled.
- an **approach** lasts ``approach`` s: of a wrong object the subject imagines both feet (after
  ``reaction`` s), of the right one both hands; the evidence for feet against hands cancels at
  ``cancel_threshold``.

Each episode is preceded by 3 s of rest (the arm turning to the object). A replay subject
(``eegmmidb:<n>`` or a subject file) streams its *play* recordings (mindgrasp_eeg.replay_eeg),
decoded by the model ``replay_model`` calibrates on its calibration recordings; ``noise`` is the
virtual amplifier's noise (no imagery at all: every answer is rest) decoded by the noise-trained
model; ``virtual`` the synthetic subject with the default model. Thresholds given as lists are
crossed. Prints a table and a JSON line with every figure.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from mindgrasp_classifier.decoder import AdaptationConfig, MiDecoder
from mindgrasp_classifier.model import MiModel
from mindgrasp_classifier.params import ClassifierParams
from mindgrasp_common.mi import MiClass
from mindgrasp_common.types import Prediction
from mindgrasp_fsm.evidence import Evidence
from mindgrasp_fsm.params import FsmParams

CHUNK_S = 1.0 / 16.0
LEAD_S = 3.0


def source(subject: str, seed: int, cache: Path):
    """(EEG generator with ``generate(n, cls)``, model) for ``subject``."""
    if subject == 'noise':
        from mindgrasp_eeg.montage import NAUTILUS_32, NAUTILUS_RATE
        from mindgrasp_eeg.synthetic import SyntheticEEG
        from mindgrasp_experiments.subject_launch import noise_model_path

        gen = SyntheticEEG(list(NAUTILUS_32), NAUTILUS_RATE, seed=seed)
        return (lambda n, _cls: gen.generate(n, None)), gen, MiModel.load(noise_model_path(cache))
    if subject == 'virtual':
        from mindgrasp_classifier.model import DEFAULT_MODEL
        from mindgrasp_eeg.montage import NAUTILUS_32, NAUTILUS_RATE
        from mindgrasp_eeg.synthetic import SyntheticEEG

        gen = SyntheticEEG(list(NAUTILUS_32), NAUTILUS_RATE, seed=seed)
        return gen.generate, gen, MiModel.load(DEFAULT_MODEL)
    from mindgrasp_eeg.replay_eeg import ReplayEEG
    from mindgrasp_eeg.subject_file import replay_subject
    from mindgrasp_experiments.subjects import replay_model

    files = replay_subject(subject)
    model = MiModel.load(replay_model(files, cache))
    gen = ReplayEEG.from_subject(files, seed=seed)
    return gen.generate, gen, model


def episode(generate, rate: float, decoder: MiDecoder, pos: int, intent: int | None,
            duration: float, reaction: float, since: float) -> tuple[list[Prediction], int]:
    """Stream ``LEAD_S`` s of rest, then ``duration`` s in which the subject rests ``reaction`` s
    and then imagines ``intent``; returns the predictions stamped after ``since`` s from the
    episode's start (stream time, s) and the new stream position."""
    n_chunk = round(CHUNK_S * rate)
    t0 = pos / rate + LEAD_S
    preds: list[Prediction] = []
    end = t0 + duration
    while pos / rate < end:
        t = pos / rate
        cls = intent if t >= t0 + reaction else None
        for res in decoder.push(generate(n_chunk, cls), pos):
            if isinstance(res, Prediction):
                stamp = (res.sample_index + 1) / rate - t0
                if stamp > since:
                    preds.append(dataclasses.replace(res, stamp=stamp))
        pos += n_chunk
    return preds, pos


def decide(preds: list[Prediction], ev: Evidence, since: float, until: float
           ) -> tuple[str, float]:
    """('yes' | 'no' | 'none', time s) of the first decision of ``ev`` on ``preds`` between
    ``since`` and ``until`` s after the episode's start."""
    ev.reset(since)
    for p in preds:
        if p.stamp > until:
            break
        if ev.update(p):
            return 'yes', p.stamp
        if ev.rejected:
            return 'no', p.stamp
    return 'none', float('nan')


def rates(outcomes: list[tuple[str, float]]) -> dict:
    """Share of each answer and the median time of the decided ones."""
    n = len(outcomes)
    out: dict = {k: sum(o == k for o, _ in outcomes) / n for k in ('yes', 'no', 'none')}
    times = [t for o, t in outcomes if o != 'none']
    out['median_s'] = float(np.median(times)) if times else None
    return out


def main(argv: list[str] | None = None) -> int:
    d = FsmParams()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--subject', default='docs/subjects/eegmmidb_s001_swapped.yaml')
    parser.add_argument('--offers', type=int, default=20, help='episodes per unit of --mix')
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--confirm', default=str(d.confirm_threshold),
                        help='confirm (and cancel) thresholds, nat s, comma-separated')
    parser.add_argument('--pass', dest='pass_', default=str(d.pass_threshold),
                        help='pass thresholds, nat s, comma-separated')
    parser.add_argument('--offer-timeout', type=float, default=d.offer_timeout)
    parser.add_argument('--offer-delay', type=float, default=d.offer_delay)
    parser.add_argument('--clip', type=float, default=d.evidence_clip)
    parser.add_argument('--approach', type=float, default=8.0, help='s of an approach')
    parser.add_argument('--reaction', type=float, default=1.0, help='s before imagery starts')
    parser.add_argument('--recenter', default=ClassifierParams().recenter,
                        choices=['fixed', 'adaptive'],
                        help="the classifier's re-centering (its parameter recenter)")
    parser.add_argument('--mix', default='1,4,1,1',
                        help='episodes of each kind (target offer, other offer, wrong approach, '
                             'right approach) per --offers: in a scan most offers are answered no')
    parser.add_argument('--recenter-rate', type=float, default=None,
                        help="(default: the classifier node's recenter_rate)")
    parser.add_argument('--recenter-prior', type=float, default=None,
                        help="s (default: the classifier node's recenter_prior)")
    parser.add_argument('--trial-episodes', type=int, default=8,
                        help='a fresh decoder every N episodes, as a lock-step experiment '
                             'starts every trial with a fresh graph (0: one decoder)')
    parser.add_argument('--cache', default=str(Path(tempfile.gettempdir()) / 'mindgrasp_models'))
    args = parser.parse_args(argv)
    confirms = [float(x) for x in args.confirm.split(',')]
    passes = [float(x) for x in args.pass_.split(',')]
    generate, gen, model = source(args.subject, args.seed, Path(args.cache))
    node = ClassifierParams()       # the classifier node's defaults, as in the loop
    adaptation = AdaptationConfig(recenter=args.recenter,
                                  recenter_rate=node.recenter_rate if args.recenter_rate is None
                                  else args.recenter_rate,
                                  recenter_prior=node.recenter_prior
                                  if args.recenter_prior is None else args.recenter_prior)

    def new_decoder() -> MiDecoder:
        return MiDecoder(model, gen.channel_names, gen.sample_rate, adaptation)

    decoder = new_decoder()
    rate = gen.sample_rate
    rng = np.random.default_rng(args.seed)
    yes, no = MiClass.BOTH_HANDS, MiClass.BOTH_FEET
    if args.subject == 'noise':
        yes = no = None
    kinds = {'target offer': (yes, args.offer_timeout), 'other offer': (no, args.offer_timeout),
             'wrong approach': (no, args.approach), 'right approach': (yes, args.approach)}
    names = list(kinds)
    mix = [int(x) for x in args.mix.split(',')]
    order = rng.permutation(np.repeat(np.arange(len(kinds)), [args.offers * m for m in mix]))
    episodes: dict[str, list[list[Prediction]]] = {k: [] for k in kinds}
    pos = 0
    for n, i in enumerate(order):
        if args.trial_episodes and n % args.trial_episodes == 0:
            decoder = new_decoder()   # a lock-step trial starts a fresh graph
        intent, duration = kinds[names[i]]
        preds, pos = episode(generate, rate, decoder, pos, intent, duration, args.reaction, 0.0)
        episodes[names[i]].append(preds)
    print(f'{args.subject}: model {model.pipeline}, classes {model.class_names}, window '
          f'{model.window:g} s, temperature {model.temperature:.2f}, re-centering '
          f'{args.recenter} (prior {adaptation.recenter_prior:g} s), a fresh decoder every '
          f'{args.trial_episodes or "-"} episodes; {args.offers} x ({args.mix}) episodes '
          f'(target offer, other offer, wrong approach, right approach), offer <= '
          f'{args.offer_timeout:g} s, approach {args.approach:g} s, reaction '
          f'{args.reaction:g} s, clip {args.clip:g} nat; the cancel threshold is the confirm '
          'threshold of the row')
    print(f'{"confirm":>7} {"pass":>5} | {"target: yes":>11} {"no":>5} {"s":>5} | '
          f'{"other: yes":>10} {"no":>5} {"s":>5} | {"cancel wrong":>12} {"s":>5} | '
          f'{"cancel right":>12}')
    figures = []
    for th in confirms:
        for pth in passes:
            confirm = Evidence(MiClass.BOTH_HANDS, [MiClass.BOTH_FEET], threshold=th,
                               clip=args.clip, reject_threshold=pth)
            cancel = Evidence(MiClass.BOTH_FEET, [MiClass.BOTH_HANDS], threshold=th,
                              clip=args.clip)
            row = {'confirm_threshold': th, 'pass_threshold': pth}
            for kind, ev, since, until in (
                    ('target offer', confirm, args.offer_delay, args.offer_timeout),
                    ('other offer', confirm, args.offer_delay, args.offer_timeout),
                    ('wrong approach', cancel, 0.0, args.approach),
                    ('right approach', cancel, 0.0, args.approach)):
                row[kind] = rates([decide(p, ev, since, until) for p in episodes[kind]])
            figures.append(row)

            def s(kind: str, row: dict = row) -> str:
                t = row[kind]['median_s']
                return f'{t:5.1f}' if t is not None else f'{"-":>5}'
            print(f'{th:7.2f} {pth:5.2f} | {row["target offer"]["yes"]:11.1%} '
                  f'{row["target offer"]["no"]:5.0%} {s("target offer")} | '
                  f'{row["other offer"]["yes"]:10.1%} {row["other offer"]["no"]:5.0%} '
                  f'{s("other offer")} | {row["wrong approach"]["yes"]:12.1%} '
                  f'{s("wrong approach")} | {row["right approach"]["yes"]:12.1%}')
    print(json.dumps({'subject': args.subject, 'episodes': args.offers, 'seed': args.seed,
                      'offer_timeout': args.offer_timeout, 'clip': args.clip,
                      'reaction': args.reaction, 'figures': figures}))
    return 0


if __name__ == '__main__':
    sys.exit(main())
