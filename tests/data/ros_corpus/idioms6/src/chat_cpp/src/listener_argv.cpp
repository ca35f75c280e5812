#include <memory>

#include "rclcpp/rclcpp.hpp"
#include "std_msgs/msg/string.hpp"

// Listens to the topic given as its first command-line argument.
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = rclcpp::Node::make_shared("argv_listener");
  auto sub = node->create_subscription<std_msgs::msg::String>(
    argv[1], 10, [](std_msgs::msg::String::ConstSharedPtr) {});
  rclcpp::spin(node);
  rclcpp::shutdown();
  return 0;
}
