from launch import LaunchDescription
from launch_ros.actions import ComposableNodeContainer, Node
from launch_ros.descriptions import ComposableNode


def generate_launch_description():
    container = ComposableNodeContainer(
        name='demo_container',
        namespace='demo',
        package='rclcpp_components',
        executable='component_container',
        composable_node_descriptions=[
            ComposableNode(
                package='comp_demo',
                plugin='comp_demo::Relay',
                name='relay',
                namespace='demo',
                parameters=[{'output': 'chatter_out'}],
                remappings=[('input', 'chatter_in')],
            ),
        ],
    )
    return LaunchDescription([
        container,
        Node(package='comp_demo', executable='gauge', namespace='demo'),
        Node(package='comp_demo', executable='probe', namespace='demo',
             remappings=[('relayed', 'chatter_out')]),
    ])
