from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([
        # one process of three nodes, none renamed: each node is itself, in the namespace
        Node(package='twin_drive', executable='drive', namespace='rover'),
        Node(package='twin_drive', executable='brake', namespace='rover'),
        Node(package='twin_py', executable='tanks', namespace='rover'),
        Node(package='twin_py', executable='pump', name='main_pump', namespace='rover'),
    ])
