"""Every node's parameters: declared once from a dataclass (descriptors with descriptions, units,
ranges), one ROS parameter file per node that agrees with the defaults, live changes applied or
refused with the reason. Parametrised over the nodes, as tests/fsm/test_params.py does for the
controller's own checks."""

from __future__ import annotations

import dataclasses
import sys

import pytest
import yaml

from mindgrasp_common.resources import resource_path
from mindgrasp_ros.params import _flat_fields, _info, describe

#: node name, parameter dataclass (module, class), parameter file (package, file)
NODES = [
    ('fsm', 'mindgrasp_fsm.params', 'FsmParams', 'mindgrasp_fsm', 'fsm.yaml'),
    ('vision', 'mindgrasp_vision.params', 'VisionConfig', 'mindgrasp_vision', 'vision.yaml'),
    ('classifier', 'mindgrasp_classifier.params', 'ClassifierParams',
     'mindgrasp_classifier', 'classifier.yaml'),
    ('sim', 'mindgrasp_sim.params', 'SimParams', 'mindgrasp_sim', 'sim.yaml'),
    ('graz_prompter', 'mindgrasp_trainer.graz_node', 'GrazParams', 'mindgrasp_trainer',
     'trainer.yaml'),
    ('trainer', 'mindgrasp_trainer.trainer_node', 'TrainerParams', 'mindgrasp_trainer',
     'trainer.yaml'),
    ('eeg_acquisition', 'mindgrasp_eeg.params', 'AcquisitionParams', 'mindgrasp_eeg', 'eeg.yaml'),
    ('virtual_amp', 'mindgrasp_eeg.params', 'VirtualAmpParams', 'mindgrasp_eeg', 'eeg.yaml'),
    ('lsl_markers', 'mindgrasp_eeg.params', 'MarkerParams', 'mindgrasp_eeg', 'eeg.yaml'),
]
IDS = [n[0] for n in NODES]


def _cls(module: str, name: str) -> type:
    import importlib

    return getattr(importlib.import_module(module), name)


@pytest.mark.parametrize(('node', 'module', 'cls_name', 'package', 'file'), NODES, ids=IDS)
def test_parameter_file_agrees_with_the_defaults(node, module, cls_name, package, file):
    cls = _cls(module, cls_name)
    data = yaml.safe_load(resource_path(package, 'param', file).read_text())
    section = data[node]['ros__parameters']
    flat: dict[str, object] = {}
    for key, value in section.items():   # nested dicts are dotted names, as ROS reads them
        if isinstance(value, dict):
            flat.update({f'{key}.{k}': v for k, v in value.items()})
        else:
            flat[key] = value
    defaults = {name: value for _, name, value in _flat_fields(cls, cls())}
    # parameters a description sets (the controller's robot parameters) stay out of the file
    described = set(getattr(sys.modules[cls.__module__], 'ROBOT_PARAMETERS', ()))
    assert set(flat) == set(defaults) - described, sorted((set(defaults) - described) ^ set(flat))
    for name, value in flat.items():
        assert value == pytest.approx(defaults[name]), (name, value, defaults[name])


@pytest.mark.parametrize(('node', 'module', 'cls_name', 'package', 'file'), NODES, ids=IDS)
def test_every_parameter_has_a_description_and_numbers_a_range(node, module, cls_name, package,
                                                               file):
    cls = _cls(module, cls_name)
    for field in dataclasses.fields(cls):
        info = _info(field)
        assert info.description, f'{node}: {field.name} has no description'
        default = getattr(cls(), field.name)
        if isinstance(default, (int, float)) and not isinstance(default, bool):
            assert info.min is not None or info.max is not None, f'{node}: {field.name} range'
    for name, (_default, desc) in describe(cls).items():
        assert desc.name == name and desc.type != 0


def test_vision_live_change_rebuilds_the_pipeline_or_is_refused(rclpy_ctx):
    from mindgrasp_vision.vision_node import VisionNode

    param = rclpy_ctx.parameter.Parameter
    node = VisionNode()
    try:
        ok = node.set_parameters([param('hysteresis', value=0.3)])[0]
        assert ok.successful and node.pipeline.ranker.hysteresis == pytest.approx(0.3)
        assert node.params.hysteresis == pytest.approx(0.3)
        bad = node.set_parameters([param('colour_ranges.red', value=[170, 8, 120])])[0]
        assert not bad.successful and 'needs 4 numbers' in bad.reason, bad.reason
        assert node.params.colour_ranges['red'] == [170, 8, 120, 40]
        fixed = node.set_parameters([param('shape_model', value='none')])[0]
        assert not fixed.successful and 'read-only' in fixed.reason
        out = node.set_parameters([param('min_pixels', value=0)])[0]
        assert not out.successful and 'within [1, 100000]' in out.reason, out.reason
    finally:
        node.destroy_node()


def test_describe_works_with_an_enum_parameter_type_as_real_rclpy_has(monkeypatch):
    """Real rclpy's ``Parameter.Type`` is a plain ``Enum`` (``int()`` of a member raises
    ``TypeError``); the descriptors must carry the ``ParameterType`` numbers all the same."""
    import enum

    from mindgrasp_ros.runtime.parameter import Parameter

    # rclpy/parameter.py: ``class Type(Enum)``, values ParameterType.*; same members as ours
    RclpyType = enum.Enum('Type', {m.name: m.value for m in Parameter.Type})  # noqa: N806

    with pytest.raises(TypeError):
        int(RclpyType.BOOL)   # the failure the old code hit under real rclpy
    monkeypatch.setattr(Parameter, 'Type', RclpyType)
    specs = describe(_cls('mindgrasp_fsm.params', 'FsmParams'))
    expected = {bool: 1, int: 2, float: 3, str: 4}
    for name, (default, desc) in specs.items():
        assert isinstance(desc.type, int) and not isinstance(desc.type, enum.Enum), name
        if type(default) in expected:
            assert desc.type == expected[type(default)], name
    ranged = [d for _, d in specs.values() if d.type == 3 and len(d.floating_point_range)]
    assert ranged, 'a DOUBLE with a range keeps its FloatingPointRange under an Enum Type'


def test_every_node_reads_its_parameters_one_way():
    """Issue 29: each node keeps what ``declare_params`` returns as ``self.params`` (typed
    attributes), never as a dict or under another name (``self.p``, ``self.cfg``, ``vars(...)``)."""
    import re
    from pathlib import Path

    src = Path(__file__).resolve().parents[2] / 'src'
    calls = [(path, line.strip()) for path in sorted(src.rglob('*.py'))
             for line in path.read_text(encoding='utf-8').splitlines()
             if re.search(r'declare_params\(self\b', line)]
    assert len(calls) >= 15, 'the rule found too few nodes to mean anything'
    other = [f'{path.relative_to(src)}: {line}' for path, line in calls
             if not re.match(r'self\.params(\s*=\s*p)?\s*=\s*declare_params\(self\b', line)]
    assert not other, '\n'.join(other)
