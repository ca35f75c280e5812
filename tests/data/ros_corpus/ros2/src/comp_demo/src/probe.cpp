// A plain executable: rclcpp::Node::make_shared and a node pointer receiver.
#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/bool.hpp>

int main(int argc, char** argv) {
  rclcpp::init(argc, argv);
  auto node = rclcpp::Node::make_shared("probe");
  auto alive = node->create_publisher<std_msgs::msg::Bool>("probe/alive", 1);
  auto relayed = node->create_subscription<std_msgs::msg::String>(
      "relayed", 10, [](std_msgs::msg::String::ConstSharedPtr) {});
  rclcpp::spin(node);
  rclcpp::shutdown();
  return 0;
}
