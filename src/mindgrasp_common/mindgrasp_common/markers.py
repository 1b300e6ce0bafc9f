"""``/sim/objects`` (``visualization_msgs/MarkerArray``) read back into :class:`SceneObject`.

The simulator publishes one marker per object (``mindgrasp_sim.messages.object_markers``): id, the
shape as marker type, pose, size as scale, colour, and the label ``"<colour> <shape>"`` as text.
This is the one reader of that topic, for every subscriber (virtual subject, trial manager).
Duck-typed on attributes: no ROS import, any message class works.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from mindgrasp_common.types import SceneObject

__all__ = ['COLOURS', 'SHAPES', 'objects_from_markers']

#: the task's object colours and their nominal RGB (0..1)
COLOURS: dict[str, tuple[float, float, float]] = {
    'red': (1.0, 0.0, 0.0), 'yellow': (1.0, 1.0, 0.0), 'blue': (0.0, 0.0, 1.0)}
#: the task's object shapes
SHAPES: tuple[str, ...] = ('cube', 'cylinder', 'sphere')
# visualization_msgs/Marker constants
_SHAPE_OF_TYPE = {1: 'cube', 2: 'sphere', 3: 'cylinder'}
_DELETE, _DELETEALL, _TEXT_VIEW_FACING = 2, 3, 9


def objects_from_markers(markers: Iterable[object], origin: Sequence[float] = (0.0, 0.0, 0.0)
                         ) -> list[SceneObject]:
    """``MarkerArray.markers`` -> scene objects, sorted by id.

    Colour from the marker text or namespace (``red``/``yellow``/``blue``), else the nearest of
    those to the marker colour; shape from the text or namespace (``cube``/``cylinder``/
    ``sphere``), else from the marker type. Text-only and delete markers are skipped.

    Parameters
    ----------
    markers : iterable of visualization_msgs/Marker
    origin : sequence of 2 or 3 float
        Position (m, marker frame) subtracted from each marker's: the arm base position gives
        objects in the base frame (axes parallel to the marker frame).
    """
    offset = np.zeros(3)
    offset[:len(origin)] = np.asarray(origin, dtype=float)
    out = []
    for m in markers:
        if m.action in (_DELETE, _DELETEALL) or m.type == _TEXT_VIEW_FACING:
            continue
        words = f'{m.text} {m.ns}'.lower().replace('_', ' ').replace('/', ' ').split()
        colour = next((w for w in words if w in COLOURS), '')
        if not colour:
            rgb = np.array([m.color.r, m.color.g, m.color.b])
            colour = min(COLOURS, key=lambda c: float(np.sum((rgb - COLOURS[c]) ** 2)))
        shape = next((w for w in words if w in SHAPES),
                     _SHAPE_OF_TYPE.get(int(m.type), 'unknown'))
        p, o = m.pose.position, m.pose.orientation
        out.append(SceneObject(
            object_id=int(m.id), colour=colour, shape=shape,
            position=np.array([p.x, p.y, p.z], dtype=float) - offset,
            orientation=np.array([o.x, o.y, o.z, o.w], dtype=float), size=float(m.scale.x),
            rgba=(float(m.color.r), float(m.color.g), float(m.color.b), float(m.color.a))))
    return sorted(out, key=lambda obj: obj.object_id)
