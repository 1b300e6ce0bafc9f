"""Bad input to any command or node ends in ONE stderr line naming the problem, no traceback, and
a non-zero exit code (2 for usage errors, as argparse and ros2cli give it).

The cases are made from the CLI's own table (:func:`mindgrasp_cli.cli.commands`, so verbs added
later are covered) and from every package's console scripts (the node executables): unknown
flags, missing values, values of the wrong type or out of their choices, missing arguments,
malformed ``--ros-args`` and parameter files. They run in-process and fail before any DDS traffic
(a few seconds for all); a handful of hand-written cases check what only the command itself can
check (out-of-range message fields, launch argument values, files), and a few run as real
processes (``mindgrasp run``, ``mindgrasp eeg virtual-amp --ros-args``).
"""

from __future__ import annotations

import argparse
import functools
import importlib
import subprocess
import sys
from pathlib import Path

import pytest

from mindgrasp_cli import cli
from mindgrasp_common.cli_checks import (
    finite_float,
    non_negative_float,
    non_negative_int,
    positive_float,
    positive_int,
    probability,
)
from mindgrasp_testing import console_scripts

REPO = Path(__file__).resolve().parents[2]

#: a harmless value for a required positional argument, by its dest
SAMPLES = {'topic': '/fuzz', 'type': 'std_msgs/msg/String', 'node': '/fuzz',
           'package': 'mindgrasp_fsm', 'executable': 'fsm_node', 'name': 'x', 'value': '1'}


#: a value outside the range of each number check (plain ``float`` takes nan: no option should)
OUT_OF_RANGE = {non_negative_int: '-1', positive_int: '0', non_negative_float: '-0.5',
                positive_float: '0', probability: '1.5', finite_float: 'nan', float: 'nan'}


def _verbs() -> list[tuple[str, ...]]:
    return [(command,) if isinstance(target, str) else (command, verb)
            for command, target in cli.commands().items()
            for verb in ([None] if isinstance(target, str) else target)]


def _verb_parser(prefix: tuple[str, ...]) -> argparse.ArgumentParser:
    parser: argparse.ArgumentParser = cli.build_parser(list(prefix))
    for word in prefix:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        parser = sub.choices[word]
    return parser


def _sample(action: argparse.Action) -> list[str]:
    """Values that satisfy ``action`` (a required argument the case is not about)."""
    if action.choices:
        value = str(next(iter(action.choices)))
    elif action.dest in SAMPLES:
        value = SAMPLES[action.dest]
    else:
        value = 'x' if action.type in (None, str) else '1'
    count = action.nargs if isinstance(action.nargs, int) else 1
    return [value] * count


def _required(parser: argparse.ArgumentParser) -> tuple[list[str], bool]:
    """(words that fill every required argument, whether a REMAINDER positional takes the rest)."""
    words: list[str] = []
    remainder = False
    for action in parser._actions:
        if action.nargs == argparse.REMAINDER:
            remainder = remainder or not action.option_strings
            continue
        if action.option_strings:
            if action.required:
                words += [action.option_strings[0], *_sample(action)]
        elif action.nargs not in ('?', '*'):
            words += _sample(action)
    return words, remainder


def _usage_cases() -> list:
    """argparse-level cases of every verb: (argv, a word the error line must contain)."""
    cases = []
    for prefix in _verbs():
        parser = _verb_parser(prefix)
        fill, remainder = _required(parser)
        label = ' '.join(prefix)
        cases.append(pytest.param([*prefix, '--no-such-flag', *fill], '--no-such-flag',
                                  id=f'{label} --no-such-flag'))
        if fill:
            cases.append(pytest.param(list(prefix), 'required', id=f'{label} (nothing)'))
        for action in parser._actions:
            if not action.option_strings or action.nargs in (0, '?', '*', argparse.REMAINDER) \
                    or action.dest == 'help':
                continue
            flag = action.option_strings[-1]
            tail = [] if remainder else fill
            cases.append(pytest.param([*prefix, *tail, flag], flag,
                                      id=f'{label} {flag} (no value)'))
            if action.choices or (action.type not in (None, str)):
                cases.append(pytest.param([*prefix, *tail, flag, 'no-such-value', 'x'], flag,
                                          id=f'{label} {flag} no-such-value'))
            if action.type in OUT_OF_RANGE:
                value = OUT_OF_RANGE[action.type]
                count = action.nargs if isinstance(action.nargs, int) else 1
                # --x=-1, not --x -1: argparse takes '-1' alone for an option when a parser
                # has options that look like negative numbers
                words = [f'{flag}={value}'] if count == 1 else [flag, *[value] * count]
                cases.append(pytest.param([*prefix, *tail, *words], flag,
                                          id=f'{label} {flag}={value}'))
    return cases


