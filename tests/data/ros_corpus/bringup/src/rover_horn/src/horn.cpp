#include "rclcpp/rclcpp.hpp"
#include "rclcpp_components/register_node_macro.hpp"
#include "std_msgs/msg/empty.hpp"

namespace rover_horn
{

class Horn : public rclcpp::Node
{
public:
  explicit Horn(const rclcpp::NodeOptions & options)
  : rclcpp::Node("horn", options)
  {
    sub_ = create_subscription<std_msgs::msg::Empty>("honk", 1, [](std_msgs::msg::Empty::ConstSharedPtr) {});
  }

private:
  rclcpp::Subscription<std_msgs::msg::Empty>::SharedPtr sub_;
};

}  // namespace rover_horn

RCLCPP_COMPONENTS_REGISTER_NODE(rover_horn::Horn)
