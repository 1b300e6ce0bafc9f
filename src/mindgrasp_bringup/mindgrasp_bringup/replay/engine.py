"""Replay a recorded run as an experiment: its recorded inputs drive the same node classes again.

    result = replay(ReplayConfig('runs/20261122T174209Z_demo', controller=True))
    result.report_path      # runs/<run>/replays/<time>/report.md

Why it reproduces exactly: the chosen nodes (the classifier; the controller when asked) run in
one process under the one graph host (:class:`~mindgrasp_ros.graph.host.GraphRunner`, ``Lockstep``
scheduler) on the bag's clock. Every
recorded input message (the /eeg/raw chunks with their stamps and sample indices, exactly as
recorded, never re-chunked) is published at its recorded time, and the graph runs until it is
quiescent before the next one, so nothing is lost or reordered and no wall-clock time enters a
decision. The classifier decides on windows of a global sample grid and stamps them from the
chunk stamps; it starts its causal filter on the sample the live classifier started on (from the
recorded ``/bci/status`` ``segment_start_sample``), and a later restart of the live filter (a
chunk it lost) is reproduced by leaving out the chunk before it. With the same model and
parameters (the run's params.yaml), the replayed predictions equal the recorded ones.

The controller is replayed open loop: its commands go nowhere, and the joint states, camera
images and detections it reads are the recorded ones, which followed the recorded arm.
"""

from __future__ import annotations

import datetime as dt
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from mindgrasp_bag.damage import assess_bag
from mindgrasp_bag.errors import BagError
from mindgrasp_bag.param_changes import PARAMETER_EVENTS
from mindgrasp_bag.paths import resolve_bag, run_dir_of
from mindgrasp_bag.qos import adapted_qos
from mindgrasp_bag.reader import BagReader
from mindgrasp_bag.ros_glue import qos_profile
from mindgrasp_bag.typestore import typestore as default_typestore
from mindgrasp_bag.writer import BagWriter
from mindgrasp_bringup.replay.param_changes import ParameterChange, apply_change, recorded_changes
from mindgrasp_ros.topics import BCI_PREDICTION, BCI_STATUS, CLOCK, EEG_RAW, FSM_STATE

__all__ = ['COMPARED_TOPICS', 'NODES', 'ReplayConfig', 'ReplayResult', 'replay']

#: nodes a replay can re-run, by the key of ``-p KEY.NAME:=VALUE`` (:func:`_node_classes`)
NODES = ('classifier', 'controller')
#: outputs compared recorded vs replayed: topic -> type
COMPARED_TOPICS = {BCI_PREDICTION.name: BCI_PREDICTION.type, FSM_STATE.name: FSM_STATE.type}
EEG_TOPIC = EEG_RAW.name
EEG_TYPE = EEG_RAW.type
STATUS_TOPIC = BCI_STATUS.name
#: never fed from the bag: the runner owns /clock; graph topics (live parameter changes are
#: applied to the re-run nodes instead: replay.param_changes)
_NOT_FED = (CLOCK.name, PARAMETER_EVENTS, '/rosout')


@dataclass
class ReplayConfig:
    """What to replay and how.

    Attributes
    ----------
    run
        Run directory (``runs/<run>``) or its bag folder.
    controller
        Re-run the controller too (open loop), not only the classifier.
    model
        Classifier model file; '' = the one the run used (its params.yaml).
    params
        Extra parameter overrides per node key (``{'classifier': {'min_certainty':
        0.6}}``).
    output
        Report directory; default ``<run>/replays/<UTC time>``.
    max_step_s
        Longest clock step (s) between recorded messages, so node timers keep
        their cadence (the controller's control loop).
    progress
        Show a tqdm progress bar on stderr.
    """

    run: str | Path
    controller: bool = False
    model: str = ''
    params: dict[str, dict[str, Any]] = field(default_factory=dict)
    output: str | Path | None = None
    max_step_s: float | None = None
    progress: bool = True


