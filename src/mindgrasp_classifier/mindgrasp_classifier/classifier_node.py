"""MI classifier node: /eeg/raw (EEGChunk) -> /bci/prediction (MIPrediction) + /bci/status.

    python -m mindgrasp_classifier.classifier_node --ros-args -p model:=models/my_model.json
    python -m mindgrasp_classifier.classifier_node --ros-args \
        --params-file config/param/classifier.yaml

One prediction per window step (1/16 s by default), stamped with the ROS time of the window's last
sample. While the window fills, or when the window holds NaN or flat channels, no prediction is
published and ``/bci/status`` (diagnostic_msgs/DiagnosticArray) says why. The node refuses to run
when the model's channels, rate or classes do not match the stream. With ``adaptation`` set, class
means adapt during the session (supervised from ``/trainer/prompt``, unsupervised from confident
predictions); ``recenter:=adaptive`` tracks the session's Riemannian mean (re-centering).
All decoding is done by :class:`~mindgrasp_classifier.decoder.MiDecoder`.
"""

from __future__ import annotations

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
from mindgrasp_classifier.model import MiModel
from mindgrasp_classifier.params import ClassifierParams
from mindgrasp_ros import rclpy
from mindgrasp_ros.node_main import declare_duration, fail, run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params
from mindgrasp_ros.topics import BCI_PREDICTION, BCI_STATUS, EEG_RAW, TRAINER_PROMPT


class ClassifierNode(rclpy.node.Node):
    """Wires :class:`MiDecoder` to ``/eeg/raw``, ``/trainer/prompt``, ``/bci/prediction``."""

    node_traits = NodeTraits(name='classifier')

    def __init__(self, **kwargs) -> None:
        super().__init__(self.node_traits.name, **kwargs)
        self.params = declare_params(self, ClassifierParams)
        if self.params.blas_threads > 0:
            # small matrices: multi-threaded BLAS only adds latency, worst on a busy machine
            threadpool_limits(limits=int(self.params.blas_threads))
        self.model = MiModel.load(self.params.model)
        if self.params.classes:
            check_classes(self.model, self.params.classes)
        self.adaptation = AdaptationConfig(
            mode=self.params.adaptation, rate=self.params.adaptation_rate,
            min_certainty=self.params.min_certainty, recenter=self.params.recenter,
            recenter_rate=self.params.recenter_rate, recenter_prior=self.params.recenter_prior)
        self.adaptation.check()
        self.cues = CueLabels(self.params.label_tmin, self.params.label_tmax)
        self._last_trial = -1
        self.decoder: MiDecoder | None = None
        self.n_predictions = 0
        self._state = (DiagnosticStatus.WARN, f'Waiting for EEG on /eeg/raw '
                       f'({len(self.model.channels)} channels at {self.model.rate:g} Hz).')
        self._last_sent = None
        self.pub_pred = self.create_publisher(MIPrediction, BCI_PREDICTION.name,
                                              BCI_PREDICTION.qos)
        self.pub_status = self.create_publisher(DiagnosticArray, BCI_STATUS.name, BCI_STATUS.qos)
        self.create_subscription(EEGChunk, EEG_RAW.name, self.eeg_callback, EEG_RAW.qos)
        self.create_subscription(Prompt, TRAINER_PROMPT.name, self.prompt_callback,
                                 TRAINER_PROMPT.qos)
        self.create_timer(self.params.status_period, self.status_callback)
        self.done = rclpy.task.Future()
        declare_duration(self)
        self.get_logger().info(
            f'Loaded {self.params.model}: {self.model.pipeline}, classes {self.model.class_names}, '
            f'{len(self.model.channels)} channels at {self.model.rate:g} Hz, window '
            f'{self.model.window:g} s every {self.model.step * 1e3:.1f} ms; adaptation '
            f'{self.adaptation.mode}, re-centering {self.adaptation.recenter}.')

    def eeg_callback(self, msg: EEGChunk) -> None:
        """Decode a chunk; publish a prediction per completed window."""
        if self.done.done():
            return
        n_ch = len(msg.channel_names)
        layout = (list(msg.channel_names), float(msg.sample_rate))
        if self.decoder is None:
            try:
                self.decoder = MiDecoder(self.model, layout[0], layout[1],
                                         self.adaptation, self.params.flat_threshold)
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
        stamp_s = rclpy.time.Time.from_msg(msg.header.stamp).nanoseconds * 1e-9
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
                           window_length=float(self.model.window),
                           probabilities=np.asarray(pred.probabilities, dtype=np.float32))
        msg.header.stamp = rclpy.time.Time(nanoseconds=round(end_s * 1e9)).to_msg()
        msg.header.frame_id = self.params.frame_id
        self.pub_pred.publish(msg)
        self.n_predictions += 1

    def prompt_callback(self, msg: Prompt) -> None:
        """Remember cue onsets (first classed prompt of a trial, as training epochs) for
        supervised adaptation."""
        if (msg.class_index != Prompt.NO_CLASS and msg.phase in ('cue', 'move')
                and msg.trial != self._last_trial):
            self._last_trial = msg.trial
            self.cues.add(rclpy.time.Time.from_msg(msg.header.stamp).nanoseconds * 1e-9,
                          int(msg.class_index))

    def fail(self, reason: str) -> None:
        """Refuse to run: publish an ERROR status, end the node (exit code 1 with the reason)."""
        self.set_state(DiagnosticStatus.ERROR, reason)
        self.status_callback()
        fail(self, reason)

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
        values = {'model': str(self.params.model), 'pipeline': self.model.pipeline,
                  'predictions': str(self.n_predictions),
                  'adaptation': self.adaptation.mode, 'recenter': self.adaptation.recenter}
        if dec is not None:
            values['adaptive_updates'] = str(dec.n_updates)
            values['window_samples'] = f'{dec.samples_buffered}/{dec.n_window}'
            if dec.segment_start is not None:
                # where the causal filter started: a replay starts there to decide identically
                values['segment_start_sample'] = str(dec.segment_start)
        item = DiagnosticStatus(level=level, name=self.node_traits.name, message=message,
                                hardware_id='', values=[KeyValue(key=k, value=v)
                                                        for k, v in sorted(values.items())])
        msg = DiagnosticArray(status=[item])
        msg.header.stamp = self.get_clock().now().to_msg()
        self.pub_status.publish(msg)



def main(args: list[str] | None = None) -> int:
    """Run the node until Ctrl-C or ``duration``; exit 2 on a bad parameter or model, 1 when the
    stream does not fit the model."""
    return run_node(ClassifierNode, args, errors=(ClassifierError,))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
