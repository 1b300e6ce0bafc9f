"""Package data through mindgrasp_common.resources."""

import os
from pathlib import Path

import pytest

from mindgrasp_common import ResourceNotFoundError, resolve_path, resource_path


def test_resource_path_finds_package_data():
    path = resource_path('mindgrasp_common', 'resources.py')
    assert path.is_file() and path.name == 'resources.py'
    assert resource_path('mindgrasp_common') == path.parent
    mi = resource_path('mindgrasp_common', 'mi.py')
    assert mi == resource_path('mindgrasp_common', '', 'mi.py')


def test_missing_file_names_package_and_file():
    with pytest.raises(ResourceNotFoundError,
                       match=r"package 'mindgrasp_common' has no data file 'config/nope.yaml' "
                             r'\(check the name\)'):
        resource_path('mindgrasp_common', 'config', 'nope.yaml')


def test_missing_file_lists_what_the_folder_holds():
    with pytest.raises(ResourceNotFoundError, match=r"no data file 'typo.py' \(its top folder "
                                                    r"holds \[.*'types.py'"):
        resource_path('mindgrasp_common', 'typo.py')


def test_missing_package_names_it_and_the_fix():
    with pytest.raises(ResourceNotFoundError,
                       match=r"Cannot find the package 'mindgrasp_nothing'.*pip install -e"):
        resource_path('mindgrasp_nothing', 'x.yaml')


@pytest.mark.parametrize('rel', ['../pyproject.toml', '/etc/passwd', 'a/./b'])
def test_paths_outside_the_package_are_refused(rel):
    with pytest.raises(ResourceNotFoundError, match="relative path inside the package"):
        resource_path('mindgrasp_common', rel)


def test_resource_error_is_a_file_not_found_error():
    assert issubclass(ResourceNotFoundError, FileNotFoundError)


def test_resolve_path_package_uri_and_fallbacks(tmp_path, monkeypatch):
    here = resource_path('mindgrasp_common', 'types.py')
    assert resolve_path('package://mindgrasp_common/types.py', 'x') == here
    # a relative name that is no file here: the package's data file
    monkeypatch.chdir(tmp_path)
    assert resolve_path('types.py', 'mindgrasp_common') == here
    # stems of file sets: found when stem + suffix exists
    assert resolve_path('types', 'mindgrasp_common', ('.py',)) == here.with_suffix('')
    assert resolve_path('package://mindgrasp_common/types', 'x', ('.py',)) == here.with_suffix('')
    # a file in the working directory wins over package data
    (tmp_path / 'types.py').write_text('')
    assert resolve_path('types.py', 'mindgrasp_common') == Path('types.py')
    # unknown: returned unchanged for the caller's own error
    assert resolve_path('nothing.json', 'mindgrasp_common') == Path('nothing.json')
    absolute = tmp_path / 'absent.json'
    assert resolve_path(str(absolute), 'mindgrasp_common') == absolute


def test_resolve_path_bad_package_uri():
    with pytest.raises(ResourceNotFoundError, match=r"has no data file 'nope\.json'"):
        resolve_path('package://mindgrasp_common/nope.json', 'x')
    with pytest.raises(ResourceNotFoundError, match=r"no data file 'nope' \(nor nope.json\)"):
        resolve_path('package://mindgrasp_common/nope', 'x', ('.json',))


def test_share_directory_of_an_ament_install_wins(tmp_path, monkeypatch):
    """With ROS 2 sourced, a colcon install's share/<pkg>/ is preferred."""
    pytest.importorskip('ament_index_python')
    prefix = tmp_path / 'install'
    index = prefix / 'share' / 'ament_index' / 'resource_index' / 'packages'
    index.mkdir(parents=True)
    (index / 'mindgrasp_common').write_text('')
    share = prefix / 'share' / 'mindgrasp_common'
    share.mkdir()
    (share / 'types.py').write_text('')
    monkeypatch.setenv('AMENT_PREFIX_PATH', os.pathsep.join([str(prefix)]))
    assert resource_path('mindgrasp_common', 'types.py') == share / 'types.py'


