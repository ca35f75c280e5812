"""The live monitor's rclpy source: the robot heard through the ROS client
library, on whatever middleware it runs (docs/ros2.md, "Two sources")."""