def _one_line_error(capsys: pytest.CaptureFixture, code: int | None) -> str:
    err = capsys.readouterr().err
    assert 'Traceback' not in err, err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert code not in (0, None), err
    return lines[0]


def _run_cli(argv: list[str]) -> int | None:
    try:
        return cli.main(argv)
    except SystemExit as exc:
        return exc.code


@functools.cache
def _cli_parser(prefix: tuple[str, ...]) -> argparse.ArgumentParser:
    """The parser ``mindgrasp <prefix> ...`` builds (once per verb: building it costs 60 ms)."""
    return cli.build_parser(list(prefix))


@pytest.mark.parametrize(('argv', 'named'), _usage_cases())
def test_usage_errors_are_one_line_exit_2(argv, named, capsys):
    prefix = tuple(argv[:1]) if isinstance(cli.commands()[argv[0]], str) else tuple(argv[:2])
    with pytest.raises(SystemExit) as exc:
        args = _cli_parser(prefix).parse_args(argv)
        pytest.fail(f'argparse accepted the bad input: {args}')
    code = exc.value.code
    line = _one_line_error(capsys, code)
    assert code == 2, line
    assert named in line, line
    assert '--help' in line, line  # says where the usage is


def test_the_cases_cover_every_verb_of_the_table():
    ids = {' '.join(p.values[0][:2]) for p in _usage_cases()}
    for prefix in _verbs():
        assert any(i.startswith(' '.join(prefix)) for i in ids), prefix


# -- what only the command can check (no DDS: each fails before its node is created) -------------

