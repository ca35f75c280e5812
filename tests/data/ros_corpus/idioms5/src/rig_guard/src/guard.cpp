#include "rig_guard/guard.hpp"

#include <functional>
#include <memory>

namespace rig_guard
{

Guard::Guard(const rclcpp::NodeOptions & options)
: rig_util::LifecycleNode("guard", "", options)
{
}

Guard::CallbackReturn Guard::on_configure(const rclcpp_lifecycle::State &)
{
  tf_buffer_ = std::make_shared<tf2_ros::Buffer>(get_clock());
  tf_listener_ = std::make_shared<tf2_ros::TransformListener>(*tf_buffer_);
  stop_pub_ = create_publisher<std_msgs::msg::Bool>("stop", 1);
  scan_sub_ = create_subscription<sensor_msgs::msg::LaserScan>(
    "scan", rclcpp::SensorDataQoS(),
    std::bind(&Guard::scanCallback, this, std::placeholders::_1));
  return CallbackReturn::SUCCESS;
}

Guard::CallbackReturn Guard::on_activate(const rclcpp_lifecycle::State &)
{
  stop_pub_->on_activate();
  createBond();
  return CallbackReturn::SUCCESS;
}

void Guard::scanCallback(sensor_msgs::msg::LaserScan::ConstSharedPtr)
{
}

}  // namespace rig_guard
