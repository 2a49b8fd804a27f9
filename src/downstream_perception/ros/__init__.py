"""The rospy side of the Python package: message builders, the costmap and mesh subscribers, and
process helpers for the demo, benchmarks and rostests. The rest of ``downstream_perception``
(the compiled core, the simulators, the evaluation) needs no ROS."""
