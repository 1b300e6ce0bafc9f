"""mindgrasp_bringup: the ``mindgrasp`` command, the launcher, launch descriptions, bag tools and
experiments of MIndGrasp-ROS."""
