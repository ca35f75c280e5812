#ifndef SENSOR_RCLCPP__BATTERY_HPP_
#define SENSOR_RCLCPP__BATTERY_HPP_

#include <string>
#include <sensor_msgs/msg/battery_state.hpp>
#include "sensor_rclcpp/sensor_base.hpp"

namespace sensor_rclcpp
{
class Battery : public SensorBase
{
public:
  Battery(rclcpp::Node::SharedPtr node, const std::string & topic);

private:
  rclcpp::Publisher<sensor_msgs::msg::BatteryState>::SharedPtr pub_;
};
}  // namespace sensor_rclcpp

#endif  // SENSOR_RCLCPP__BATTERY_HPP_