@pytest.fixture(scope='module')
def bad_files(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp('bad')
    (folder / 'broken.yaml').write_text('a: [\n')
    (folder / 'not_ros.yaml').write_text('fsm: {grasp_retries: 3}\n')
    (folder / 'scalar.yaml').write_text('fsm:\n  ros__parameters: 3\n')
    return folder


SEMANTIC = [
    (['topic', 'pub', '-1', '/bci/prediction', 'mindgrasp_msgs/msg/MIPrediction',
      '{class_index: 300}'], "field 'class_index' is uint8 (a whole number from 0 to 255)"),
    (['topic', 'pub', '/x', 'std_msgs/msg/Int8', '{data: 1000}'], "'data' is int8"),
    (['topic', 'pub', '/x', 'std_msgs/msg/String', '{data: 3}'], "'data' is string"),
    (['topic', 'pub', '/x', 'std_msgs/msg/Float64MultiArray', '{data: [a]}'],
     "'data'[0] is float64"),
    (['topic', 'pub', '/x', 'std_msgs/msg/Float32', '{data: 1.0e+39}'], "'data' is float32"),
    (['topic', 'pub', '/x', 'std_msgs/msg/Header', '{stamp: 3}'],
     "'stamp' is a builtin_interfaces"),
    (['topic', 'pub', '/x', 'std_msgs/msg/String', '{nofield: 1}'], "no field 'nofield'"),
    (['topic', 'pub', '/x', 'std_msgs/msg/String', '{data: ['], 'not valid YAML (line 1'),
    (['topic', 'pub', '/x', 'std_msgs/msg/String', '[1]'], 'must be a YAML mapping'),
    (['topic', 'pub', '9bad', 'std_msgs/msg/String'], "Invalid topic name '9bad'"),
    (['topic', 'pub', '/x', 'bogus/msg/X'], "Unknown msg type 'bogus/msg/X'"),
    (['topic', 'echo', '/x', 'bogus/msg/X'], "Unknown msg type 'bogus/msg/X'"),
    (['topic', 'echo', '/a//b'], "must not contain"),
    (['topic', 'hz', '/x', '--type', 'nope'], "'nope' is not a ROS type name"),
    (['topic', 'info', '9bad'], "Invalid topic name '9bad'"),
    (['node', 'info', '/9bad'], "Invalid node name '9bad'"),
    (['param', 'set', '/fsm', 'grasp_retries', '99999999999999999999'],
     "parameter 'grasp_retries' is int64 (a whole number from -9223372036854775808"),
    (['param', 'set', '/fsm', 'x', '[1, 99999999999999999999]'], "parameter 'x'[1] is int64"),
    (['param', 'set', '/fsm', 'x', '[1, a'], 'not a parameter value (line 1'),
    (['param', 'get', 'bad-name', 'x'], "Invalid node name 'bad-name'"),
    (['param', 'list', '/a//b'], "Invalid node name '/a//b'"),
    (['param', 'describe', '/9', 'x'], "Invalid node name '9'"),
    (['launch', 'experiment', 'eeg_source:=bogus', 'trials:=1'],
     "launch argument 'eeg_source' is 'bogus': 'bogus' is not an EEG source; give synthetic"),
    (['launch', 'experiment', 'eeg_source:=eegmmidb:200'], 'EEGMMIDB has subjects 1-109'),
    (['launch', 'experiment', 'eeg_source:=/no/such/subject.yaml'], 'does not exist'),
    (['launch', 'no_such_profile'], 'no_such_profile'),
    (['launch', 'demo', 'no_such_argument:=1'], 'no_such_argument'),
    (['launch', 'demo', 'trials:=abc'], "'trials' is 'abc'"),
    (['launch', 'sim', 'camera:=big'], 'WIDTHxHEIGHT@HZ'),
    (['run', 'no_such_package', 'node'], "package 'no_such_package' not found"),
    (['run', 'mindgrasp_fsm', 'no_such_node'], "'mindgrasp_fsm.no_such_node' does not exist"),
    (['eeg', 'virtual-amp', '--no-ros', '--ros-args', '-p', 'seed:=1'], '--ros-args needs'),
    (['topic'], 'a verb is required: echo, hz, info, list, pub'),
    # files and parameters of the offline commands
    (['experiment', 'report', '/no/such/run'], '/no/such/run'),
    (['experiment', 'set-locations', '--trials', '1', '--param', 'no_equals'], 'no_equals'),
    (['experiment', 'set-locations', '--trials', '1', '--launch', '/no/such.launch.py'],
     '/no/such.launch.py'),
    (['export', 'eeg', '/no/such/run'], '/no/such/run'),
    (['eeg', 'play', '/no/such.edf'], '/no/such.edf'),
    (['replay', '/no/such/run'], '/no/such/run'),
    (['evaluate', 'classifier', '--model', 'package://no_such_package/m', '--eegbci', '1'],
     'no_such_package'),
    (['train', 'vision', '--n-images', '1'], '--n-images must be >= 30'),
]


@pytest.mark.parametrize(('argv', 'message'), SEMANTIC, ids=lambda v: ' '.join(v)[:60]
                         if isinstance(v, list) else None)
def test_bad_values_are_one_line(argv, message, capsys):
    code = _run_cli(argv)
    line = _one_line_error(capsys, code)
    assert message in line, line
    if argv[:2] in (['topic', 'pub'], ['param', 'set']):
        assert code == 2, line   # a value that does not fit: a usage error, nothing was sent


@pytest.mark.parametrize(('argv', 'message'), [
    (['experiment', 'random-locations', '--trials', '1', '--realism', '{bad}/broken.yaml'],
     'is not valid YAML (line 2, column 1'),
    (['train', 'vision', '--n-images', '30', '--realism', '{bad}/broken.yaml'],
     'is not valid YAML (line 2, column 1'),
    (['session', 'run', '--subject', 's1', '--plan', '{bad}/broken.yaml', '--root', '{bad}'],
     'is not valid YAML: line 2, column 1'),
    (['experiment', 'set-locations', '--trials', '1', '--subject', '{bad}/broken.yaml'],
     'line 2, column 1'),
    (['eeg', 'play', 'eegbci:999:4'], 'EEGMMIDB has subjects 1-109 and runs 1-14'),
], ids=lambda v: ' '.join(v)[:50] if isinstance(v, list) else None)
def test_bad_files_are_one_line(argv, message, bad_files, capsys):
    code = _run_cli([a.format(bad=bad_files) for a in argv])
    line = _one_line_error(capsys, code)
    assert message in line, line


# -- every node's argument parser: --ros-args rules and parameter files ---------------------------

def _node_mains() -> list:
    scripts = {}
    for package_dir in sorted(REPO.glob('src/mindgrasp_*')):
        if (package_dir / 'setup.py').is_file():
            scripts.update(console_scripts(package_dir))
    return [pytest.param(target, id=name) for name, target in sorted(scripts.items())
            if name != 'mindgrasp']


#: ``--ros-args`` rules a node must refuse: the words, then a part of its one error line
BAD_ROS_ARGS = [(words.split(), message.strip()) for words, message in (
    row.split(' | ') for row in """\
-p bogus | Invalid parameter 'bogus': write it as -p name:=value
-p | -p needs a value
-p :=3 | the name is missing
-r bad | Invalid remapping 'bad'
-r __node:=9bad | Invalid node name '9bad'
-r __ns:=/a//b | Invalid namespace
--log-level loud | Unknown log level 'loud'
--bogus | Unknown ROS argument '--bogus'
--params-file /no/such/params.yaml | does not exist
--params-file {bad}/broken.yaml | is not valid YAML (line 2, column 1
--params-file {bad}/not_ros.yaml | must be a mapping of node names to
--params-file {bad}/scalar.yaml | must be a mapping""".splitlines())]


@pytest.mark.parametrize('target', _node_mains())
def test_every_node_refuses_bad_ros_args_in_one_line(target, bad_files, capsys):
    module_name, _, function = target.partition(':')
    main = getattr(importlib.import_module(module_name), function)
    for ros_args, message in BAD_ROS_ARGS:
        argv = ['node', '--ros-args', *(a.format(bad=bad_files) for a in ros_args)]
        code = main(argv)
        line = _one_line_error(capsys, code)
        assert code == 2, line
        assert message in line, (argv, line)


# -- a handful as real processes: the console script, its exit code and its stderr ---------------

def _mindgrasp(*argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *argv], capture_output=True,
                          text=True, timeout=120, check=False)


