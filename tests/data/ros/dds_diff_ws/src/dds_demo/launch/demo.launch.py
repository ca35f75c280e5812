"""The demo system: the sensor and the planner."""
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([
        Node(package='dds_demo', executable='sensor', name='sensor'),
        Node(package='dds_demo', executable='planner', name='planner'),
    ])
