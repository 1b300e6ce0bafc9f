"""mindgrasp_cli: the ``mindgrasp`` command of MIndGrasp-ROS, as ``ros2cli`` is ``ros2``: the
command line that finds every package's commands and verbs by their entry points, and the
graph verbs (``topic``, ``node``, ``param``, ``service``, ``interface``, ``run``)."""