@pytest.mark.parametrize(('argv', 'message'), [
    (['run', 'mindgrasp_fsm', 'fsm_node', '--ros-args', '-p', 'bogus'],
     "[FsmNode] ERROR: Invalid parameter 'bogus': write it as -p name:=value."),
    # the options reach the node: its own range check refuses the value
    (['eeg', 'virtual-amp', '--ros-args', '-p', 'accuracy:=7'], "'accuracy'"),
    (['topic', 'hz', '/x', '--window', '0'], 'argument -w/--window: must be >= 1, got 0'),
])
def test_real_processes(argv, message):
    done = _mindgrasp(*argv)
    assert 'Traceback' not in done.stderr, done.stderr
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and message in lines[0], done.stderr
    assert done.returncode == 2, done.stderr


def test_virtual_amp_passes_ros_args_on():
    from mindgrasp_eeg.commands.eeg_virtual_amp import _ros_argv

    argv = ['eeg', 'virtual-amp', '--seed', '3', '--ros-args', '-p', 'seed:=1', '-r',
            '__node:=amp2']
    args = cli.build_parser(argv).parse_args(argv)
    ros = _ros_argv(args)
    assert ros[0] == '--ros-args' and ros[-4:] == ['-p', 'seed:=1', '-r', '__node:=amp2']
    assert ros.index('seed:=3') < ros.index('seed:=1')   # the later -p wins, as in rcl


def test_an_unknown_node_is_one_line_without_the_cli_itself():
    """A valid name nobody has: one line listing the nodes there are, not the command's own
    hidden node (it listed /_mindgrasp_cli_<pid>)."""
    done = _mindgrasp('node', 'info', '/no_such_node')
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert done.returncode == 1 and len(lines) == 1, done.stderr
    assert "Node '/no_such_node' was not found. Nodes: " in lines[0]
    assert '_mindgrasp_cli' not in lines[0] and 'Traceback' not in done.stderr
