"""ROS plumbing shared by the trainer nodes: prompt QoS and message, rate and parameter checks.
Imports the client layer; the protocols themselves do not.
"""

from __future__ import annotations

from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt
from mindgrasp_ros.interfaces.rcl_interfaces.msg import SetParametersResult

from mindgrasp_ros import rclpy
from mindgrasp_trainer.protocol import PromptEvent, TrainerError

__all__ = [
    'EegGate',
    'check_rate',
    'fixed_parameters_callback',
    'prompt_qos',
    'to_msg',
]


class EegGate:
    """Tells a prompter when EEG flows on /eeg/raw, so that its first trial is recorded.

    Subscribes until the first chunk arrives, then unsubscribes (the prompter does not need the
    samples); logs once that it waits.
    """

    def __init__(self, node: rclpy.node.Node) -> None:
        from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import EEGChunk

        from mindgrasp_ros.topics import EEG_RAW

        self.node = node
        self.seen = False
        self.logged = False
        self.sub = node.create_subscription(EEGChunk, EEG_RAW.name, self._callback, EEG_RAW.qos)

    def _callback(self, _msg: object) -> None:
        if not self.seen:
            self.seen = True
            self.node.get_logger().info('EEG is flowing on /eeg/raw; the session starts.')

    def ready(self) -> bool:
        if self.seen and self.sub is not None:
            self.node.destroy_subscription(self.sub)
            self.sub = None
        if not self.seen and not self.logged:
            self.logged = True
            self.node.get_logger().info(
                'Waiting for EEG on /eeg/raw before the first trial (wait_for_eeg).')
        return self.seen


def prompt_qos() -> rclpy.qos.QoSProfile:
    """QoS of /trainer/prompt (the topic table, :data:`mindgrasp_ros.topics.TRAINER_PROMPT`)."""
    from mindgrasp_ros.topics import TRAINER_PROMPT

    return TRAINER_PROMPT.qos


def check_rate(name: str, value: float, allow_zero: bool = False) -> float:
    """Validate a timer rate parameter (Hz)."""
    value = float(value)
    if not (value > 0 or (allow_zero and value == 0)) or value > 10000:
        zero = ' (0 turns it off)' if allow_zero else ''
        msg = (
            f"The rate '{name}' must be a positive number of Hz up to 10000{zero}; "
            f'{value} is invalid.'
        )
        raise TrainerError(msg)
    return value


def fixed_parameters_callback(live: dict) -> object:
    """An on-set-parameters callback: names in ``live`` map to a validator that applies the new
    value; every other parameter is fixed for the session and the change is refused."""

    def callback(params: list) -> SetParametersResult:
        for param in params:
            if param.name == 'use_sim_time':
                continue
            if param.name not in live:
                return SetParametersResult(
                    successful=False,
                    reason=f"'{param.name}' is fixed once the session is planned; restart the "
                    f'node to change it (live: {", ".join(sorted(live)) or "none"}).',
                )
            try:
                live[param.name](param.value)
            except TrainerError as err:
                return SetParametersResult(successful=False, reason=str(err))
        return SetParametersResult(successful=True)

    return callback


def to_msg(event: PromptEvent, stamp) -> Prompt:
    """A mindgrasp_msgs/Prompt for ``event``, stamped with the phase onset ``stamp``."""
    msg = Prompt(
        paradigm=event.paradigm,
        class_index=event.class_index,
        class_name=event.class_name,
        phase=event.phase,
        trial=event.trial,
        duration=event.duration,
    )
    msg.header.stamp = stamp
    return msg
