"""ament_python package for colcon build; the root pyproject.toml also installs it.

The files installed to share/ (package.xml, the ament index marker, data folders) are
declared in setup.cfg ``[options.data_files]`` (globs, one line per folder), so each package
builds on its own (tests/bringup/test_colcon_workspace.py).
"""

import re
from pathlib import Path

from setuptools import find_packages, setup

package_name = 'mindgrasp_experiments'
here = Path(__file__).resolve().parent
# one description: package.xml's
DESCRIPTION = re.search(r'<description>(.*?)</description>',
                        (here / 'package.xml').read_text(encoding='utf-8'), re.S).group(1)


setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    # data files inside the Python package, as the root pyproject.toml ships them
    package_data={'': [f'**/*.{ext}' for ext in ('yaml', 'json', 'urdf', 'xml', 'txt', 'msg', 'srv',
                                                 'npz', 'pt', 'stl', 'obj', 'launch.py')]},
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
            'eeg fit-virtual = mindgrasp_experiments.commands.eeg_fit_virtual',
            'evaluate decoding = mindgrasp_experiments.commands.evaluate_decoding',
            'experiment set-locations = mindgrasp_experiments.commands.experiment_set_locations',
            ('experiment random-locations = '
             'mindgrasp_experiments.commands.experiment_random_locations'),
            'experiment report = mindgrasp_experiments.commands.experiment_report',
            'experiment sweep = mindgrasp_experiments.commands.experiment_sweep',
            'robot check = mindgrasp_experiments.commands.robot_check',
            'experiment population = mindgrasp_experiments.commands.experiment_population',
        ],
    },
)
