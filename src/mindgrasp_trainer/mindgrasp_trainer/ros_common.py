"""ROS plumbing shared by the prompter nodes: the EEG gate, the prompt QoS and message.
Imports the client layer; the protocols themselves do not.
"""

from __future__ import annotations

from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt

from mindgrasp_ros import rclpy
from mindgrasp_trainer.protocol import PromptEvent

__all__ = [
    'EegGate',
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
