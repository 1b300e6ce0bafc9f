"""Read the stamps :mod:`.latency` needs from a run's MCAP bag (and its params.yaml).

A periodic topic's nominal rate is the parameter its publisher's class names for it
(:attr:`~mindgrasp_ros.node_traits.NodeTraits.periodic`), read from the run's params.yaml for
the nodes its launch.yaml lists.

Each message's publication time is the MCAP ``publish_time`` (the DDS source timestamp our
recorder and rosbag2 Jazzy store); bags without it (0) fall back to the receive time
(``log_time``). The bag is read with :class:`~.reader.BagReader`, as by every bag tool: an
unfinished file (a killed recorder, a full disk, a file cut short) is read up to its last
complete record, and a damaged chunk costs only its own messages; what was skipped goes into the
report's notes.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from .latency import RunStamps
from .paths import run_dir_of
from .reader import BagReader
from .typestore import typestore

__all__ = ['PERIODIC', 'read_run_stamps']

EEG, PRED, CMD = '/eeg/raw', '/bci/prediction', '/arm_controller/commands'
PROMPT, FLIP = '/trainer/prompt', '/display/flip'

#: periodic topics whose intervals the report measures (/bci/prediction: at the model's window
#: step, no parameter of its own)
PERIODIC: tuple[str, ...] = (EEG, PRED, CMD, '/joint_states', '/camera/color/image_raw')


def _stamp_ns(header: Any) -> int:
    return int(header.stamp.sec) * 10**9 + int(header.stamp.nanosec)


def _messages(bag: Path, topics: set[str],
              notes: list[str]) -> Iterator[tuple[str, int, bytes]]:
    """``(topic, publication ns, cdr bytes)`` of ``topics``, read as every bag tool reads (a
    damaged chunk or a cut-off tail costs only its own messages); what the reader skipped or
    recovered is appended to ``notes``."""
    with BagReader(bag) as reader:
        present = topics & set(reader.topics)
        if present:
            for topic, _, pub, data in reader.records(present):
                yield topic, pub, data
        notes.extend(reader.notes)


def _nominal_periods(bag: Path) -> dict[str, float]:
    """Nominal period (s) of each :data:`PERIODIC` topic set in the run's params.yaml, by the
    parameter the publishing node's class names for it."""
    from mindgrasp_ros.run_nodes import run_nodes

    run_dir = run_dir_of(bag)
    if run_dir is None:
        return {}
    params = yaml.safe_load((run_dir / 'params.yaml').read_text(encoding='utf-8')) or {}
    out: dict[str, float] = {}
    for node in run_nodes(run_dir):
        section = (params.get(node.name) or params.get(node.name.lstrip('/')) or {}).get(
            'ros__parameters', {})
        for topic, (name, kind) in node.traits.periodic.items():
            value = section.get(name)
            if topic in PERIODIC and isinstance(value, (int, float)) and value > 0:
                out[topic] = float(value) if kind == 'period' else 1.0 / float(value)
    return out


def read_run_stamps(bag: Path | str) -> RunStamps:
    """The stamps of the bag's EEG chunks, predictions, commands, cues and flips.

    Args:
        bag: a bag directory (``runs/<run>/bag``) or one .mcap file.

    Raises:
        BagError: ``bag`` is not a bag.
    """
    bag = Path(bag)
    store = typestore()
    chunks: list[tuple[int, int, int]] = []
    preds: list[tuple[int, int]] = []
    commands: list[int] = []
    s = RunStamps()
    periodic: dict[str, list[int]] = {t: [] for t in PERIODIC}
    for topic, pub, data in _messages(bag, {EEG, PRED, CMD, PROMPT, FLIP, *PERIODIC}, s.notes):
        if topic in periodic:
            periodic[topic].append(pub)
        if topic == EEG:
            m = store.deserialize_cdr(data, 'mindgrasp_msgs/msg/EEGChunk')
            first = _stamp_ns(m.header)
            n = max(1, int(m.n_samples))
            last = first + round((n - 1) * 1e9 / float(m.sample_rate)) if m.sample_rate else first
            chunks.append((first, last, pub))
        elif topic == PRED:
            m = store.deserialize_cdr(data, 'mindgrasp_msgs/msg/MIPrediction')
            preds.append((_stamp_ns(m.header), pub))
        elif topic == CMD:
            commands.append(pub)
        elif topic in (PROMPT, FLIP):
            m = store.deserialize_cdr(data, 'mindgrasp_msgs/msg/Prompt')
            target = s.cue_ns if topic == PROMPT else s.flip_ns
            target.setdefault((int(m.trial), str(m.phase)), _stamp_ns(m.header))
    c = np.array(sorted(chunks, key=lambda r: r[1]), np.int64).reshape(-1, 3)
    p = np.array(sorted(preds, key=lambda r: r[1]), np.int64).reshape(-1, 2)
    s.chunk_first_ns, s.chunk_last_ns, s.chunk_pub_ns = c[:, 0], c[:, 1], c[:, 2]
    s.pred_stamp_ns, s.pred_pub_ns = p[:, 0], p[:, 1]
    s.command_pub_ns = np.sort(np.array(commands, np.int64))
    s.periodic_ns = {t: np.array(v, np.int64) for t, v in periodic.items() if v}
    s.nominal_period_s = _nominal_periods(bag)
    return s
