"""rosbag2 ``metadata.yaml`` (version 9): build, write, load, and rebuild from MCAP files.

A bag whose writer was killed has MCAP files without a summary section and no metadata.yaml;
:func:`rebuild_metadata` recovers both the topic list and the counts from the files themselves
(their summary when present, else a scan of every complete record).

Written here rather than by ``rosbags.rosbag2.Writer``: rosbags writes metadata.yaml only from its
own writer's state when that writer closes, while ours must describe split MCAP files written by
the ``mcap`` library and bags rebuilt from files. The layout follows rosbag2 Jazzy (version 9).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from mindgrasp_common.safe_files import write_atomic

from .errors import BagError
from .mcap_scan import McapContents, read_mcap_contents
from .qos import parse_offered_qos

__all__ = ['DAMAGED_SUFFIX', 'FileStats', 'TopicStats', 'build_metadata', 'load_metadata',
           'mcap_files', 'rebuild_metadata', 'write_metadata']

METADATA_FILE = 'metadata.yaml'
#: what `bag reindex` appends to the name of a file it repaired, kept as it was
DAMAGED_SUFFIX = '.damaged'
ROS_DISTRO = 'jazzy'


@dataclass
class TopicStats:
    """One topic of a bag: rosbag2 topic metadata plus its message count."""

    name: str
    type: str
    offered_qos_profiles: list[dict[str, Any]] = field(default_factory=list)
    type_description_hash: str = ''
    serialization_format: str = 'cdr'
    message_count: int = 0


@dataclass
class FileStats:
    """One storage file of a bag (path relative to the bag directory; times in ns)."""

    path: str
    start_ns: int = 0
    end_ns: int = 0
    message_count: int = 0

    def add(self, timestamp_ns: int) -> None:
        """Count one message at ``timestamp_ns``."""
        if self.message_count == 0:
            self.start_ns = self.end_ns = timestamp_ns
        else:
            self.start_ns = min(self.start_ns, timestamp_ns)
            self.end_ns = max(self.end_ns, timestamp_ns)
        self.message_count += 1


def build_metadata(files: list[FileStats], topics: list[TopicStats], *,
                   storage_identifier: str = 'mcap', compression_format: str = '',
                   compression_mode: str = '',
                   custom_data: dict[str, str] | None = None) -> dict[str, Any]:
    """The ``rosbag2_bagfile_information`` mapping as rosbag2 (Jazzy) writes it."""
    counted = [f for f in files if f.message_count]
    start = min((f.start_ns for f in counted), default=0)
    end = max((f.end_ns for f in counted), default=0)
    return {'rosbag2_bagfile_information': {
        'version': 9,
        'storage_identifier': storage_identifier,
        'duration': {'nanoseconds': end - start},
        'starting_time': {'nanoseconds_since_epoch': start},
        'message_count': sum(f.message_count for f in files),
        'topics_with_message_count': [
            {'topic_metadata': {
                'name': t.name,
                'type': t.type,
                'serialization_format': t.serialization_format,
                'offered_qos_profiles': t.offered_qos_profiles,
                'type_description_hash': t.type_description_hash,
            }, 'message_count': t.message_count}
            for t in topics],
        'compression_format': compression_format,
        'compression_mode': compression_mode,
        'relative_file_paths': [f.path for f in files],
        'files': [
            {'path': f.path,
             'starting_time': {'nanoseconds_since_epoch': f.start_ns},
             'duration': {'nanoseconds': f.end_ns - f.start_ns},
             'message_count': f.message_count}
            for f in files],
        'custom_data': dict(custom_data) if custom_data else None,
        'ros_distro': ROS_DISTRO,
    }}


def dump_metadata(metadata: dict[str, Any]) -> str:
    """YAML text of a metadata mapping (block style, rosbag2's key order)."""
    return yaml.safe_dump(metadata, default_flow_style=False, sort_keys=False)


def write_metadata(bag_dir: Path, metadata: dict[str, Any]) -> Path:
    """Write ``metadata.yaml`` atomically (temporary file + rename), so it is never half written."""
    text = dump_metadata(metadata)
    return write_atomic(Path(bag_dir) / METADATA_FILE,
                        lambda tmp: tmp.write_text(text, encoding='utf-8'))


def load_metadata(bag_dir: Path) -> dict[str, Any]:
    """The ``rosbag2_bagfile_information`` mapping of a bag directory."""
    path = Path(bag_dir) / METADATA_FILE
    try:
        data = yaml.safe_load(path.read_text(encoding='utf-8'))
    except FileNotFoundError:
        msg = f'{path} does not exist; run `mindgrasp bag reindex {bag_dir}` to rebuild it.'
        raise BagError(msg) from None
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        where = getattr(exc, 'problem_mark', None)
        at = f' at line {where.line + 1}' if where is not None else ''
        msg = (f'{path} is corrupt (not valid YAML{at}); run `mindgrasp bag reindex {bag_dir}` '
               'to rebuild it from the .mcap files (the corrupt one is kept as '
               f'{METADATA_FILE}{DAMAGED_SUFFIX}).')
        raise BagError(msg) from None
    except OSError as exc:
        msg = f'Cannot read {path}: {exc.strerror}; check its permissions.'
        raise BagError(msg) from None
    info = data.get('rosbag2_bagfile_information') if isinstance(data, dict) else None
    if not isinstance(info, dict) or not isinstance(info.get('message_count', 0), int):
        msg = (f'{path} is corrupt (no valid rosbag2_bagfile_information section); run '
               f'`mindgrasp bag reindex {bag_dir}` to rebuild it from the .mcap files (the '
               f'corrupt one is kept as {METADATA_FILE}{DAMAGED_SUFFIX}).')
        raise BagError(msg)
    return info


def _split_index(path: Path) -> tuple[int, str]:
    match = re.search(r'_(\d+)\.mcap$', path.name)
    return (int(match.group(1)) if match else -1, path.name)


def mcap_files(bag_dir: Path) -> list[Path]:
    """The bag's .mcap files in split order (``<name>_0.mcap``, ``<name>_1.mcap``, ...)."""
    return sorted(Path(bag_dir).glob('*.mcap'), key=_split_index)


def rebuild_metadata(bag_dir: Path, *, write: bool = True) -> dict[str, Any]:
    """Rebuild ``metadata.yaml`` from the bag's MCAP files and (by default) write it.

    Raises:
        BagError: the directory holds no .mcap file.
    """
    bag_dir = Path(bag_dir)
    paths = mcap_files(bag_dir)
    if not paths:
        msg = (f'{bag_dir} holds no .mcap file, so its metadata cannot be rebuilt; '
               'pass the directory of a bag recorded with MCAP storage.')
        raise BagError(msg)
    topics: dict[str, TopicStats] = {}
    files: list[FileStats] = []
    compression = ''
    for path in paths:
        contents: McapContents = read_mcap_contents(path)
        files.append(FileStats(path.name, contents.start_ns, contents.end_ns,
                               contents.message_count))
        for channel in contents.channels.values():
            topic = topics.get(channel.topic)
            if topic is None:
                topic = topics[channel.topic] = TopicStats(
                    channel.topic, channel.schema_name,
                    parse_offered_qos(channel.metadata.get('offered_qos_profiles')),
                    channel.metadata.get('topic_type_hash', ''), channel.message_encoding)
            topic.message_count += contents.channel_counts.get(channel.id, 0)
        compression = compression or contents.compression
    _ = compression  # chunk compression is internal to MCAP: rosbag2 leaves the fields empty
    custom_data = None
    if (bag_dir / METADATA_FILE).exists():      # keep what the recording said about itself
        try:
            custom_data = load_metadata(bag_dir).get('custom_data') or None
        except BagError:
            custom_data = None
    metadata = build_metadata(files, list(topics.values()),
                              custom_data=custom_data if isinstance(custom_data, dict) else None)
    if write:
        write_metadata(bag_dir, metadata)
    return metadata
