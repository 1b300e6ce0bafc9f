"""Scene descriptions: which objects stand where (ROS-free).

A scene is a YAML file (``config/scenes/<name>.yaml``, or any path)::

    name: set_locations
    seed: 0
    defaults: {size: 0.05, density: 600.0, friction: 0.9, rolling_friction: 0.0003}
    objects:                          # fixed objects
      - {shape: cube, colour: red, radius: 0.5, angle_deg: 0}      # polar, around the base
      - {shape: sphere, colour: blue, position: [0.3, -0.2]}       # or cartesian x, y (m)
      - {shape: mesh, mesh: mug.obj, colour: red, scale: 1.0, position: [0.4, 0.1, 0.0]}
    random:                           # and/or a seeded random draw
      n_objects: 3
      shapes: [cube, cylinder, sphere]
      colours: [red, yellow, blue]
      radius: [0.2, 0.7]
      angle_deg: [-170, 170]
      size: [0.04, 0.06]
      min_separation: 0.15

Per object: ``shape`` (cube, cylinder, sphere or mesh), ``colour`` (red, yellow, blue, green,
white, or any name with ``rgba: [r, g, b, a]``), ``size`` (m: cube edge, cylinder diameter and
height, sphere diameter), ``mass`` (kg) or ``density`` (kg/m^3), ``yaw_deg``, ``friction``,
``rolling_friction``, ``spinning_friction``. Angles are counter-clockwise from the arm's forward
(+x) direction, in degrees.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from mindgrasp_common.cli_checks import yaml_error_text
from mindgrasp_common.resources import resource_path
from mindgrasp_sim.errors import SimError

SHAPES = ('cube', 'cylinder', 'sphere', 'mesh')
COLOURS: dict[str, tuple[float, float, float, float]] = {
    'red': (0.9, 0.05, 0.05, 1.0),
    'yellow': (0.95, 0.9, 0.05, 1.0),
    'blue': (0.05, 0.1, 0.95, 1.0),
    'green': (0.1, 0.8, 0.1, 1.0),
    'white': (0.95, 0.95, 0.95, 1.0),
}
_OBJECT_KEYS = {
    'shape', 'colour', 'color', 'rgba', 'size', 'mass', 'density', 'radius', 'angle_deg',
    'position', 'yaw_deg', 'friction', 'rolling_friction', 'spinning_friction', 'mesh', 'scale',
    'name',
}
_DEFAULTS = {
    'size': 0.05, 'density': 600.0, 'friction': 0.9, 'rolling_friction': 0.0003,
    'spinning_friction': 0.001,
}


def scenes_dir() -> Path:
    """The scenes shipped with this package (``config/scenes/*.yaml``)."""
    return resource_path('mindgrasp_sim', 'scenes')


@dataclass(frozen=True)
class ObjectSpec:
    """One object of a scene, as placed at reset.

    position: (x, y, z) of the object's centre (m, world frame); z is the resting height.
    """

    shape: str
    colour: str
    size: float
    mass: float
    position: tuple[float, float, float]
    yaw: float = 0.0
    rgba: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    friction: float = 0.9
    rolling_friction: float = 0.0003
    spinning_friction: float = 0.001
    mesh: str | None = None
    scale: float = 1.0
    name: str = ''

    @property
    def label(self) -> str:
        """``"<colour> <shape>"``, as in GraspResult."""
        return f'{self.colour} {self.shape}'


@dataclass
class SceneSpec:
    """A parsed scene file: fixed objects plus an optional random-draw recipe."""

    name: str
    seed: int = 0
    objects: list[ObjectSpec] = field(default_factory=list)
    random: dict[str, Any] | None = None
    defaults: dict[str, Any] = field(default_factory=dict)
    source: str = ''

    def draw(self, seed: int, n_objects: int | None = None) -> list[ObjectSpec]:
        """Objects of one layout: the fixed ones plus a seeded random draw (if the scene has one).

        Same seed, same layout. Raises SimError when the objects do not fit without overlaps.
        """
        objects = list(self.objects)
        if self.random is None:
            return objects
        return objects + _random_objects(self.random, self.defaults, seed, n_objects, objects,
                                         self.source)


def _num(entry: dict, key: str, where: str, default: Any = None, positive: bool = False) -> float:
    value = entry.get(key, default)
    try:
        value = float(value)
    except (TypeError, ValueError):
        msg = (f"{where}: field '{key}' must be a number, got {value!r}; "
               f'write it as e.g. {key}: {default if default is not None else 0.05}.')
        raise SimError(msg) from None
    if not math.isfinite(value) or (positive and value <= 0):
        msg = f"{where}: field '{key}' must be a finite{' positive' if positive else ''} number, " \
              f'got {value!r}; fix the scene file.'
        raise SimError(msg)
    return value


def _range(entry: dict, key: str, where: str, default: tuple[float, float]) -> tuple[float, float]:
    value = entry.get(key, default)
    if (not isinstance(value, (list, tuple)) or len(value) != 2
            or not all(isinstance(v, (int, float)) for v in value) or value[0] > value[1]):
        msg = (f"{where}: field '{key}' must be a range [low, high] with low <= high, got "
               f'{value!r}; write it as e.g. {key}: [{default[0]}, {default[1]}].')
        raise SimError(msg)
    return float(value[0]), float(value[1])


def _volume(shape: str, size: float) -> float:
    r = size / 2
    if shape == 'cube':
        return size ** 3
    if shape == 'cylinder':
        return math.pi * r * r * size
    return 4.0 / 3.0 * math.pi * r ** 3


def _colour(entry: dict, where: str) -> tuple[str, tuple[float, float, float, float]]:
    name = entry.get('colour', entry.get('color'))
    if name is None:
        msg = f"{where}: field 'colour' is missing; give one of {sorted(COLOURS)}."
        raise SimError(msg)
    name = str(name)
    if 'rgba' in entry:
        rgba = entry['rgba']
        if (not isinstance(rgba, (list, tuple)) or len(rgba) != 4
                or not all(isinstance(v, (int, float)) and 0 <= v <= 1 for v in rgba)):
            msg = f"{where}: field 'rgba' must be four numbers in [0, 1], got {rgba!r}."
            raise SimError(msg)
        return name, tuple(float(v) for v in rgba)  # type: ignore[return-value]
    if name not in COLOURS:
        msg = (f"{where}: field 'colour' is {name!r}, which is not one of {sorted(COLOURS)}; "
               "use one of those or add 'rgba: [r, g, b, a]'.")
        raise SimError(msg)
    return name, COLOURS[name]


def parse_object(entry: Any, defaults: dict, where: str, base_dir: Path | None = None
                 ) -> ObjectSpec:
    """Validate one ``objects:`` entry and return its :class:`ObjectSpec`."""
    if not isinstance(entry, dict):
        msg = f'{where}: an object must be a mapping like {{shape: cube, colour: red, ...}}, ' \
              f'got {entry!r}.'
        raise SimError(msg)
    unknown = set(entry) - _OBJECT_KEYS
    if unknown:
        msg = f'{where}: unknown field(s) {sorted(unknown)}; allowed are {sorted(_OBJECT_KEYS)}.'
        raise SimError(msg)
    merged = {**_DEFAULTS, **defaults, **entry}
    shape = merged.get('shape')
    if shape not in SHAPES:
        msg = f"{where}: field 'shape' is {shape!r}, which is not one of {list(SHAPES)}."
        raise SimError(msg)
    colour, rgba = _colour(merged, where)
    size = _num(merged, 'size', where, 0.05, positive=True)
    mesh = None
    if shape == 'mesh':
        if 'mesh' not in entry:
            msg = f"{where}: shape 'mesh' needs a field 'mesh' with the path of an .obj file."
            raise SimError(msg)
        mesh_path = Path(str(entry['mesh']))
        if not mesh_path.is_absolute() and base_dir is not None:
            mesh_path = base_dir / mesh_path
        if not mesh_path.is_file():
            msg = f"{where}: field 'mesh' names {str(mesh_path)!r}, which does not exist."
            raise SimError(msg)
        mesh = str(mesh_path)
    if 'mass' in entry:
        mass = _num(merged, 'mass', where, 0.1, positive=True)
    else:
        vol = _volume('sphere' if shape == 'mesh' else shape, size)
        mass = _num(merged, 'density', where, 600.0, positive=True) * vol
    if 'position' in entry:
        pos = entry['position']
        if (not isinstance(pos, (list, tuple)) or len(pos) not in (2, 3)
                or not all(isinstance(v, (int, float)) and math.isfinite(v) for v in pos)):
            msg = f"{where}: field 'position' must be [x, y] or [x, y, z] in metres, got {pos!r}."
            raise SimError(msg)
        x, y = float(pos[0]), float(pos[1])
        z = float(pos[2]) if len(pos) == 3 else size / 2
    elif 'radius' in entry or 'angle_deg' in entry:
        r = _num(merged, 'radius', where, 0.5, positive=True)
        a = math.radians(_num(merged, 'angle_deg', where, 0.0))
        x, y, z = r * math.cos(a), r * math.sin(a), size / 2
    else:
        msg = f"{where}: give the object's place as 'position: [x, y]' or as 'radius' and " \
              "'angle_deg'."
        raise SimError(msg)
    return ObjectSpec(
        shape=shape, colour=colour, size=size, mass=mass, position=(x, y, z),
        yaw=math.radians(_num(merged, 'yaw_deg', where, 0.0)), rgba=rgba,
        friction=_num(merged, 'friction', where, 0.9),
        rolling_friction=_num(merged, 'rolling_friction', where, 0.0003),
        spinning_friction=_num(merged, 'spinning_friction', where, 0.001),
        mesh=mesh, scale=_num(merged, 'scale', where, 1.0, positive=True),
        name=str(entry.get('name', '')),
    )


def _random_objects(recipe: dict, defaults: dict, seed: int, n_objects: int | None,
                    fixed: list[ObjectSpec], where: str) -> list[ObjectSpec]:
    rng = np.random.default_rng(seed)
    n = int(recipe.get('n_objects', 3) if n_objects is None else n_objects)
    if n < 0:
        msg = f'{where}: n_objects must be >= 0, got {n}.'
        raise SimError(msg)
    shapes = list(recipe.get('shapes', ['cube', 'cylinder', 'sphere']))
    colours = list(recipe.get('colours', ['red', 'yellow', 'blue']))
    r_lo, r_hi = _range(recipe, 'radius', f'{where}: random', (0.2, 0.7))
    a_lo, a_hi = _range(recipe, 'angle_deg', f'{where}: random', (-170.0, 170.0))
    s_lo, s_hi = _range(recipe, 'size', f'{where}: random', (0.04, 0.06))
    y_lo, y_hi = _range(recipe, 'yaw_deg', f'{where}: random', (-45.0, 45.0))
    sep = float(recipe.get('min_separation', 0.15))
    placed = [np.array(o.position[:2]) for o in fixed]
    out: list[ObjectSpec] = []
    for i in range(n):
        shape = shapes[i % len(shapes)]
        colour = colours[int(rng.integers(len(colours)))]
        size = float(rng.uniform(s_lo, s_hi))
        yaw = float(rng.uniform(y_lo, y_hi)) if shape != 'sphere' else 0.0
        for _ in range(1000):
            # uniform over the annulus area, not over the radius
            r = math.sqrt(rng.uniform(r_lo ** 2, r_hi ** 2))
            a = math.radians(rng.uniform(a_lo, a_hi))
            xy = np.array([r * math.cos(a), r * math.sin(a)])
            if all(np.linalg.norm(xy - p) >= sep for p in placed):
                break
        else:
            msg = (f'{where}: could not place {n} objects {sep} m apart within radius '
                   f'{r_lo}-{r_hi} m; lower n_objects or min_separation.')
            raise SimError(msg)
        placed.append(xy)
        entry = {'shape': shape, 'colour': colour, 'size': size,
                 'position': [float(xy[0]), float(xy[1])], 'yaw_deg': math.degrees(yaw)}
        out.append(parse_object(entry, defaults, f'{where}: random object {i}'))
    return out


def resolve_scene_path(scene: str | Path) -> Path:
    """A scene name (``set_locations``) or a path to a YAML file -> an existing path."""
    path = Path(scene)
    if path.suffix in ('.yaml', '.yml') or path.is_file():
        if not path.is_file():
            msg = f'Scene file {str(path)!r} does not exist; give an existing YAML path or one ' \
                  f'of the names in {scenes_dir()}.'
            raise SimError(msg)
        return path
    candidate = scenes_dir() / f'{scene}.yaml'
    if not candidate.is_file():
        known = sorted(p.stem for p in scenes_dir().glob('*.yaml'))
        msg = f'Unknown scene {str(scene)!r}; use one of {known} or a path to a scene YAML file.'
        raise SimError(msg)
    return candidate


def load_scene(scene: str | Path | dict) -> SceneSpec:
    """Read and validate a scene (name, path or an already loaded mapping)."""
    if isinstance(scene, dict):
        data, source, base = scene, '<dict>', None
    else:
        path = resolve_scene_path(scene)
        source, base = str(path), path.parent
        try:
            data = yaml.safe_load(path.read_text(encoding='utf-8'))
        except yaml.YAMLError as exc:
            msg = (f'Scene file {source!r} is not valid YAML ({yaml_error_text(exc)}); fix its '
                   'syntax.')
            raise SimError(msg) from None
    if not isinstance(data, dict):
        msg = f'Scene {source!r} must be a mapping with an objects: and/or random: section.'
        raise SimError(msg)
    unknown = set(data) - {'name', 'seed', 'defaults', 'objects', 'random'}
    if unknown:
        msg = f'Scene {source!r}: unknown top-level field(s) {sorted(unknown)}; allowed are ' \
              "name, seed, defaults, objects, random."
        raise SimError(msg)
    defaults = data.get('defaults') or {}
    if not isinstance(defaults, dict):
        msg = f"Scene {source!r}: field 'defaults' must be a mapping."
        raise SimError(msg)
    entries = data.get('objects') or []
    if not isinstance(entries, list):
        msg = f"Scene {source!r}: field 'objects' must be a list of objects."
        raise SimError(msg)
    objects = [parse_object(e, defaults, f'Scene {source!r}, objects[{i}]', base)
               for i, e in enumerate(entries)]
    random = data.get('random')
    if random is not None and not isinstance(random, dict):
        msg = f"Scene {source!r}: field 'random' must be a mapping (n_objects, radius, ...)."
        raise SimError(msg)
    if not objects and random is None:
        msg = f"Scene {source!r} has no objects; add an 'objects:' list or a 'random:' section."
        raise SimError(msg)
    seed = data.get('seed', 0)
    if not isinstance(seed, int):
        msg = f"Scene {source!r}: field 'seed' must be an integer, got {seed!r}."
        raise SimError(msg)
    return SceneSpec(name=str(data.get('name', Path(source).stem)), seed=seed, objects=objects,
                     random=random, defaults=defaults, source=source)


__all__ = ['COLOURS', 'SHAPES', 'ObjectSpec', 'SceneSpec', 'load_scene',
           'parse_object', 'resolve_scene_path', 'scenes_dir']