@dataclass
class ReplayResult:
    """Recorded and replayed outputs: topic -> [(log time ns, CDR bytes)]; where it is written."""

    bag: Path
    run_dir: Path | None
    output: Path
    nodes: list[str]
    recorded: dict[str, list[tuple[int, bytes]]]
    replayed: dict[str, list[tuple[int, bytes]]]
    fed: dict[str, int]                   # topic -> messages fed
    skipped_eeg_chunks: int               # chunks left out to reproduce the live filter starts
    first_fed_eeg_ns: int | None          # stamp of the first EEG chunk fed (ns)
    last_fed_eeg_ns: int | None           # stamp of the last sample fed (ns)
    start_ns: int
    end_ns: int
    notes: list[str] = field(default_factory=list)
    damage: dict[str, Any] = field(default_factory=dict)   # :meth:`BagDamage.as_dict`
    report_path: Path | None = None
    summary: dict[str, Any] = field(default_factory=dict)
    parameter_changes: list[dict[str, Any]] = field(default_factory=list)  # recorded, re-applied


def _node_classes() -> dict[str, type]:
    """Key of :data:`NODES` -> the node class; its name (the section of params.yaml, its
    diagnostic status) is the class's own (:class:`~mindgrasp_ros.node_traits.NodeTraits`)."""
    from mindgrasp_classifier.classifier_node import ClassifierNode
    from mindgrasp_fsm.fsm_node import FsmNode

    return {'classifier': ClassifierNode, 'controller': FsmNode}


def _node_params(run_dir: Path | None, name: str) -> dict[str, Any]:
    if run_dir is None:
        return {}
    try:
        data = yaml.safe_load((run_dir / 'params.yaml').read_text()) or {}
    except (OSError, yaml.YAMLError):
        return {}
    for key in (f'/{name}', name):
        section = data.get(key)
        if isinstance(section, dict):
            return dict(section.get('ros__parameters') or {})
    return {}


def _segment_starts(statuses: list[bytes], store: Any, classifier: str) -> list[int]:
    """Samples where the live classifier (status name ``classifier``) (re)started its filter,
    in order (from /bci/status)."""
    starts: list[int] = []
    for data in statuses:
        msg = store.deserialize_cdr(data, 'diagnostic_msgs/msg/DiagnosticArray')
        for status in msg.status:
            if status.name != classifier:
                continue
            for kv in status.values:
                if kv.key == 'segment_start_sample':
                    value = int(kv.value)
                    if not starts or value > starts[-1]:
                        starts.append(value)
    return starts


