"""Scene files: the shipped scenes, the format, and errors that name the field and the fix."""

from __future__ import annotations

import math

import pytest
import yaml

from mindgrasp_sim.errors import SimError
from mindgrasp_sim.scene import load_scene, resolve_scene_path


def test_shipped_scenes_load():
    spec = load_scene('set_locations')
    assert spec.name == 'set_locations' and len(spec.objects) == 9 and spec.random is None
    assert {o.label for o in spec.objects} == {
        f'{c} {s}' for c in ('red', 'yellow', 'blue') for s in ('cube', 'cylinder', 'sphere')}
    cube = spec.objects[0]
    assert cube.mass == pytest.approx(600.0 * 0.05 ** 3)           # density x volume
    assert cube.position[2] == pytest.approx(0.025)                # resting on the ground
    spec = load_scene('random_locations')
    assert spec.random is not None and spec.objects == []
    assert spec.draw(3) == spec.draw(3) and spec.draw(3) != spec.draw(4)


def test_cartesian_polar_mass_and_rgba(tmp_path):
    scene = {'name': 'mine', 'objects': [
        {'shape': 'cube', 'colour': 'red', 'position': [0.3, -0.2], 'mass': 0.2, 'yaw_deg': 30},
        {'shape': 'sphere', 'colour': 'purple', 'rgba': [0.5, 0, 0.5, 1], 'radius': 0.4,
         'angle_deg': 90, 'size': 0.04},
    ]}
    path = tmp_path / 'mine.yaml'
    path.write_text(yaml.safe_dump(scene))
    spec = load_scene(path)
    a, b = spec.objects
    assert a.position == (0.3, -0.2, 0.025) and a.mass == 0.2
    assert a.yaw == pytest.approx(math.radians(30))
    assert b.colour == 'purple' and b.rgba == (0.5, 0.0, 0.5, 1.0)
    assert b.position[0] == pytest.approx(0.0, abs=1e-12) and b.position[1] == pytest.approx(0.4)


@pytest.mark.parametrize(('entry', 'message'), [
    ({'shape': 'pyramid', 'colour': 'red', 'position': [0.3, 0]},
     r"objects\[0\]: field 'shape' is 'pyramid', which is not one of"),
    ({'shape': 'cube', 'position': [0.3, 0]}, r"objects\[0\]: field 'colour' is missing"),
    ({'shape': 'cube', 'colour': 'teal', 'position': [0.3, 0]},
     r"field 'colour' is 'teal'.*add 'rgba: \[r, g, b, a\]'"),
    ({'shape': 'cube', 'colour': 'red', 'position': [0.3]},
     r"field 'position' must be \[x, y\] or \[x, y, z\] in metres"),
    ({'shape': 'cube', 'colour': 'red'}, r"give the object's place as 'position: \[x, y\]'"),
    ({'shape': 'cube', 'colour': 'red', 'position': [0.3, 0], 'size': -0.05},
     r"field 'size' must be a finite positive number"),
    ({'shape': 'cube', 'colour': 'red', 'position': [0.3, 0], 'mass': 'heavy'},
     r"field 'mass' must be a number, got 'heavy'"),
    ({'shape': 'cube', 'colour': 'red', 'position': [0.3, 0], 'colur': 'red'},
     r"unknown field\(s\) \['colur'\]"),
    ({'shape': 'mesh', 'colour': 'red', 'position': [0.3, 0]},
     r"shape 'mesh' needs a field 'mesh'"),
    ({'shape': 'mesh', 'mesh': 'nowhere.obj', 'colour': 'red', 'position': [0.3, 0]},
     r"field 'mesh' names .*nowhere.obj', which does not exist"),
])
def test_malformed_entries_name_the_field(tmp_path, entry, message):
    path = tmp_path / 'bad.yaml'
    path.write_text(yaml.safe_dump({'objects': [entry]}))
    with pytest.raises(SimError, match=message):
        load_scene(path)


def test_file_level_errors(tmp_path):
    with pytest.raises(SimError, match=r"Unknown scene 'kitchen'; use one of \['random_locations'"):
        resolve_scene_path('kitchen')
    with pytest.raises(SimError, match='does not exist; give an existing YAML path'):
        load_scene(tmp_path / 'missing.yaml')
    bad = tmp_path / 'bad.yaml'
    bad.write_text('objects: [ {shape: cube')
    with pytest.raises(SimError, match='is not valid YAML'):
        load_scene(bad)
    bad.write_text(yaml.safe_dump({'objects': [], 'lights': 1}))
    with pytest.raises(SimError, match=r"unknown top-level field\(s\) \['lights'\]"):
        load_scene(bad)
    bad.write_text(yaml.safe_dump({'name': 'empty'}))
    with pytest.raises(SimError, match='has no objects'):
        load_scene(bad)
    bad.write_text(yaml.safe_dump({'random': {'radius': [0.7, 0.2]}}))
    with pytest.raises(SimError, match=r"field 'radius' must be a range \[low, high\]"):
        load_scene(bad).draw(0)
    bad.write_text(yaml.safe_dump({'random': {'n_objects': 40, 'radius': [0.2, 0.3]}}))
    with pytest.raises(SimError, match=r'could not place 40 objects 0\.15 m apart'):
        load_scene(bad).draw(0)


def test_mesh_objects_are_simulated(tmp_path):
    from mindgrasp_sim.simulation import Simulation

    # a 4 cm cube as an OBJ mesh, 1 cm above the ground: it falls and rests
    h = 0.02
    verts = [(x, y, z) for x in (-h, h) for y in (-h, h) for z in (-h, h)]
    faces = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]
    obj = tmp_path / 'box.obj'
    obj.write_text(''.join(f'v {x} {y} {z}\n' for x, y, z in verts)
                   + ''.join('f ' + ' '.join(map(str, f)) + '\n' for f in faces))
    scene = {'objects': [{'shape': 'mesh', 'mesh': 'box.obj', 'colour': 'red', 'size': 0.04,
                          'position': [0.5, 0.0, 0.03]}]}
    path = tmp_path / 'mesh.yaml'
    path.write_text(yaml.safe_dump(scene))
    with Simulation(path) as sim:
        sim.step(240)
        (o,) = sim.objects()
        assert o.shape == 'mesh' and o.position[2] == pytest.approx(0.02, abs=0.003)
