#ifndef RIG_GUARD__GUARD_HPP_
#define RIG_GUARD__GUARD_HPP_

#include <memory>

#include "rig_util/lifecycle_node.hpp"
#include "sensor_msgs/msg/laser_scan.hpp"
#include "std_msgs/msg/bool.hpp"
#include "tf2_ros/buffer.h"
#include "tf2_ros/transform_listener.h"

namespace rig_guard
{

// Stops the rig when the scan sees an obstacle.
class Guard : public rig_util::LifecycleNode
{
public:
  explicit Guard(const rclcpp::NodeOptions & options = rclcpp::NodeOptions());

protected:
  CallbackReturn on_configure(const rclcpp_lifecycle::State & state) override;
  CallbackReturn on_activate(const rclcpp_lifecycle::State & state) override;
  void scanCallback(sensor_msgs::msg::LaserScan::ConstSharedPtr msg);

  rclcpp::Subscription<sensor_msgs::msg::LaserScan>::SharedPtr scan_sub_;
  rclcpp_lifecycle::LifecyclePublisher<std_msgs::msg::Bool>::SharedPtr stop_pub_;
  std::shared_ptr<tf2_ros::Buffer> tf_buffer_;
  std::shared_ptr<tf2_ros::TransformListener> tf_listener_;
};

}  // namespace rig_guard

#endif  // RIG_GUARD__GUARD_HPP_
