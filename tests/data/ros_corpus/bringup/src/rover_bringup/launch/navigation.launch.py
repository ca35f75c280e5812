"""The rover's servers, each its own process or all composed in one container."""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction
from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration, PythonExpression
from launch_ros.actions import LoadComposableNodes, Node, PushROSNamespace
from launch_ros.descriptions import ComposableNode, ParameterFile

# tf is published under the robot's namespace
TF_REMAPS = [('/tf', 'tf'), ('/tf_static', 'tf_static')]


def generate_launch_description():
    namespace = LaunchConfiguration('namespace')
    use_composition = LaunchConfiguration('use_composition')
    params = ParameterFile(LaunchConfiguration('params_file'), allow_substs=True)
    remappings = TF_REMAPS + [('scan', 'scan_filtered')]
    drive_remaps = remappings + [('cmd_vel', 'cmd_vel_raw')]
    dock_name = 'dock'
    tuning = {'speed_limit': '0.5', 'frames': ['odom', 'base_link']}
    container = (namespace, '/', 'rover_container')

    standalone = GroupAction(
        condition=IfCondition(PythonExpression(['not ', use_composition])),
        actions=[
            PushROSNamespace(namespace=namespace),
            Node(
                package='rover_drive',
                executable='drive_server',
                output='screen',
                parameters=[params, tuning],
                remappings=drive_remaps,
            ),
            Node(
                package='rover_dock',
                executable='rover_dock',
                name=dock_name,
                parameters=[params],
                remappings=remappings,
            ),
        ],
    )

    composed = GroupAction(
        condition=IfCondition(use_composition),
        actions=[
            PushROSNamespace(namespace=namespace),
            LoadComposableNodes(
                target_container=container,
                composable_node_descriptions=[
                    ComposableNode(
                        package='rover_drive',
                        plugin='rover_drive::DriveServer',
                        name='drive_server',
                        parameters=[params, tuning],
                        remappings=drive_remaps,
                    ),
                    ComposableNode(
                        package='rover_dock',
                        plugin='rover_dock::DockServer',
                        name=dock_name,
                        parameters=[params],
                        remappings=remappings,
                    ),
                ],
            ),
        ],
    )

    ld = LaunchDescription()
    ld.add_action(DeclareLaunchArgument('namespace', default_value='rover'))
    ld.add_action(DeclareLaunchArgument('use_composition', default_value='False'))
    ld.add_action(DeclareLaunchArgument('params_file', default_value='rover.yaml'))
    ld.add_action(standalone)
    ld.add_action(composed)
    return ld