def _stamp_ns(header: Any) -> int:
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def replay(cfg: ReplayConfig) -> ReplayResult:
    """Run the replay; the comparison report is written by :func:`.report.write_report`.

    Raises
    ------
    BagError
        The run or bag cannot be read, or has nothing to replay.
    """
    from mindgrasp_ros import rclpy
    from mindgrasp_ros.graph.host import GraphRunner, Lockstep
    from mindgrasp_ros.graph.spec import NodeSpec
    from mindgrasp_ros.node_traits import traits_of
    from mindgrasp_ros.runtime.arguments import load_params_file

    bag = resolve_bag(cfg.run)
    run_dir = run_dir_of(bag)
    store = default_typestore()
    keys = list(NODES) if cfg.controller else ['classifier']
    classes = _node_classes()
    names = {key: traits_of(classes[key]).name for key in keys}
    stamp = dt.datetime.now(dt.timezone.utc).strftime('%Y%m%dT%H%M%SZ')
    base = run_dir if run_dir is not None else bag.resolve().parent
    output = Path(cfg.output) if cfg.output else base / 'replays' / stamp
    reader = BagReader(bag).open()
    # one damage policy for every bag tool: replay what can be read, say and count what cannot
    damage = assess_bag(bag)
    try:
        if EEG_TOPIC not in reader.topics or not reader.topics[EEG_TOPIC].message_count:
            msg = (f'The bag {bag} has no {EEG_TOPIC} messages, so the classifier has nothing to '
                   'decode; replay a run recorded with the EEG (record:=true, the default).')
            raise BagError(msg)
        output.mkdir(parents=True, exist_ok=False)
        (output / 'params').mkdir()
        # the bag's clock: ns exactly (start_time_s would round through a float)
        graph = GraphRunner(Lockstep(start_time_ns=reader.start_ns))
        runner = graph.scheduler.runner
        try:
            nodes = []
            for key in keys:
                module, name = classes[key].__module__, names[key]
                params = _node_params(run_dir, name)
                params.update(cfg.params.get(key, {}))
                if key == 'classifier' and cfg.model:
                    params['model'] = str(cfg.model)
                params.pop('use_sim_time', None)  # the runner puts every node on the bag clock
                params['duration'] = 0.0          # end with the bag, not after a live duration
                path = output / 'params' / f'{name}.yaml'
                path.write_text(yaml.safe_dump({f'/{name}': {'ros__parameters': params}},
                                               sort_keys=True))
                spec = NodeSpec(name, module, parameters=load_params_file(path, f'/{name}'))
                try:
                    nodes.append(graph.add(spec))
                except Exception as exc:  # each node package raises its own error type
                    msg = (f'The {key} node cannot start with the parameters of the run '
                           f'({type(exc).__name__}: {exc}); override the parameter with '
                           f'-p {key}.NAME:=VALUE (e.g. a path of a run made by an older '
                           'version).')
                    raise BagError(msg) from None
            outputs = {p.topic_name for n in nodes for p in n.publishers}
            inputs = {s.topic_name for n in nodes for s in n.subscriptions}
            feed = sorted(t for t in inputs if t in reader.topics and t not in outputs
                          and t not in _NOT_FED)
            collect = [t for t in COMPARED_TOPICS if t in outputs]
            io = runner.add(rclpy.node.Node, 'replay_io')
            replayed: dict[str, list[tuple[int, bytes]]] = {t: [] for t in collect}
            for topic in collect:
                def keep(data: bytes, _info: Any = None, topic: str = topic) -> None:
                    replayed[topic].append((runner.time_ns, bytes(data)))
                io.create_subscription(COMPARED_TOPICS[topic], topic, keep,
                                       qos_profile(rclpy, {'reliability': 'reliable',
                                                           'durability': 'volatile',
                                                           'depth': 10000}), raw=True)
            pubs = {}
            for topic in feed:
                info = reader.topics[topic]
                qos = adapted_qos(info.offered_qos_profiles)
                qos['depth'] = 10000
                pubs[topic] = io.create_publisher(info.type, topic, qos_profile(rclpy, qos),
                                                  raw=True)
            runner.spin_until_quiescent()
            # one pass over the bag (images and other large topics are skipped by the index)
            recorded: dict[str, list[tuple[int, bytes]]] = {
                t: [] for t in COMPARED_TOPICS if t in reader.topics}
            statuses: list[bytes] = []
            inputs: list[tuple[str, int, bytes]] = []
            events: list[tuple[int, bytes]] = []   # /parameter_events: live changes
            wanted = set(feed) | set(recorded) | ({STATUS_TOPIC, PARAMETER_EVENTS}
                                                  & set(reader.topics))
            for topic, t_ns, data in reader.messages(sorted(wanted)):
                if topic in recorded:
                    recorded[topic].append((t_ns, data))
                if topic == STATUS_TOPIC:
                    statuses.append(data)
                if topic == PARAMETER_EVENTS:
                    events.append((t_ns, data))
                if topic in pubs:
                    inputs.append((topic, t_ns, data))
            starts = _segment_starts(statuses, store, names['classifier'])
            result = ReplayResult(bag, run_dir, output, keys, recorded, replayed,
                                  dict.fromkeys(feed, 0), 0, None, None, reader.start_ns,
                                  reader.end_ns, damage=damage.as_dict())
            result.notes += [f'Damaged bag: {line}' for line in damage.lines()]
            max_step = cfg.max_step_s or (0.01 if cfg.controller else 0.1)
            by_name = {f'/{names[k]}': n for k, n in zip(keys, nodes, strict=True)}
            changes = recorded_changes(events, store, set(by_name), {
                (f'/{names[k]}', name) for k in keys for name in cfg.params.get(k, {})})
            _feed(runner, inputs, pubs, store, starts, result, max_step, cfg.progress,
                  changes, by_name)
        finally:
            graph.close()
    finally:
        reader.close()
    result.notes += [n for n in reader.notes if n not in result.notes]
    if not starts:
        result.notes.append('The recording has no classifier filter start (/bci/status '
                            'segment_start_sample, recorded by newer classifiers); the replayed '
                            'classifier started on the first recorded EEG chunk.')
    _write_replayed_bag(output / 'replayed_bag', result, store)
    return result


