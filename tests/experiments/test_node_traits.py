"""Node traits are declared on the node classes, and what they name exists."""

from __future__ import annotations

import dataclasses
import re

import pytest

from mindgrasp_bag.recorder_node import RecorderNode, RecorderParams
from mindgrasp_eeg.acquisition_node import AcquisitionNode
from mindgrasp_eeg.virtual_amp_node import VirtualAmpNode, VirtualAmpParams
from mindgrasp_experiments.oracle_subject_node import OracleParams, OracleSubjectNode
from mindgrasp_experiments.trial_manager_node import TrialManagerNode
from mindgrasp_launch import LaunchError, lockstep
from mindgrasp_launch.lockstep import check_left_out_nodes, node_traits
from mindgrasp_ros.node_traits import NodeTraits, traits_of
from mindgrasp_sim.params import SimParams
from mindgrasp_sim.sim_node import SimNode

SEEDED = [(VirtualAmpNode, VirtualAmpParams), (OracleSubjectNode, OracleParams),
          (SimNode, SimParams)]


@pytest.mark.parametrize(('node', 'params'), SEEDED, ids=lambda c: c.__name__)
def test_seeded_and_lockstep_parameters_are_parameters_of_the_node(node, params) -> None:
    traits = traits_of(node)
    names = {f.name for f in dataclasses.fields(params)}
    assert traits.seed_parameters and set(traits.seed_parameters) <= names
    assert set(traits.lockstep_parameters) <= names


def test_roles_come_from_the_classes() -> None:
    assert traits_of(TrialManagerNode).trial_manager
    assert not traits_of(SimNode).trial_manager
    acquisition = traits_of(AcquisitionNode)
    assert acquisition.lockstep_left_out and acquisition.provides == ('eeg',)
    assert traits_of(VirtualAmpNode).provides == ('eeg',)
    assert traits_of(object) == NodeTraits()           # a class without traits: the defaults


def test_the_recorder_declares_what_lockstep_sets_on_it() -> None:
    """Its /clock exclusion and bag directory come from its class, not from its module name."""
    traits = traits_of(RecorderNode)
    names = {f.name for f in dataclasses.fields(RecorderParams)}
    assert traits.lockstep_exclude_parameter == 'exclude_regex'
    assert traits.lockstep_output_parameter == 'output'
    assert {traits.lockstep_exclude_parameter, traits.lockstep_output_parameter} <= names


def test_lockstep_components_load_each_node_class_once(tmp_path, monkeypatch) -> None:
    asked: list[str] = []

    def counting(spec):
        asked.append(spec.label)
        return node_traits(spec)

    monkeypatch.setattr(lockstep, 'node_traits', counting)
    comps = lockstep.lockstep_components('experiment', {'subject': 'oracle', 'seed': '0'},
                                         tmp_path / 'params', log=lambda _text: None)
    assert comps and sorted(asked) == sorted(set(asked)), asked


def test_a_node_left_out_without_a_stand_in_is_refused() -> None:
    @dataclasses.dataclass
    class Spec:
        label: str
        module: str | None

    acquisition = Spec('eeg_acquisition', 'mindgrasp_eeg.acquisition_node')
    amp = Spec('virtual_amp', 'mindgrasp_eeg.virtual_amp_node')
    driver = Spec('arm_driver', None)                  # not a Python node: default traits
    check_left_out_nodes([acquisition, amp, driver])
    with pytest.raises(LaunchError, match='lock-step cannot take EEG from an LSL stream'):
        check_left_out_nodes([acquisition, driver])
    with pytest.raises(LaunchError, match=re.escape(
            "'mine' cannot be composed: Cannot import node module 'no_such_pkg.node'")):
        node_traits(Spec('mine', 'no_such_pkg.node'))


def test_traits_of_the_wrong_type_are_refused() -> None:
    class Bad:
        node_traits = {'seed_parameters': ('seed',)}

    with pytest.raises(TypeError, match=r'Bad.node_traits must be a NodeTraits, not dict'):
        traits_of(Bad)
