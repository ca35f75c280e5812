#include "rig_util/odom_smoother.hpp"

#include <functional>

namespace rig_util
{

OdomSmoother::OdomSmoother(
  const rclcpp_lifecycle::LifecycleNode::WeakPtr & parent,
  double filter_duration,
  const std::string & odom_topic)
: filter_duration_(filter_duration)
{
  auto node = parent.lock();
  odom_sub_ = node->create_subscription<nav_msgs::msg::Odometry>(
    odom_topic, rclcpp::SensorDataQoS(),
    std::bind(&OdomSmoother::odomCallback, this, std::placeholders::_1));
}

void OdomSmoother::odomCallback(const nav_msgs::msg::Odometry::SharedPtr)
{
}

}  // namespace rig_util
