"""ament_python package for colcon build; the root pyproject.toml also installs it."""

import re
from pathlib import Path

from setuptools import find_packages, setup

package_name = 'mindgrasp_experiments'
here = Path(__file__).resolve().parent
# one description: package.xml's
DESCRIPTION = re.search(r'<description>(.*?)</description>',
                        (here / 'package.xml').read_text(encoding='utf-8'), re.S).group(1)


def share_files() -> list[tuple[str, list[str]]]:
    """Data files of the Python package (parameter YAML, scenes, URDF, models, launch files) also
    installed to share/<package>/<same path>, where ament_index and ``ros2 launch`` find them."""
    groups: dict[str, list[str]] = {}
    for path in sorted((here / package_name).rglob('*')):
        rel = path.relative_to(here / package_name)
        if (not path.is_file() or '__pycache__' in rel.parts or rel.parts[0].startswith('.')
                or (path.suffix == '.py' and not path.name.endswith('.launch.py'))
                or len(rel.parts) == 1):
            continue
        groups.setdefault(str(Path('share', package_name, rel.parent)), []).append(
            str(path.relative_to(here)))
    return sorted(groups.items())


setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    # data files inside the Python package, as the root pyproject.toml ships them
    package_data={'': [f'**/*.{ext}' for ext in ('yaml', 'json', 'urdf', 'xml', 'txt', 'msg', 'srv',
                                                 'npz', 'pt', 'stl', 'obj', 'launch.py')]},
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        *share_files(),
    ],
    install_requires=['setuptools'],
    zip_safe=False,
    maintainer='MIndGrasp-ROS maintainers',
    maintainer_email='maintainers@users.noreply.github.com',
    description=DESCRIPTION,
    license='MIT',
    entry_points={
        'console_scripts': [
            'trial_manager_node = mindgrasp_experiments.trial_manager_node:main',
            'oracle_subject_node = mindgrasp_experiments.oracle_subject_node:main',
        ],
        # verbs of the mindgrasp command: 'COMMAND VERB = module' (add_arguments, main)
        'mindgrasp.verb': [
            'eeg fit-virtual = mindgrasp_experiments.fit_virtual_cli',
            'evaluate decoding = mindgrasp_experiments.commands.evaluate_decoding',
            'experiment set-locations = mindgrasp_experiments.commands.set_locations',
            'experiment random-locations = mindgrasp_experiments.commands.random_locations',
            'experiment report = mindgrasp_experiments.commands.report',
            'experiment sweep = mindgrasp_experiments.commands.sweep',
        ],
    },
)