# -- config/: what a user edits, in one place -------------------------------------------------

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(('package', 'rel', 'in_config'), [
    ('mindgrasp_fsm', 'param/fsm.yaml', 'param/fsm.yaml'),
    ('mindgrasp_eeg', 'param/eeg.yaml', 'param/eeg.yaml'),
    ('mindgrasp_bringup', 'param/demo.yaml', 'profiles/demo.yaml'),
    ('mindgrasp_sim', 'scenes/set_locations.yaml', 'scenes/set_locations.yaml'),
    ('mindgrasp_bringup', 'plans/graded.yaml', 'plans/graded.yaml'),
    ('mindgrasp_bringup', 'config/plans/graded.yaml', 'plans/graded.yaml'),
    ('mindgrasp_sim', 'robots/xarm6.yaml', 'robots/xarm6.yaml'),
    ('mindgrasp_sim', 'urdf/mindgrasp_arm.urdf', 'robots/urdf/mindgrasp_arm.urdf'),
    ('mindgrasp_bringup', 'config/robots/panda.yaml', 'robots/panda.yaml'),
])
def test_config_files_are_found_in_config_by_their_package(package, rel, in_config):
    expected = REPO / 'config' / in_config
    assert resource_path(package, rel) == expected
    assert resolve_path(f'package://{package}/{rel}', 'x') == expected


def test_no_package_keeps_a_file_that_belongs_in_config():
    left = sorted(str(p.relative_to(REPO))
                  for folder, pattern in (('param', '*.yaml'), ('scenes', '*.yaml'),
                                          ('plans', '*.yaml'), ('robots', '*'), ('urdf', '*'))
                  for p in REPO.glob(f'src/mindgrasp_*/mindgrasp_*/{folder}/{pattern}'))
    assert not left, f'move to config/ (config/README.md): {left}'


def test_installed_config_wins_without_ros(tmp_path, monkeypatch):
    """A sourced colcon workspace without ROS 2 (no ament_index_python): the share directory of
    ``AMENT_PREFIX_PATH`` is found as ament_index finds it."""
    prefix = tmp_path / 'install' / 'mindgrasp_bringup'
    index = prefix / 'share' / 'ament_index' / 'resource_index' / 'packages'
    index.mkdir(parents=True)
    (index / 'mindgrasp_bringup').write_text('')
    installed = prefix / 'share' / 'mindgrasp_bringup' / 'config' / 'param' / 'fsm.yaml'
    installed.parent.mkdir(parents=True)
    installed.write_text('fsm: {}\n')
    monkeypatch.setenv('AMENT_PREFIX_PATH', f'{tmp_path / "nothing"}{os.pathsep}{prefix}')
    assert resource_path('mindgrasp_fsm', 'param', 'fsm.yaml') == installed
    # a file the install lacks: the checkout's
    assert resource_path('mindgrasp_sim', 'scenes') == REPO / 'config' / 'scenes'


def test_robot_descriptions_are_config_files_with_their_urdfs():
    """robot:=NAME finds the descriptions in config/robots/, their arms and hands in arms/ and
    hands/, and each part's URDF (in config/robots/urdf/ or pybullet_data) with its licence."""
    from mindgrasp_common.robot_description import load_robot, robot_names

    assert robot_names() == ['iiwa_franka_hand', 'iiwa_mindgrasp_hand', 'iiwa_xarm_gripper',
                             'jaco', 'mindgrasp_arm', 'panda', 'xarm6']
    for name in robot_names():
        robot = load_robot(name)
        assert robot.path == REPO / 'config' / 'robots' / f'{name}.yaml'
        assert robot.urdf.is_file()
        assert robot.licence
        for part, folder in ((robot.arm, 'arms'), (robot.hand, 'hands')):
            assert part.path.parent == REPO / 'config' / 'robots' / folder and part.licence
            assert part.urdf.parent == REPO / 'config' / 'robots' / 'urdf' \
                or 'pybullet_data' in part.urdf.parts


def test_missing_config_file_names_where_it_looked():
    with pytest.raises(ResourceNotFoundError,
                       match=r"'param/nope.yaml' of 'mindgrasp_fsm' is a config file, looked for "
                             r"as config/param/nope.yaml: .*config/param holds \[.*'fsm.yaml'"):
        resource_path('mindgrasp_fsm', 'param', 'nope.yaml')
