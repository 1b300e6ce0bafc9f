"""``evaluate classifier --live``: the online path end to end, scored against the cues.

Each recording is streamed in real time over LSL by the EEG package's dataset player, received by
the acquisition node (``mindgrasp_eeg.acquisition_node``, its own process) and decoded by the
classifier node (``mindgrasp_classifier.classifier_node``, its own process); this process listens
to ``/eeg/raw`` and ``/bci/prediction`` over DDS, maps each prediction stamp back to the stream
sample it ends on, and scores the predictions on the same epoch windows as the offline
evaluation. Use a ``ROS_DOMAIN_ID`` of your own: the nodes run on the current one.
"""

from __future__ import annotations

import dataclasses
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from mindgrasp_classifier.data import Recording
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import MiModel, resolve_model_path
from mindgrasp_classifier.training import score_predictions
from mindgrasp_ros.node_process import NodeProcess
from mindgrasp_ros.topics import BCI_PREDICTION, EEG_RAW


def _stamp(msg: Any) -> float:
    return msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec


def stream_live(model_path: str, rec: Recording, workdir: Path,
                timeout_margin: float = 20.0, progress: bool = False,
                desc: str = 'live') -> tuple[np.ndarray, np.ndarray]:
    """Play one recording through LSL -> acquisition node -> classifier node in real time.

    Returns
    -------
    ends : ndarray of int, shape (n_predictions,)
        Recording sample index of each predicted window's last sample.
    distances : ndarray, shape (n_predictions, n_classes)
    """
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import EEGChunk, MIPrediction

    from mindgrasp_eeg.acquisition import read_clocks
    from mindgrasp_eeg.acquisition_node import AcquisitionNode
    from mindgrasp_eeg.player import DatasetPlayer
    from mindgrasp_ros import rclpy

    name = f'mindgrasp-eval-{uuid.uuid4().hex[:8]}'
    data = np.where(np.isfinite(rec.data), rec.data, 0.0)   # the player streams numbers only
    player = DatasetPlayer(dataclasses.replace(rec, data=data, annotations=[]),
                           name, block=max(1, round(rec.rate / 64)))
    procs: list[NodeProcess] = []
    rclpy.init(args=[])
    try:
        node = rclpy.node.Node(f'classifier_live_eval_{uuid.uuid4().hex[:6]}')
        executor = rclpy.executors.SingleThreadedExecutor()
        executor.add_node(node)
        chunks: list[tuple[float, int, int]] = []
        preds: list[tuple[float, np.ndarray]] = []
        node.create_subscription(
            EEGChunk, EEG_RAW.name,
            lambda m: chunks.append((_stamp(m), int(m.first_sample_index), int(m.n_samples))),
            EEG_RAW.qos)
        node.create_subscription(     # depth 100 (the table's is 10): no prediction dropped
            MIPrediction, BCI_PREDICTION.name,
            lambda m: preds.append((_stamp(m), np.asarray(m.distances, dtype=float))), 100)
        # the classifier first: the stream must not sit idle while it loads (an acquisition
        # node that hears nothing for 5 s reconnects, and would miss the first samples)
        clf = NodeProcess(
            'mindgrasp_classifier.classifier_node',
            ['--ros-args', '-r', f'__node:=classifier_{name[-8:]}', '-p', f'model:={model_path}',
             '-p', 'classes:=[]'],
            None, workdir / 'classifier.log')
        procs.append(clf)
        if not clf.wait_for_output('Loaded', 60):
            msg = f'The classifier node did not start:\n{clf.output()[-2000:]}'
            raise ClassifierError(msg)
        acq = NodeProcess(
            AcquisitionNode.__module__,
            ['--ros-args', '-r', f'__node:={AcquisitionNode.node_traits.name}_{name[-8:]}',
             '-p', f'stream_name:={name}', '-p', f'n_channels:={len(rec.channels)}',
             '-p', f'sample_rate:={rec.rate}', '-p', 'check_channel_names:=false',
             '-p', 'adapt_to_stream:=true', '-p', 'resolve_timeout:=30.0'],
            None, workdir / 'acquisition.log')
        procs.append(acq)
        if not acq.wait_for_output('Connected to', 60):
            msg = f'The acquisition node did not connect to the player:\n{acq.output()[-2000:]}'
            raise ClassifierError(msg)
        pub_ready = time.monotonic() + 30
        while time.monotonic() < pub_ready and not (
                node.count_publishers(BCI_PREDICTION.name) and node.count_publishers(EEG_RAW.name)):
            executor.spin_once(timeout_sec=0.05)
        time.sleep(1.0)                              # let discovery settle on both sides
        thread = threading.Thread(target=player.run, kwargs={'period': 0.005}, daemon=True)
        thread.start()
        end = time.monotonic() + rec.data.shape[0] / rec.rate + timeout_margin
        n_expected = rec.data.shape[0]
        from tqdm import tqdm

        bar = tqdm(total=round(n_expected / rec.rate, 1), unit='s', desc=desc, file=sys.stderr,
                   disable=not progress, bar_format='{l_bar}{bar}| {n:.1f}/{total:.1f} s '
                                                    '[{elapsed}<{remaining}]')
        while time.monotonic() < end:
            executor.spin_once(timeout_sec=0.02)
            streamed = round(min(sum(c[2] for c in chunks), n_expected) / rec.rate, 1)
            if streamed > bar.n:
                bar.update(streamed - bar.n)   # seconds of EEG through the node chain
            if not thread.is_alive() and chunks and \
                    chunks[-1][1] + chunks[-1][2] >= n_expected and \
                    preds and preds[-1][0] >= chunks[-1][0]:
                break
            if clf.poll() is not None:
                msg = f'The classifier node stopped:\n{clf.output()[-2000:]}'
                raise ClassifierError(msg)
        bar.close()
        for _ in range(20):
            executor.spin_once(timeout_sec=0.02)
        lsl_now, ros_now_ns = read_clocks(lambda: node.get_clock().now().nanoseconds)
        node.destroy_node()
    finally:
        player.close()
        for p in reversed(procs):
            p.stop()
        rclpy.try_shutdown()
    start = None if player.start_time is None else \
        player.start_time + (ros_now_ns * 1e-9 - lsl_now)
    return _map_predictions(chunks, preds, rec.rate, start)


