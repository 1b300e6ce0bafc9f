"""ament_python package for colcon build; the root pyproject.toml also installs it.

Metadata is in setup.cfg. The package has no data files (the launch files, profiles and
parameter files it reads belong to mindgrasp_bringup and the top-level config/): it installs its
modules, package.xml and the ament index marker.
"""

import re
from pathlib import Path

from setuptools import find_packages, setup

package_name = 'mindgrasp_launch'
package_xml = (Path(__file__).resolve().parent / 'package.xml').read_text(encoding='utf-8')

setup(
    packages=find_packages(exclude=['test']),
    data_files=[('share/ament_index/resource_index/packages', ['resource/' + package_name]),
                ('share/' + package_name, ['package.xml'])],
    # one description: package.xml's
    description=re.search(r'<description>(.*?)</description>', package_xml, re.S).group(1),
    entry_points={
        # the mindgrasp command's launch command (add_arguments, main), as ros2launch registers
        # `ros2 launch` itself
        'mindgrasp.command': [
            'launch = mindgrasp_launch.commands.launch',
        ],
    },
)
