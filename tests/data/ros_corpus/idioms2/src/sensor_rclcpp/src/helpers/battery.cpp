#include "sensor_rclcpp/battery.hpp"

#include <cinttypes>

namespace sensor_rclcpp
{
Battery::Battery(rclcpp::Node::SharedPtr node, const std::string & topic)
: SensorBase(node, "battery_link")
{
  pub_ = node_->create_publisher<sensor_msgs::msg::BatteryState>(topic, 10);
  RCLCPP_DEBUG(node_->get_logger(), "battery on %s, %" PRId64 " cells", topic.c_str(), int64_t{4});
}
}  // namespace sensor_rclcpp
