"""mindgrasp_bringup: the launch files and profiles of MIndGrasp-ROS, replay, calibration sessions
and the Foxglove live view."""
