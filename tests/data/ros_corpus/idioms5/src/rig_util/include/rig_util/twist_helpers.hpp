#ifndef RIG_UTIL__TWIST_HELPERS_HPP_
#define RIG_UTIL__TWIST_HELPERS_HPP_

#include <string>
#include <utility>

#include "geometry_msgs/msg/twist.hpp"
#include "rclcpp_lifecycle/lifecycle_node.hpp"

namespace rig_util
{

// Subscribes to velocity commands on the topic its owner names.
class TwistSubscriber
{
public:
  template<typename CallbackT>
  TwistSubscriber(
    const rclcpp_lifecycle::LifecycleNode::SharedPtr & node,
    const std::string & topic,
    CallbackT && callback)
  {
    sub_ = node->create_subscription<geometry_msgs::msg::Twist>(
      topic, rclcpp::SystemDefaultsQoS(), std::forward<CallbackT>(callback));
  }

protected:
  rclcpp::Subscription<geometry_msgs::msg::Twist>::SharedPtr sub_;
};

// Publishes velocity commands on the topic its owner names.
class TwistPublisher
{
public:
  TwistPublisher(
    const rclcpp_lifecycle::LifecycleNode::SharedPtr & node,
    const std::string & topic,
    const rclcpp::QoS & qos)
  {
    pub_ = node->create_publisher<geometry_msgs::msg::Twist>(topic, qos);
  }

protected:
  rclcpp_lifecycle::LifecyclePublisher<geometry_msgs::msg::Twist>::SharedPtr pub_;
};

}  // namespace rig_util

#endif  // RIG_UTIL__TWIST_HELPERS_HPP_
