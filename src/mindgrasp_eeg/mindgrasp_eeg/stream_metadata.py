"""The amplifier's metadata as the acquisition node found it, kept in the run directory (ROS-free).

The acquisition node writes ``<run_dir>/eeg_stream.json`` once it is connected (in a launch,
``$MINDGRASP_RUN_DIR``), so exports know the amplifier without the stream: ``mindgrasp export
bids`` takes ``eeg.json``'s ``Manufacturer``, ``ManufacturersModelName`` and ``EEGReference`` from
it (its options override), and the channel types of ``channels.tsv``. The file::

    {"name": ..., "type": "EEG", "source_id": ..., "hostname": ..., "sample_rate": 250.0,
     "manufacturer": "g.tec", "model": "g.Nautilus", "reference": "right earlobe",
     "unit": "microvolts",
     "channels": [{"label": "Fp1", "unit": "microvolts", "type": "EEG"}, ...]}

Empty strings where the stream declares nothing (a stream without metadata).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from mindgrasp_common.safe_files import write_atomic

from .lsl import StreamDescription

__all__ = ['FILE_NAME', 'read_stream_metadata', 'stream_metadata', 'write_stream_metadata']

FILE_NAME = 'eeg_stream.json'


def stream_metadata(desc: StreamDescription) -> dict[str, Any]:
    """The JSON object of ``desc`` (see the module docstring)."""
    n = len(desc.channel_names)
    units = desc.channel_units or ('',) * n
    types = desc.channel_types or ('',) * n
    return {'name': desc.name, 'type': desc.type, 'source_id': desc.source_id,
            'hostname': desc.hostname, 'sample_rate': desc.sample_rate,
            'manufacturer': desc.manufacturer, 'model': desc.model,
            'reference': desc.reference, 'unit': desc.unit,
            'channels': [{'label': label, 'unit': unit, 'type': kind}
                         for label, unit, kind in zip(desc.channel_names, units, types,
                                                      strict=True)]}


def write_stream_metadata(desc: StreamDescription, run_dir: str | Path) -> Path:
    """Write ``<run_dir>/eeg_stream.json`` (atomically: whole or absent); returns its path.

    Raises
    ------
    OSError
        The disk refused it (the caller keeps it, see
        :class:`mindgrasp_common.safe_files.DeferredWriter`).
    """
    text = json.dumps(stream_metadata(desc), indent=1) + '\n'
    return write_atomic(Path(run_dir) / FILE_NAME,
                        lambda tmp: tmp.write_text(text, encoding='utf-8'))


def read_stream_metadata(run_dir: str | Path) -> dict[str, Any]:
    """The run's ``eeg_stream.json``, or ``{}`` when the run has none (a lock-step run, a run
    recorded before the node kept it) or it is unreadable: exports then use their options."""
    path = Path(run_dir) / FILE_NAME
    try:
        data = json.loads(path.read_text(encoding='utf-8'))
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}
