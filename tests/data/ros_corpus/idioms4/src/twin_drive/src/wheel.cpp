#include "twin_drive/wheel.hpp"

using twin_drive::Wheel;

Wheel::Wheel(const std::string & name, const std::string & joint)
: Node(name)
{
  speed_pub_ = create_publisher<std_msgs::msg::Float64>(joint + "/speed", 10);
  command_sub_ = create_subscription<std_msgs::msg::Float64>(
    "~/command", 10, [this](std_msgs::msg::Float64::SharedPtr msg) {(void)msg;});
  stop_srv_ = create_service<std_srvs::srv::Trigger>(
    "stop",
    [](const std::shared_ptr<std_srvs::srv::Trigger::Request>,
    std::shared_ptr<std_srvs::srv::Trigger::Response> res) {res->success = true;});
}
