"""The mindgrasp command's own verbs: the ROS graph (topic, node, param, service, interface) and
``run``, registered in this package's setup.py."""
