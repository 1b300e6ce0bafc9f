"""ament_python package for colcon build; the root pyproject.toml also installs it.

The files installed to share/ (package.xml, the ament index marker, data folders) are
declared in setup.cfg ``[options.data_files]`` (globs, one line per folder), so each package
builds on its own (tests/bringup/test_colcon_workspace.py).
"""

import re
from pathlib import Path

from setuptools import find_packages, setup

package_name = 'mindgrasp_classifier'
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
            'classifier_node = mindgrasp_classifier.classifier_node:main',
        ],
        # verbs of the mindgrasp command: 'COMMAND VERB = module' (add_arguments, main)
        'mindgrasp.verb': [
            'train classifier = mindgrasp_classifier.commands.train_classifier',
            'evaluate classifier = mindgrasp_classifier.commands.evaluate_classifier',
        ],
    },
)
