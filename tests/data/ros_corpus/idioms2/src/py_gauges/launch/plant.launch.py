from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, PushRosNamespace


def generate_launch_description():
    namespace = LaunchConfiguration('namespace')
    use_sim_time = LaunchConfiguration('use_sim_time', default='false')
    line = LaunchConfiguration('line', default='line2')

    declare_namespace = DeclareLaunchArgument('namespace', default_value='plant')
    declare_sim_time = DeclareLaunchArgument('use_sim_time', default_value=use_sim_time)

    first_gauge = Node(
        package='py_gauges',
        executable='gauge',
        name='boiler_gauge',
        namespace=namespace,
        remappings=[('temperature', 'probe/temperature')],
        parameters=[{'use_sim_time': use_sim_time}],
    )
    second_line = GroupAction([
        PushRosNamespace(line),
        Node(package='py_gauges', executable='gauge', name='gauge', namespace='cell'),
        Node(package='py_gauges', executable='gauge_panel', namespace='/panels'),
        Node(package='sensor_rclcpp', executable='sensor_hub'),
    ])
    return LaunchDescription([declare_namespace, declare_sim_time, first_gauge, second_line])
