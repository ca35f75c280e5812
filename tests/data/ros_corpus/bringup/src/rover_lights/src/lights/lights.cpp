#include <memory>

#include "rclcpp/rclcpp.hpp"
#include "rclcpp_components/register_node_macro.hpp"
#include "std_msgs/msg/bool.hpp"

namespace rover_lights
{

class Lights : public rclcpp::Node
{
public:
  explicit Lights(const rclcpp::NodeOptions & options)
  : rclcpp::Node("lights", options)
  {
    sub_ = create_subscription<std_msgs::msg::Bool>(
      "headlights", 1, [](std_msgs::msg::Bool::ConstSharedPtr) {});
  }

private:
  rclcpp::Subscription<std_msgs::msg::Bool>::SharedPtr sub_;
};

}  // namespace rover_lights

RCLCPP_COMPONENTS_REGISTER_NODE(rover_lights::Lights)
