#ifndef RIG_UTIL__ODOM_SMOOTHER_HPP_
#define RIG_UTIL__ODOM_SMOOTHER_HPP_

#include <string>

#include "nav_msgs/msg/odometry.hpp"
#include "rclcpp_lifecycle/lifecycle_node.hpp"

namespace rig_util
{

// Averages the odometry of the last filter_duration seconds.
class OdomSmoother
{
public:
  explicit OdomSmoother(
    const rclcpp_lifecycle::LifecycleNode::WeakPtr & parent,
    double filter_duration = 0.3,
    const std::string & odom_topic = "odom");

protected:
  void odomCallback(const nav_msgs::msg::Odometry::SharedPtr msg);
  rclcpp::Subscription<nav_msgs::msg::Odometry>::SharedPtr odom_sub_;
  double filter_duration_;
};

}  // namespace rig_util

#endif  // RIG_UTIL__ODOM_SMOOTHER_HPP_
