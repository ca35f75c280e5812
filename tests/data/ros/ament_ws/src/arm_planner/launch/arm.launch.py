"""The test arm: planner and driver in the arm's namespace."""
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction, IncludeLaunchDescription
from launch.launch_description_sources import AnyLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, PushRosNamespace


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('arm', default_value='arm'),
        GroupAction([
            PushRosNamespace(LaunchConfiguration('arm')),
            Node(package='arm_planner', executable='planner', name='planner',
                 remappings=[('joint_states', '/robot/joint_states')]),
            IncludeLaunchDescription(
                AnyLaunchDescriptionSource(os.path.join(
                    get_package_share_directory('arm_driver'), 'launch', 'driver.launch.xml')),
                launch_arguments={'states': '/robot/joint_states'}.items()),
        ]),
    ])
