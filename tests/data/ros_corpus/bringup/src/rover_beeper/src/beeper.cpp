#include "rclcpp/rclcpp.hpp"
#include "std_msgs/msg/empty.hpp"
int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = rclcpp::Node::make_shared("beeper");
  auto pub = node->create_publisher<std_msgs::msg::Empty>("beep", 1);
  rclcpp::spin(node);
  return 0;
}
