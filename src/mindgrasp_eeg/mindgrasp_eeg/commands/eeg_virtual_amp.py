"""Run the virtual amplifier: synthetic 32-channel EEG of a virtual subject as an LSL stream.

Examples::

    mindgrasp eeg virtual-amp                                  # ROS node, subject 'noise'
    mindgrasp eeg virtual-amp --mode follow --accuracy 0.8     # imagines /trainer/prompt
    mindgrasp eeg virtual-amp --mode pursue --seed 3 --blinks 0.25
    mindgrasp eeg virtual-amp --no-ros --cues 40               # no ROS: own Graz-like cues,
                                                               # labels on <name>-markers

With ROS it runs :mod:`mindgrasp_eeg.virtual_amp_node` (extra ``--ros-args ...`` are passed on).
``--no-ros`` streams without a ROS graph: the subject follows an internal cue schedule (fixation
2 s, imagery 4 s, rest 2 s, seeded random classes), and each cue goes out as an LSL marker
(``cue/<class>``, ``rest``), so LabRecorder or any LSL client records labelled EEG.
"""

from __future__ import annotations

import argparse
import sys
import time

from mindgrasp_common.cli_checks import non_negative_float, non_negative_int, probability
from mindgrasp_eeg import EEGError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp eeg virtual-amp``."""
    parser.add_argument('--name', default='MIndGrasp-VirtualAmp', help='LSL stream name')
    parser.add_argument('--mode', choices=['noise', 'follow', 'pursue'], default='noise',
                        help='virtual subject mode')
    parser.add_argument('--seed', type=non_negative_int, default=0, help='EEG and decision seed')
    parser.add_argument('--accuracy', type=probability, default=0.9,
                        help='probability of the right class')
    parser.add_argument('--reaction-delay', type=non_negative_float, default=0.5, help='s')
    parser.add_argument('--lapse-rate', type=probability, default=0.0, help='follow: missed trials')
    parser.add_argument('--blinks', type=non_negative_float, default=0.0, help='blink rate (1/s)')
    parser.add_argument('--emg', type=non_negative_float, default=0.0, help='EMG burst rate (1/s)')
    parser.add_argument('--duration', type=non_negative_float, default=0.0,
                        help='s, 0 = until Ctrl-C')
    parser.add_argument('--use-sim-time', action='store_true', help='pace by /clock')
    parser.add_argument('--no-ros', action='store_true',
                        help='stream without ROS (internal cue schedule with --cues)')
    parser.add_argument('--cues', type=non_negative_int, default=0,
                        help='--no-ros: number of cued trials (0 = none, the subject rests)')
    # an option, not a REMAINDER positional: argparse hands a positional REMAINDER nothing that
    # starts with '-' when no positional comes before it, so '--ros-args ...' was refused
    parser.add_argument('--ros-args', dest='ros_args', nargs=argparse.REMAINDER, default=[],
                        metavar='ARG', help='ROS arguments passed on to the node, e.g. '
                                            '--ros-args -p seed:=1 -r __node:=amp2 (last)')


def _ros_argv(args: argparse.Namespace) -> list[str]:
    params = {'stream_name': args.name, 'subject_mode': args.mode, 'seed': args.seed,
              'accuracy': args.accuracy, 'reaction_delay': args.reaction_delay,
              'lapse_rate': args.lapse_rate, 'blink_rate': args.blinks, 'emg_rate': args.emg,
              'duration': args.duration, 'use_sim_time': str(args.use_sim_time).lower()}
    argv = ['--ros-args']
    for key, value in params.items():
        argv += ['-p', f'{key}:={value}']
    return argv + list(args.ros_args)  # after ours: a -p given here wins


def run_without_ros(args: argparse.Namespace) -> int:
    """Stream with an internal Graz-like cue schedule; cues as LSL markers."""
    import numpy as np

    from mindgrasp_eeg.lsl import EEGOutlet, MarkerOutlet
    from mindgrasp_eeg.montage import NAUTILUS_32, NO_CLASS, class_name
    from mindgrasp_eeg.subject import VirtualSubject
    from mindgrasp_eeg.synthetic import SyntheticEEG
    from mindgrasp_eeg.virtual_amp import VirtualAmplifier

    mode = 'follow' if args.cues else 'noise'
    subject = VirtualSubject(mode, accuracy=args.accuracy, reaction_delay=args.reaction_delay,
                             lapse_rate=args.lapse_rate, seed=args.seed)
    amp = VirtualAmplifier(SyntheticEEG(seed=args.seed, blink_rate=args.blinks,
                                        emg_rate=args.emg), subject,
                           EEGOutlet(args.name, NAUTILUS_32, 250.0))
    markers = MarkerOutlet(f'{args.name}-markers')
    rng = np.random.default_rng(args.seed)
    schedule = []                                # (t, class, phase, trial)
    for trial in range(1, args.cues + 1):
        t = 2.0 + (trial - 1) * 8.0
        cls = int(rng.integers(0, 4))
        schedule += [(t, NO_CLASS, 'fixation', trial), (t + 2.0, cls, 'cue', trial),
                     (t + 6.0, NO_CLASS, 'rest', trial)]
    print(f"Virtual amplifier '{args.name}' (no ROS): 32 ch @ 250 Hz in microvolts, "
          f'{args.cues} cued trials, markers on {args.name}-markers.', flush=True)
    t0 = time.monotonic()
    end = t0 + args.duration if args.duration > 0 else (
        t0 + schedule[-1][0] + 2.0 if schedule else float('inf'))
    try:
        while time.monotonic() < end:
            now = time.monotonic() - t0
            while schedule and schedule[0][0] <= now:
                t, cls, phase, trial = schedule.pop(0)
                subject.on_prompt(t, cls, phase, trial)
                markers.push(f'{phase}/{class_name(cls)}' if phase == 'cue' else phase)
            amp.step(now)
            time.sleep(1 / 64)
    except KeyboardInterrupt:
        pass
    print(f'Pushed {amp.n_samples} samples.', flush=True)
    return 0


def main(args: argparse.Namespace) -> int:
    """Run the node (or the ROS-free loop); the node's exit code (2 and one line on a bad
    parameter), or 1 with a message when the ROS-free loop cannot start."""
    try:
        if args.no_ros:
            if args.ros_args:
                print('mindgrasp eeg virtual-amp: error: --ros-args needs the ROS node; leave '
                      'out --no-ros or the ROS arguments.', file=sys.stderr)
                return 2
            return run_without_ros(args)
        from mindgrasp_eeg.virtual_amp_node import main as node_main

        return node_main(['virtual_amp', *_ros_argv(args)])
    except EEGError as exc:
        print(f'mindgrasp eeg virtual-amp: {exc}', file=sys.stderr)
        return 1
