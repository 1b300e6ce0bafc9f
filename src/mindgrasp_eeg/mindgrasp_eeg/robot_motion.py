"""The robot's joint states and end-effector pose of a recorded run, as one table (ROS-free).

:mod:`.bids` writes this table as BIDS motion data (``tracksys-robot``; mne-bids does not write
motion data) in the derivatives dataset ``derivatives/mindgrasp``.
Rows are the ``/joint_states`` messages; each row carries the latest ``/ee_pose`` at or before it.

Columns: ``onset`` (s from the first EEG sample, from the header stamps), ``<joint>_position``
(rad, or m for prismatic joints), ``<joint>_velocity`` (rad/s), ``ee_x/ee_y/ee_z`` (m, in the
pose's frame), ``ee_qx/ee_qy/ee_qz/ee_qw`` (unit quaternion).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mindgrasp_ros.topics import EE_POSE, JOINT_STATES

__all__ = ['EE_COLUMNS', 'read_robot_motion']

EE_COLUMNS = ('ee_x', 'ee_y', 'ee_z', 'ee_qx', 'ee_qy', 'ee_qz', 'ee_qw')


def _stamp_ns(header: object) -> int:
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def read_robot_motion(bag: Path, start_ns: int) -> tuple[list[str], np.ndarray] | None:
    """``(columns, rows)`` of the bag's robot motion, or None when it has no joint states.

    Args:
        bag: a rosbag2 folder.
        start_ns: ROS time of the first EEG sample (ns): onset 0.

    Returns:
        column names and an array of shape (n_messages, n_columns); NaN where a value is
        missing (no pose yet, a joint missing from a message).
    """
    from mindgrasp_bag.reader import BagReader
    from mindgrasp_ros.typesupport import typestore

    store = typestore()
    joints: list[str] = []
    rows: list[tuple[int, dict[str, float], tuple[float, ...]]] = []
    pose: tuple[float, ...] = (np.nan,) * len(EE_COLUMNS)
    with BagReader(bag) as reader:     # a damaged chunk costs only its own messages
        topics = {JOINT_STATES.name, EE_POSE.name} & set(reader.topics)
        if JOINT_STATES.name not in topics:
            return None
        for topic, _, raw in reader.messages(topics):
            msg = store.deserialize_cdr(raw, reader.topics[topic].type)
            if topic == EE_POSE.name:
                p, q = msg.pose.position, msg.pose.orientation
                pose = (p.x, p.y, p.z, q.x, q.y, q.z, q.w)
                continue
            values: dict[str, float] = {}
            for i, name in enumerate(msg.name):
                if name not in joints:
                    joints.append(name)
                values[f'{name}_position'] = float(msg.position[i]) if len(msg.position) > i \
                    else np.nan
                values[f'{name}_velocity'] = float(msg.velocity[i]) if len(msg.velocity) > i \
                    else np.nan
            rows.append((_stamp_ns(msg.header), values, pose))
    if not rows:
        return None
    columns = ['onset', *[f'{j}_{k}' for j in joints for k in ('position', 'velocity')],
               *EE_COLUMNS]
    table = np.full((len(rows), len(columns)), np.nan)
    for r, (stamp, values, ee) in enumerate(rows):
        table[r, 0] = (stamp - start_ns) * 1e-9
        for c, name in enumerate(columns[1:-len(EE_COLUMNS)], start=1):
            table[r, c] = values.get(name, np.nan)
        table[r, -len(EE_COLUMNS):] = ee
    return columns, table