def _feed(runner: Any, inputs: list[tuple[str, int, bytes]], pubs: dict[str, Any], store: Any,
          starts: list[int], result: ReplayResult, max_step_s: float, progress: bool,
          changes: list[ParameterChange] = (), nodes: dict[str, Any] | None = None) -> None:
    """Publish every recorded input at its recorded time; the graph settles after each.
    ``changes`` (live parameter changes) are set on ``nodes`` (by name) at their times."""
    from tqdm import tqdm

    max_step_ns = max(1, round(max_step_s * 1e9))
    total = len(inputs)
    later_starts = set(starts[1:])

    def advance(t_ns: int) -> None:
        while pending and pending[0].time_ns <= t_ns:
            change = pending.pop(0)
            advance(change.time_ns)
            row = apply_change(nodes[change.node], change, runner.time_ns)
            result.parameter_changes.append(row)
            at_s = (row['applied_ns'] - result.start_ns) / 1e9
            result.notes.append(
                f'Live change of the run applied at {at_s:.3f} s: {change.node} '
                f'{change.name}={change.value!r}'
                + ('' if row['successful'] else f' (refused: {row["reason"]})'))
            runner.spin_until_quiescent()
        while runner.time_ns < t_ns:
            runner.step(min(max_step_ns, t_ns - runner.time_ns) / 1e9)

    pending = list(changes)

    bar = tqdm(total=total, unit='msg', desc='replay', disable=not progress, file=sys.stderr,
               leave=True)
    try:
        for topic, t_ns, data in inputs:
            bar.update(1)
            if topic == EEG_TOPIC:
                chunk = store.deserialize_cdr(data, EEG_TYPE)
                first, n = int(chunk.first_sample_index), int(chunk.n_samples)
                if starts and first + n <= starts[0]:
                    result.skipped_eeg_chunks += 1   # before the live classifier started
                    continue
                if first + n in later_starts:
                    result.skipped_eeg_chunks += 1   # the live classifier lost it and restarted
                    continue
                stamp = _stamp_ns(chunk.header)
                if result.first_fed_eeg_ns is None:
                    result.first_fed_eeg_ns = stamp
                rate = float(chunk.sample_rate) or 1.0
                result.last_fed_eeg_ns = stamp + round((n - 1) / rate * 1e9)
            advance(t_ns)
            pubs[topic].publish(data)
            result.fed[topic] += 1
            runner.spin_until_quiescent()
        advance(result.end_ns + 1_000_000_000)  # one more second: the last timers run
    finally:
        bar.close()


def _write_replayed_bag(path: Path, result: ReplayResult, store: Any) -> None:
    """The replayed outputs as a rosbag2 bag (Foxglove, ``mindgrasp bag info``)."""
    with BagWriter(path, typestore=store) as writer:
        for topic, messages in result.replayed.items():
            writer.add_topic(topic, COMPARED_TOPICS[topic])
            for t_ns, data in messages:
                writer.write(topic, t_ns, data)
