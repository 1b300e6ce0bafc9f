"""Launch descriptions resolved in-process: substitutions, conditions, includes, namespaces,
parameters, arguments and their errors (no process is started)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
import yaml

from mindgrasp_launch import (
    DeclareLaunchArgument,
    EnvironmentVariable,
    ExecuteProcess,
    GroupAction,
    IfCondition,
    IncludeLaunchDescription,
    LaunchConfiguration,
    LaunchConfigurationEquals,
    LaunchDescription,
    LaunchError,
    LaunchService,
    Node,
    PathJoinSubstitution,
    PushRosNamespace,
    PythonExpression,
    SetLaunchConfiguration,
    ThisLaunchFileDir,
    UnlessCondition,
    profiles,
)
from mindgrasp_launch import params as ros_params
from mindgrasp_launch.commands import launch as launch_cmd
from mindgrasp_launch.service import format_arguments, parse_launch_arguments

HERE = Path(__file__).resolve().parent
FIXTURES = HERE / 'launch_fixtures'


@pytest.fixture(autouse=True)
def _fixtures_importable(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(HERE))


def ticker(name: str, **kwargs: object) -> Node:
    return Node(package='launch_fixtures', executable='ticker', name=name, **kwargs)


def plan(description: LaunchDescription, *args: str, record: bool = False):
    given = list(args) + ([] if record else ['record:=false'])
    return LaunchService(description, given).plan()


def test_node_command_line_is_that_of_ros2_launch() -> None:
    p = plan(LaunchDescription([
        ticker('talker', namespace='robot', arguments=['--count', '2'],
               remappings=[('/chatter', '/robot/chatter')], ros_arguments=['--log-level', 'warn'],
               parameters=[{'rate': 5}]),
    ]))
    (spec,) = p.processes
    cmd = spec.command('/tmp/p.yaml')
    # python -m MODULE through mindgrasp_ros.start (a Ctrl-C while it imports is a clean stop)
    assert cmd[:4] == [sys.executable, '-m', 'mindgrasp_ros.start', 'launch_fixtures.ticker']
    assert cmd[4:] == ['--count', '2', '--ros-args', '-r', '__node:=talker', '-r',
                       '__ns:=/robot', '--params-file', '/tmp/p.yaml', '--log-level', 'warn',
                       '-r', '/chatter:=/robot/chatter']
    assert spec.fully_qualified_name == '/robot/talker'


def test_launch_arguments_defaults_overrides_and_substitutions(monkeypatch) -> None:
    monkeypatch.setenv('MG_TEST_VAR', 'from-env')
    description = LaunchDescription([
        DeclareLaunchArgument('count', default_value='3'),
        DeclareLaunchArgument('tag', default_value=['pre-', LaunchConfiguration('count')]),
        ticker('a', arguments=['--count', LaunchConfiguration('count'),
                               '--label', LaunchConfiguration('tag'),
                               EnvironmentVariable('MG_TEST_VAR'),
                               PythonExpression([LaunchConfiguration('count'), ' * 2']),
                               PathJoinSubstitution(['/x', LaunchConfiguration('count'), 'y'])]),
    ])
    (spec,) = plan(description).processes
    assert spec.arguments == ['--count', '3', '--label', 'pre-3', 'from-env', '6', '/x/3/y']
    (spec,) = plan(description, 'count:=7').processes
    assert spec.arguments[:4] == ['--count', '7', '--label', 'pre-7']
    (spec,) = plan(description, 'count:=7', 'tag:=mine').processes
    assert spec.arguments[3] == 'mine'


def test_conditions_select_nodes() -> None:
    description = LaunchDescription([
        DeclareLaunchArgument('sim', default_value='true', choices=['true', 'false']),
        DeclareLaunchArgument('driver', default_value='none'),
        ticker('sim', condition=IfCondition(LaunchConfiguration('sim'))),
        ticker('driver', condition=UnlessCondition(LaunchConfiguration('sim'))),
        ticker('special', condition=LaunchConfigurationEquals('driver', 'ur5')),
    ])
    assert [p.label for p in plan(description).processes] == ['sim']
    assert [p.label for p in plan(description, 'sim:=false').processes] == ['driver']
    assert [p.label for p in plan(description, 'driver:=ur5').processes] == ['sim', 'special']
    with pytest.raises(LaunchError, match=r"'sim' got 'maybe'.*choices: true, false"):
        plan(description, 'sim:=maybe')
    bad = LaunchDescription([ticker('x', condition=IfCondition('perhaps'))])
    with pytest.raises(LaunchError, match="IfCondition expects true or false, got 'perhaps'"):
        plan(bad)


def test_group_scopes_namespace_and_configurations() -> None:
    description = LaunchDescription([
        DeclareLaunchArgument('robot', default_value='arm1'),
        GroupAction([
            PushRosNamespace(LaunchConfiguration('robot')),
            SetLaunchConfiguration('robot', 'changed-inside'),
            ticker('driver'),
            ticker('absolute', namespace='/elsewhere'),
            ticker('relative', namespace='sub'),
        ]),
        ticker('outside', arguments=[LaunchConfiguration('robot')]),
        GroupAction([ticker('skipped')], condition=IfCondition('false')),
    ])
    names = {p.label: p.fully_qualified_name for p in plan(description).processes}
    assert names == {'driver': '/arm1/driver', 'absolute': '/elsewhere/absolute',
                     'relative': '/arm1/sub/relative', 'outside': '/outside'}
    outside = plan(description).processes[-1]
    assert outside.arguments == ['arm1']


def test_set_parameter_and_set_remap_apply_to_the_nodes_that_follow() -> None:
    from mindgrasp_launch import SetParameter, SetRemap

    description = LaunchDescription([
        DeclareLaunchArgument('sim_time', default_value='true'),
        ticker('before'),
        GroupAction([
            SetParameter('use_sim_time', LaunchConfiguration('sim_time')),
            SetRemap('/clock', '/bag/clock'),
            ticker('inside', parameters=[{'rate': 3}]),
            ticker('own', parameters=[{'use_sim_time': False}]),
        ]),
        ticker('after'),
    ])
    procs = {p.label: p for p in plan(description).processes}
    assert procs['before'].parameters == {} and procs['after'].parameters == {}
    assert procs['inside'].parameters == {'use_sim_time': True, 'rate': 3}
    assert procs['own'].parameters == {'use_sim_time': False}  # the node's own value wins
    assert procs['inside'].remappings == [('/clock', '/bag/clock')]
    assert procs['after'].remappings == []


def test_include_passes_arguments_and_keeps_scope() -> None:
    description = LaunchDescription([
        IncludeLaunchDescription(str(FIXTURES / 'two_tickers.launch.py'),
                                 launch_arguments={'count': '9', 'rate': '2.5'}),
        ExecuteProcess(cmd=['echo', LaunchConfiguration('count', default='unset')],
                       name='echo'),
    ])
    p = plan(description)
    labels = [s.label for s in p.processes]
    assert labels == ['first', 'second', 'echo']
    assert p.processes[0].arguments[:2] == ['--count', '9']
    assert p.processes[0].parameters == {'rate': 2.5, 'tag': 'one'}
    assert p.processes[2].arguments == [] and p.processes[2].program[-1] == 'unset'
    # an included file's arguments are arguments of the including launch too
    assert 'exit_code' in {a.name for a in LaunchService(description).declared_arguments()}


def test_include_by_path_relative_to_this_launch_file(tmp_path: Path) -> None:
    inner = tmp_path / 'inner.launch.py'
    inner.write_text(
        'from mindgrasp_launch import *\n'
        'def generate_launch_description():\n'
        '    return LaunchDescription([ExecuteProcess(cmd=["true", ThisLaunchFileDir()],'
        ' name="inner")])\n')
    outer = tmp_path / 'outer.launch.py'
    outer.write_text(
        'from mindgrasp_launch import *\n'
        'def generate_launch_description():\n'
        '    return LaunchDescription([IncludeLaunchDescription("inner.launch.py")])\n')
    (spec,) = LaunchService(outer, ['record:=false']).plan().processes
    assert spec.program[1] == str(tmp_path)
    assert ThisLaunchFileDir  # imported for the launch files above
    cyclic = tmp_path / 'cycle.launch.py'
    cyclic.write_text(
        'from mindgrasp_launch import *\n'
        'def generate_launch_description():\n'
        '    return LaunchDescription([IncludeLaunchDescription(__file__)])\n')
    with pytest.raises(LaunchError, match='cycle'):
        LaunchService(cyclic, ['record:=false']).plan()


def test_parameters_from_files_and_dicts_merge_in_order(tmp_path: Path) -> None:
    f = tmp_path / 'p.yaml'
    f.write_text(yaml.safe_dump({
        '/**': {'ros__parameters': {'common': 1, 'rate': 1.0}},
        'classifier': {'ros__parameters': {'window': {'length_s': 2.0}, 'rate': 2.0}},
        '/other/classifier': {'ros__parameters': {'rate': 99.0}},
        '/**/vision': {'ros__parameters': {'size': [1, 2]}},
        'ns': {'vision': {'ros__parameters': {'nested': True}}},
    }))
    description = LaunchDescription([
        DeclareLaunchArgument('rate', default_value='4.5'),
        ticker('classifier', parameters=[f, {'rate': LaunchConfiguration('rate'),
                                             'name': 'text', 'flag': 'true'}]),
        ticker('vision', namespace='ns', parameters=[str(f)]),
        ticker('vision', namespace='ns2', parameters=[f]),
    ])
    c, v, v2 = plan(description).processes
    assert c.parameters == {'common': 1, 'rate': 4.5, 'window.length_s': 2.0, 'name': 'text',
                            'flag': 'true'}
    assert v.parameters == {'common': 1, 'rate': 1.0, 'size': [1, 2], 'nested': True}
    assert v2.parameters == {'common': 1, 'rate': 1.0, 'size': [1, 2]}
    assert v2.label == 'vision-2' and c.parameter_files == [str(f)]
    text = ros_params.dump_parameters({'/classifier': c.parameters})
    assert yaml.safe_load(text)['/classifier']['ros__parameters']['window'] == {'length_s': 2.0}


@pytest.mark.parametrize(('key', 'fqn', 'expected'), [
    ('/**', '/a/b', True), ('**', None, True), ('node', '/node', True), ('node', '/ns/node', False),
    ('/**/node', '/ns/deep/node', True), ('/ns/*', '/ns/node', True), ('/ns/*', '/ns/a/b', False),
    ('/ns/node', '/ns/node', True), ('/ns/node', '/node', False), ('node', None, False),
])
def test_parameter_file_node_keys_match_as_rcl_does(key: str, fqn: str | None,
                                                    expected: bool) -> None:
    assert ros_params.node_matches(key, fqn) is expected


def test_bad_parameter_files_and_values(tmp_path: Path) -> None:
    missing = LaunchDescription([ticker('a', parameters=[tmp_path / 'nope.yaml'])])
    with pytest.raises(LaunchError, match=r'nope.yaml does not exist: check the path'):
        plan(missing)
    broken = tmp_path / 'broken.yaml'
    broken.write_text('a: [1, 2\n')
    with pytest.raises(LaunchError, match='is not valid YAML'):
        plan(LaunchDescription([ticker('a', parameters=[broken])]))
    flat = tmp_path / 'flat.yaml'
    flat.write_text('rate: 3\n')
    with pytest.raises(LaunchError, match='not under ros__parameters'):
        plan(LaunchDescription([ticker('a', parameters=[flat])]))
    with pytest.raises(LaunchError, match=r"parameter 'mixed' of node /a .* cannot hold"):
        plan(LaunchDescription([ticker('a', parameters=[{'mixed': [1, 'x']}])]))


def test_unknown_and_malformed_arguments_list_the_valid_ones() -> None:
    description = LaunchDescription([DeclareLaunchArgument('gui', default_value='false'),
                                     DeclareLaunchArgument('stream')])
    with pytest.raises(LaunchError, match=r"unknown launch argument 'guy' .*valid arguments are "
                                          r"gui \(default 'false'\), stream \(required\), "
                                          r"record \(default 'true'\)"):
        plan(description, 'guy:=true', 'stream:=x')
    with pytest.raises(LaunchError, match=r"'stream' is required and was not given: add "
                                          r"stream:=<value>"):
        plan(description)
    with pytest.raises(LaunchError, match=r"'gui=true' is not of the form name:=value"):
        parse_launch_arguments(['gui=true'])
    with pytest.raises(LaunchError, match=r"'duration' must be a number of seconds >= 0"):
        plan(description, 'stream:=x', 'duration:=-3')
    with pytest.raises(LaunchError, match="launch configuration 'nothing' does not exist"):
        plan(LaunchDescription([ticker('a', arguments=[LaunchConfiguration('nothing')])]))


def test_missing_node_module_is_named_with_the_fix() -> None:
    description = LaunchDescription([
        Node(package='mindgrasp_sim', executable='no_such_node', name='sim'),
        Node(package='no_such_package', executable='x_node', name='x'),
        Node(executable='no-such-driver-on-path', name='driver'),
        ticker('fine'),
    ])
    with pytest.raises(LaunchError) as info:
        plan(description)
    text = str(info.value)
    assert "launch 'launch' cannot start" in text
    assert "sim: the node module 'mindgrasp_sim.no_such_node' does not exist" in text
    assert "'python -m no_such_package.x_node'" in text
    assert "'no-such-driver-on-path' was found neither on PATH nor as a Python module" in text
    assert 'fine' not in text


def test_external_executable_resolves_on_path() -> None:
    (spec,) = plan(LaunchDescription([Node(executable='true', name='driver',
                                           remappings=[('a', 'b')])])).processes
    assert spec.program[0].endswith('/true') and spec.module is None
    assert spec.command()[1:] == ['--ros-args', '-r', '__node:=driver', '-r', 'a:=b']


def test_package_slash_executable_runs_with_ros2_run(tmp_path: Path, monkeypatch) -> None:
    fake_ros2 = tmp_path / 'ros2'
    fake_ros2.write_text('#!/bin/sh\n')
    fake_ros2.chmod(0o755)
    description = LaunchDescription([Node(executable='ur_driver/ur_node', name='arm')])
    monkeypatch.setenv('PATH', '/usr/bin:/bin')
    with pytest.raises(LaunchError, match=r"'ur_driver/ur_node' is neither the Python module "
                                          r"ur_driver.ur_node nor runnable with 'ros2 run'"):
        plan(description)
    monkeypatch.setenv('PATH', f'{tmp_path}:/usr/bin:/bin')
    (spec,) = plan(description).processes
    assert spec.command() == [str(fake_ros2), 'run', 'ur_driver', 'ur_node', '--ros-args', '-r',
                              '__node:=arm']


def test_recorder_is_first_and_gets_the_bag_and_topics() -> None:
    p = plan(LaunchDescription([ticker('a')]), 'record_topics:=/eeg/raw, /fsm/state',
             'record_regex:=^/camera/', record=True)
    recorder, a = p.processes
    assert recorder.label == 'recorder' and recorder.daemon and not a.daemon
    assert recorder.module == 'mindgrasp_bag.recorder_node'
    assert recorder.parameters['topics'] == ['/eeg/raw', '/fsm/state']
    assert recorder.parameters['regex'] == '^/camera/'
    # the run's bag: zstd chunks, without the display frames drawn from recorded topics
    assert recorder.parameters['compression'] == 'zstd'
    assert recorder.parameters['exclude_regex'] == r'^/(display/image|trainer/display)$'
    assert p.record and p.arguments['record'] == 'true'


def test_profiles_and_unknown_profile() -> None:
    assert 'demo' in profiles()
    with pytest.raises(LaunchError, match=r"unknown launch profile 'demoo': valid profiles are "
                                          r".*demo"):
        LaunchService('demoo')
    with pytest.raises(LaunchError, match='does not exist: check the path'):
        LaunchService('/nowhere/x.launch.py')


def test_every_profile_loads_and_declares_described_arguments() -> None:
    for name in profiles():
        service = LaunchService(name)
        text = format_arguments(service.declared_arguments())
        assert "'record':" in text and "'duration':" in text
        assert 'no description given' not in text, name


def test_bad_launch_files(tmp_path: Path) -> None:
    nogen = tmp_path / 'nogen.launch.py'
    nogen.write_text('x = 1\n')
    with pytest.raises(LaunchError, match='has no generate_launch_description'):
        LaunchService(nogen)
    wrong = tmp_path / 'wrong.launch.py'
    wrong.write_text('def generate_launch_description():\n    return [1]\n')
    with pytest.raises(LaunchError, match='returned list, not a LaunchDescription'):
        LaunchService(wrong)
    boom = tmp_path / 'boom.launch.py'
    boom.write_text('raise RuntimeError("kaput")\n')
    with pytest.raises(LaunchError, match='failed to import: RuntimeError: kaput'):
        LaunchService(boom)
    with pytest.raises(LaunchError, match='holds actions'):
        LaunchDescription(['not an action'])


def test_cli_show_args_list_and_errors(capsys: pytest.CaptureFixture[str]) -> None:
    from mindgrasp_cli.cli import main

    assert main(['launch', '--list']) == 0
    assert 'demo' in capsys.readouterr().out
    assert main(['launch', str(FIXTURES / 'two_tickers.launch.py'), '--show-args']) == 0
    out = capsys.readouterr().out
    assert "'count':" in out and "(default: '3')" in out and "'record':" in out
    assert main(['launch', 'nope']) == 2
    assert "unknown launch profile 'nope'" in capsys.readouterr().err
    assert main(['launch', str(FIXTURES / 'two_tickers.launch.py'), 'cnt:=1']) == 2
    assert "unknown launch argument 'cnt'" in capsys.readouterr().err
    assert main(['launch', str(FIXTURES / 'two_tickers.launch.py'), 'record:=false',
                 '--dry-run']) == 0
    out = capsys.readouterr().out
    assert '[first] ' in out and '__ns:=/grp' in out and '<run dir>/params/first.yaml' in out
    assert launch_cmd.profile_summaries()[0][1]  # every profile has a docstring


def test_a_profile_takes_the_params_files_of_each_launch_in_one_process(tmp_path,
                                                                       monkeypatch) -> None:
    """A session runs its phases' launches in its own process, each with its own
    ``$MINDGRASP_PARAMS_FILES``: a description generated for one phase is not reused for the
    next (a cached description once kept the first phase's files)."""
    def fixation() -> list:
        plan = LaunchService('graz', {}).plan(strict=False)
        return [p.parameters.get('fixation') for p in plan.processes
                if p.label == 'graz_prompter']

    phase = tmp_path / 'phase.yaml'
    phase.write_text('graz_prompter:\n  ros__parameters:\n    fixation: 0.25\n')
    monkeypatch.delenv('MINDGRASP_PARAMS_FILES', raising=False)
    default = fixation()
    monkeypatch.setenv('MINDGRASP_PARAMS_FILES', str(phase))
    assert fixation() == [0.25] != default
    monkeypatch.delenv('MINDGRASP_PARAMS_FILES')
    assert fixation() == default
