"""MI classifier node: /eeg/raw (EEGChunk) -> /bci/prediction (MIPrediction) + /bci/status.

    python -m mindgrasp_classifier.classifier_node --ros-args -p model:=models/my_model.json
    python -m mindgrasp_classifier.classifier_node --ros-args \
        --params-file src/mindgrasp_classifier/mindgrasp_classifier/param/classifier.yaml

One prediction per window step (1/16 s by default), stamped with the ROS time of the window's last
sample. While the window fills, or when the window holds NaN or flat channels, no prediction is
published and ``/bci/status`` (diagnostic_msgs/DiagnosticArray) says why. The node refuses to run
when the model's channels, rate or classes do not match the stream. With ``adaptation`` set, class
means adapt during the session (supervised from ``/trainer/prompt``, unsupervised from confident
predictions); ``recenter:=adaptive`` tracks the session's Riemannian mean (re-centering).
All decoding is done by :class:`~mindgrasp_classifier.decoder.MiDecoder`.
"""

from __future__ import annotations

import sys

import numpy as np
from mindgrasp_ros.interfaces.diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import EEGChunk, MIPrediction, Prompt
from threadpoolctl import threadpool_limits

from mindgrasp_classifier.decoder import (
    AdaptationConfig,
    CueLabels,
    MiDecoder,
    Prediction,
    check_classes,
)
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import CLASS_NAMES, DEFAULT_MODEL, MiModel
from mindgrasp_ros import rclpy

PARAMETERS = [
    ('model', DEFAULT_MODEL), ('classes', list(CLASS_NAMES)),
    ('adaptation', 'none'), ('adaptation_rate', 0.005), ('min_certainty', 0.5),
    ('recenter', 'fixed'), ('recenter_rate', 0.005), ('label_tmin', 0.5), ('label_tmax', 2.5),
    ('flat_threshold', 1e-8), ('status_period', 1.0), ('frame_id', 'eeg'), ('duration', 0.0),
    ('blas_threads', 1),
]


