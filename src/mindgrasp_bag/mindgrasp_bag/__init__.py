"""rosbag2 recording and playback for MIndGrasp: MCAP storage, metadata.yaml version 9.

Layers: :mod:`.qos`, :mod:`.metadata` and :mod:`.mcap_scan` (file formats), :mod:`.writer` and
:mod:`.reader` (bags), :mod:`.recorder` and :mod:`.player` (ROS-free cores driven by callbacks),
:mod:`.recorder_node` and :mod:`.player_node` (ROS nodes), :mod:`.info` (``bag info`` text).
"""

from .errors import BagError
from .player import Player, PlayStats
from .reader import BagReader, TopicInfo
from .recorder import Recorder, TopicCounters
from .writer import BagWriter

__all__ = ['BagError', 'BagReader', 'BagWriter', 'PlayStats', 'Player', 'Recorder',
           'TopicCounters', 'TopicInfo']
