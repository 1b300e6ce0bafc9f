"""ament_python package for colcon build; the root pyproject.toml also installs it.

Metadata is in setup.cfg. The package has no data files (the recorder's and player's parameters
are their dataclass defaults): it installs its modules, package.xml and the ament index marker.
"""

import re
from pathlib import Path

from setuptools import find_packages, setup

package_name = 'mindgrasp_bag'
package_xml = (Path(__file__).resolve().parent / 'package.xml').read_text(encoding='utf-8')

setup(
    packages=find_packages(exclude=['test']),
    # one description: package.xml's
    description=re.search(r'<description>(.*?)</description>', package_xml, re.S).group(1),
    entry_points={
        'console_scripts': [
            'recorder_node = mindgrasp_bag.recorder_node:main',
            'player_node = mindgrasp_bag.player_node:main',
        ],
        # verbs of the mindgrasp command: 'COMMAND VERB = module' (add_arguments, main)
        'mindgrasp.verb': [
            'bag record = mindgrasp_bag.commands.bag_record',
            'bag play = mindgrasp_bag.commands.bag_play',
            'bag info = mindgrasp_bag.commands.bag_info',
            'bag reindex = mindgrasp_bag.commands.bag_reindex',
            'bag latency = mindgrasp_bag.commands.bag_latency',
        ],
    },
)