def _map_predictions(chunks: list[tuple[float, int, int]], preds: list[tuple[float, np.ndarray]],
                     rate: float, start: float | None) -> tuple[np.ndarray, np.ndarray]:
    """Recording sample index of each prediction's last sample.

    The acquisition node numbers samples from the first one it received, so its index is the
    recording's only when nothing was missed at the start. ``start`` (ROS time, s, of the
    recording's sample 0, from the player's clock) gives each chunk its recording index; the
    difference is the shift. Within the stream: stamp = chunk stamp + (index - first) / rate.
    """
    if not chunks or not preds or start is None:
        msg = ('No EEG chunks or predictions arrived; check that DDS works on this ROS_DOMAIN_ID '
               'and look at the node logs.')
        raise ClassifierError(msg)
    chunks = sorted(chunks)
    stamps = np.array([c[0] for c in chunks])
    firsts = np.array([c[1] for c in chunks])
    shift = int(np.median(np.round((stamps - start) * rate) - firsts))
    ends, dists = [], []
    for t, d in preds:
        i = int(np.searchsorted(stamps, t + 0.5 / rate, side='right')) - 1
        if i < 0:
            continue
        s, first, _n = chunks[i]
        ends.append(first + shift + round((t - s) * rate))
        dists.append(d)
    return np.array(ends, dtype=int), np.array(dists)


def evaluate_live(model_path: str, recordings: Sequence[Recording], tmin: float = 0.5,
                  tmax: float = 2.5, speed: float = 1.0, progress: bool = False) -> dict[str, Any]:
    """Stream each recording through the live node chain and score the predictions."""
    if speed != 1.0:
        msg = (f'--live plays in real time only (speed 1.0, got {speed}): prediction stamps are '
               'mapped back to samples through the real-time stream clock.')
        raise ClassifierError(msg)
    model = MiModel.load(model_path)
    results = []
    with tempfile.TemporaryDirectory(prefix='mindgrasp-live-') as tmp:
        for i, rec in enumerate(recordings):
            work = Path(tmp) / f'rec{i}'
            work.mkdir()
            results.append(stream_live(str(resolve_model_path(model_path)), rec, work,
                                       progress=progress,
                                       desc=f'live {i + 1}/{len(recordings)}'))
    report = score_predictions(model, recordings, results, tmin, tmax)
    report['n_predictions'] = int(sum(len(e) for e, _ in results))
    return report