class ClassifierNode(rclpy.node.Node):
    """Wires :class:`MiDecoder` to ``/eeg/raw``, ``/trainer/prompt``, ``/bci/prediction``."""

    def __init__(self, **kwargs) -> None:
        super().__init__('classifier', **kwargs)
        self.declare_parameters('', PARAMETERS)
        self.p = {name: self.get_parameter(name).value for name, _ in PARAMETERS}
        if self.p['blas_threads'] > 0:
            # small matrices: multi-threaded BLAS only adds latency, worst on a busy machine
            threadpool_limits(limits=int(self.p['blas_threads']))
        self.model = MiModel.load(self.p['model'])
        if self.p['classes']:
            check_classes(self.model, self.p['classes'])
        self.adaptation = AdaptationConfig(
            mode=self.p['adaptation'], rate=self.p['adaptation_rate'],
            min_certainty=self.p['min_certainty'], recenter=self.p['recenter'],
            recenter_rate=self.p['recenter_rate'])
        self.adaptation.check()
        self.cues = CueLabels(self.p['label_tmin'], self.p['label_tmax'])
        self._last_trial = -1
        self.decoder: MiDecoder | None = None
        self.error: str | None = None
        self.n_predictions = 0
        self._state = (DiagnosticStatus.WARN, f'Waiting for EEG on /eeg/raw '
                       f'({len(self.model.channels)} channels at {self.model.rate:g} Hz).')
        self._last_sent = None
        qos_raw = rclpy.qos.QoSProfile(depth=100,
                                       reliability=rclpy.qos.ReliabilityPolicy.BEST_EFFORT,
                                       durability=rclpy.qos.DurabilityPolicy.VOLATILE)
        qos_prompt = rclpy.qos.QoSProfile(depth=10,
                                          reliability=rclpy.qos.ReliabilityPolicy.RELIABLE,
                                          durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL)
        self.pub_pred = self.create_publisher(MIPrediction, '/bci/prediction', 10)
        self.pub_status = self.create_publisher(DiagnosticArray, '/bci/status', 10)
        self.create_subscription(EEGChunk, '/eeg/raw', self.eeg_callback, qos_raw)
        self.create_subscription(Prompt, '/trainer/prompt', self.prompt_callback, qos_prompt)
        self.create_timer(self.p['status_period'], self.status_callback)
        self._start_ns = self.get_clock().now().nanoseconds
        self.create_timer(0.1, self.duration_callback)
        self.done = False
        self.get_logger().info(
            f'Loaded {self.p["model"]}: {self.model.pipeline}, classes {self.model.class_names}, '
            f'{len(self.model.channels)} channels at {self.model.rate:g} Hz, window '
            f'{self.model.window:g} s every {self.model.step * 1e3:.1f} ms; adaptation '
            f'{self.adaptation.mode}, re-centering {self.adaptation.recenter}.')

    def eeg_callback(self, msg: EEGChunk) -> None:
        """Decode a chunk; publish a prediction per completed window."""
        if self.error is not None:
            return
        n_ch = len(msg.channel_names)
        layout = (list(msg.channel_names), float(msg.sample_rate))
        if self.decoder is None:
            try:
                self.decoder = MiDecoder(self.model, layout[0], layout[1],
                                         self.adaptation, self.p['flat_threshold'])
            except ClassifierError as exc:
                self.fail(str(exc))
                return
            self._layout = layout
        elif layout != self._layout:
            self.fail(f'The EEG stream on /eeg/raw changed from {len(self._layout[0])} channels '
                      f'at {self._layout[1]:g} Hz to {n_ch} channels at {layout[1]:g} Hz '
                      '(another amplifier or a second publisher?); keep one stream per topic '
                      'and restart the classifier.')
            return
        data = np.asarray(msg.data, dtype=float)
        if n_ch == 0 or data.size != int(msg.n_samples) * n_ch:
            self.set_state(DiagnosticStatus.WARN, f'Dropped a malformed EEG chunk ({data.size} '
                           f'values for {msg.n_samples} samples x {n_ch} channels).')
            return
        unit_scale = {'': 1.0, 'V': 1.0, 'mV': 1e-3, 'uV': 1e-6, 'µV': 1e-6}.get(msg.unit)
        if unit_scale is None:
            self.fail(f'The EEG stream has unit {msg.unit!r}; publish EEG in V (or mV/uV).')
            return
        stamp_s = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
        first = int(msg.first_sample_index)
        rate = float(msg.sample_rate)
        dec = self.decoder
        try:
            results = dec.push(data.reshape(int(msg.n_samples), n_ch) * unit_scale, first)
        except ClassifierError as exc:
            self.fail(str(exc))
            return
        if not results:
            if dec.samples_buffered < dec.n_window:
                self.set_state(DiagnosticStatus.WARN, f'Filling the window: '
                               f'{dec.samples_buffered}/{dec.n_window} samples.')
            return
        for res in results:
            end_s = stamp_s + (res.sample_index - first) / rate
            if not isinstance(res, Prediction):
                self.set_state(DiagnosticStatus.WARN, f'No prediction: {res.reason}')
                continue
            self.publish_prediction(res, end_s)
        if isinstance(results[-1], Prediction):
            self.set_state(DiagnosticStatus.OK, 'Decoding.')
        # label for the next windows (supervised adaptation): the next window's span
        nxt = end_s + dec.n_step / rate
        dec.set_label(self.cues.label(nxt - dec.n_window / rate, nxt))

    def publish_prediction(self, pred: Prediction, end_s: float) -> None:
        """Send one MIPrediction stamped with the window's last sample."""
        msg = MIPrediction(class_index=pred.class_index, class_names=self.model.class_names,
                           certainty=float(pred.certainty),
                           distances=np.asarray(pred.distances, dtype=np.float32),
                           window_length=float(self.model.window))
        ns = round(end_s * 1e9)
        msg.header.stamp.sec, msg.header.stamp.nanosec = ns // 1_000_000_000, ns % 1_000_000_000
        msg.header.frame_id = self.p['frame_id']
        self.pub_pred.publish(msg)
        self.n_predictions += 1

    def prompt_callback(self, msg: Prompt) -> None:
        """Remember cue onsets (first classed prompt of a trial, as training epochs) for
        supervised adaptation."""
        if (msg.class_index != Prompt.NO_CLASS and msg.phase in ('cue', 'move')
                and msg.trial != self._last_trial):
            self._last_trial = msg.trial
            self.cues.add(msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec,
                          int(msg.class_index))

    def fail(self, reason: str) -> None:
        """Refuse to run: log, publish an ERROR status, end the node."""
        self.error = reason
        self.get_logger().error(reason)
        self.set_state(DiagnosticStatus.ERROR, reason)
        self.status_callback()
        self.done = True

    def set_state(self, level: int, message: str) -> None:
        """Change the status; published at once when the level or reason changes."""
        old = self._state
        self._state = (level, message)
        if old[0] != level or (level != DiagnosticStatus.OK and old[1].split(':')[0]
                               != message.split(':')[0]):
            if level == DiagnosticStatus.WARN and not message.startswith('Filling'):
                self.get_logger().warning(message)
            self.status_callback()

    def status_callback(self) -> None:
        """Publish /bci/status."""
        level, message = self._state
        dec = self.decoder
        values = {'model': str(self.p['model']), 'pipeline': self.model.pipeline,
                  'predictions': str(self.n_predictions),
                  'adaptation': self.adaptation.mode, 'recenter': self.adaptation.recenter}
        if dec is not None:
            values['adaptive_updates'] = str(dec.n_updates)
            values['window_samples'] = f'{dec.samples_buffered}/{dec.n_window}'
            if dec.segment_start is not None:
                # where the causal filter started: a replay starts there to decide identically
                values['segment_start_sample'] = str(dec.segment_start)
        item = DiagnosticStatus(level=level, name='classifier', message=message,
                                hardware_id='', values=[KeyValue(key=k, value=v)
                                                        for k, v in sorted(values.items())])
        msg = DiagnosticArray(status=[item])
        msg.header.stamp = self.get_clock().now().to_msg()
        self.pub_status.publish(msg)

    def duration_callback(self) -> None:
        """End after ``duration`` seconds when it is > 0."""
        duration = self.p['duration']
        if duration > 0 and self.get_clock().now().nanoseconds - self._start_ns > duration * 1e9:
            self.done = True


def main(args: list[str] | None = None) -> int:
    """Run the node until Ctrl-C or ``duration``; exit 1 with a message on bad input."""
    rclpy.init(args=args)
    node = None
    code = 0
    try:
        node = ClassifierNode()
        executor = rclpy.executors.SingleThreadedExecutor()
        executor.add_node(node)
        while rclpy.ok() and not node.done:
            executor.spin_once(timeout_sec=0.1)
        if node.error is not None:
            print(f'[classifier] ERROR: {node.error}', file=sys.stderr, flush=True)
            code = 1
    except ClassifierError as exc:
        print(f'[classifier] ERROR: {exc}', file=sys.stderr, flush=True)
        code = 1
    except KeyboardInterrupt:
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return code


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
