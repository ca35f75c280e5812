#ifndef TWIN_DRIVE__WHEEL_HPP_
#define TWIN_DRIVE__WHEEL_HPP_
#include <memory>
#include <string>
#include <rclcpp/rclcpp.hpp>
#include <std_msgs/msg/float64.hpp>
#include <std_srvs/srv/trigger.hpp>

namespace twin_drive
{
class Wheel : public rclcpp::Node
{
public:
  explicit Wheel(const std::string & name, const std::string & joint = "axle");

private:
  rclcpp::Publisher<std_msgs::msg::Float64>::SharedPtr speed_pub_;
  rclcpp::Subscription<std_msgs::msg::Float64>::SharedPtr command_sub_;
  rclcpp::Service<std_srvs::srv::Trigger>::SharedPtr stop_srv_;
};
}  // namespace twin_drive
#endif  // TWIN_DRIVE__WHEEL_HPP_
