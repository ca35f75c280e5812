// Republishes the pose it hears under another name; installed from include/rover/core.
#ifndef ROVER__CORE__POSE_RELAY_HPP_
#define ROVER__CORE__POSE_RELAY_HPP_

#include <string>

#include "geometry_msgs/msg/pose_stamped.hpp"
#include "rclcpp_lifecycle/lifecycle_node.hpp"

namespace rover
{
namespace core
{

class PoseRelay
{
public:
  PoseRelay(rclcpp_lifecycle::LifecycleNode * node, const std::string & from, const std::string & to)
  {
    pub_ = node->create_publisher<geometry_msgs::msg::PoseStamped>(to, 1);
    sub_ = node->create_subscription<geometry_msgs::msg::PoseStamped>(
      from, 1, [this](geometry_msgs::msg::PoseStamped::ConstSharedPtr msg) {pub_->publish(*msg);});
  }

private:
  rclcpp_lifecycle::LifecyclePublisher<geometry_msgs::msg::PoseStamped>::SharedPtr pub_;
  rclcpp::Subscription<geometry_msgs::msg::PoseStamped>::SharedPtr sub_;
};

}  // namespace core
}  // namespace rover

#endif  // ROVER__CORE__POSE_RELAY_HPP_
