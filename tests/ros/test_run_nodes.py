"""A run's nodes are known by their classes' traits (issue 29): the BIDS task and the latency
report's nominal rates come from what the node classes in launch.yaml declare, not from node
names, so a renamed node still gives its run's task and rates."""

from __future__ import annotations

from pathlib import Path

import yaml


def _run(tmp_path: Path, processes: list[dict], params: dict[str, dict]) -> Path:
    (tmp_path / 'params').mkdir(parents=True)
    (tmp_path / 'launch.yaml').write_text(yaml.safe_dump(
        {'profile': 'custom', 'processes': processes}), encoding='utf-8')
    for label, values in params.items():
        (tmp_path / 'params' / f'{label}.yaml').write_text(yaml.safe_dump(
            {'/**': {'ros__parameters': values}}), encoding='utf-8')
    (tmp_path / 'params.yaml').write_text(yaml.safe_dump(
        {f'/{label}': {'ros__parameters': v} for label, v in params.items()}), encoding='utf-8')
    return tmp_path


def test_the_task_is_the_parameter_the_node_class_names(tmp_path: Path) -> None:
    from mindgrasp_eeg.bids import _protocol
    from mindgrasp_ros.run_nodes import run_nodes

    # renamed nodes: only their classes say which is the trial manager and which prompts
    run = _run(tmp_path / 'a', [
        {'label': 'manager_2', 'node': '/manager_2',
         'module': 'mindgrasp_experiments.trial_manager_node'},
        {'label': 'cues', 'node': '/cues', 'module': 'mindgrasp_trainer.graz_node'},
        {'label': 'gone', 'node': '/gone', 'module': 'mindgrasp_no_such.node'}],
        {'manager_2': {'protocol': 'random_locations'}, 'cues': {'trials': 4}})
    assert [(n.label, n.traits.task_parameter, n.traits.prompts) for n in run_nodes(run)] == [
        ('manager_2', 'protocol', ('test',)), ('cues', '', ('graz',)), ('gone', '', ())]
    assert _protocol(run) == 'random_locations'
    graz = _run(tmp_path / 'b', [{'label': 'cues', 'node': '/cues',
                                  'module': 'mindgrasp_trainer.graz_node'}], {'cues': {}})
    assert _protocol(graz) == 'graz'
    assert _protocol(_run(tmp_path / 'c', [], {})) == 'custom'       # the launch profile


def test_nominal_rates_come_from_the_parameters_the_classes_name(tmp_path: Path) -> None:
    from mindgrasp_bag.run_stamps import _nominal_periods

    run = _run(tmp_path, [
        {'label': 'controller', 'node': '/controller', 'module': 'mindgrasp_fsm.fsm_node'},
        {'label': 'amp_in', 'node': '/amp_in', 'module': 'mindgrasp_eeg.acquisition_node'},
        {'label': 'world', 'node': '/world', 'module': 'mindgrasp_sim.sim_node'}],
        {'controller': {'control_period': 0.05}, 'amp_in': {'chunk_period': 0.25},
         'world': {'joint_state_rate': 50.0, 'camera_rate': 0.0}})
    (run / 'bag').mkdir()
    assert _nominal_periods(run / 'bag') == {'/arm_controller/commands': 0.05,
                                             '/eeg/raw': 0.25, '/joint_states': 0.02}
