"""ament_python package for colcon build; the root pyproject.toml also installs it.

Metadata and the data files (package.xml, the ament index marker) are in setup.cfg, the
description copied from package.xml; here only what the root setup.py reads too, the entry
points. The launch files, profiles and parameter files the launcher reads belong to
mindgrasp_bringup and the top-level config/.
"""

from setuptools import find_packages, setup

setup(
    packages=find_packages(exclude=['test']),
    entry_points={
        # the mindgrasp command's launch command (add_arguments, main), as ros2launch registers
        # `ros2 launch` itself
        'mindgrasp.command': [
            'launch = mindgrasp_launch.commands.launch',
        ],
    },
)
