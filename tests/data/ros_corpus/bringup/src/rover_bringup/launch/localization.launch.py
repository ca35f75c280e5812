"""The map server: an empty map, or the map file given as 'map'."""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction
from launch.conditions import IfCondition
from launch.substitutions import EqualsSubstitution, LaunchConfiguration, NotEqualsSubstitution
from launch_ros.actions import Node, PushROSNamespace


def generate_launch_description():
    namespace = LaunchConfiguration('namespace')
    map_yaml = LaunchConfiguration('map')
    remappings = [('/tf', 'tf'), ('/tf_static', 'tf_static')]

    return LaunchDescription([
        DeclareLaunchArgument('namespace', default_value='rover'),
        DeclareLaunchArgument('map', default_value=''),
        GroupAction([
            PushROSNamespace(namespace),
            Node(
                condition=IfCondition(EqualsSubstitution(LaunchConfiguration('map'), '')),
                package='rover_map',
                executable='map_server',
                name='map_server',
                remappings=remappings,
            ),
            Node(
                condition=IfCondition(NotEqualsSubstitution(LaunchConfiguration('map'), '')),
                package='rover_map',
                executable='map_server',
                name='map_server',
                parameters=[{'yaml_filename': map_yaml}],
                remappings=remappings + [('map', 'map_loaded')],
            ),
        ]),
    ])
