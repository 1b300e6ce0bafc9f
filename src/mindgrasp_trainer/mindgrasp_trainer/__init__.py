"""mindgrasp_trainer: cue protocols that calibrate the motor-imagery classifier.

Layers: :mod:`~mindgrasp_trainer.protocol` (class names, prompt events, balanced orders),
:mod:`~mindgrasp_trainer.graz` (Graz-BCI schedule), :mod:`~mindgrasp_trainer.trainer` (MIndGrasp
Trainer state machine), :mod:`~mindgrasp_trainer.display` (Graz screen), all ROS-free; then the
nodes :mod:`~mindgrasp_trainer.graz_node` and :mod:`~mindgrasp_trainer.trainer_node`.
"""

from mindgrasp_trainer.graz import GrazProtocol, PromptSequencer
from mindgrasp_trainer.protocol import CLASS_NAMES, NO_CLASS, PromptEvent, TrainerError
from mindgrasp_trainer.trainer import TrainerProtocol, ee_distance

__all__ = [
    'CLASS_NAMES',
    'NO_CLASS',
    'GrazProtocol',
    'PromptEvent',
    'PromptSequencer',
    'TrainerError',
    'TrainerProtocol',
    'ee_distance',
]
