#ifndef ROVER_DRIVE__DRIVE_SERVER_HPP_
#define ROVER_DRIVE__DRIVE_SERVER_HPP_

#include <memory>

#include "geometry_msgs/msg/twist.hpp"
#include "nav_msgs/msg/odometry.hpp"
#include "rover_core/managed_node.hpp"
#include "rover_msgs/action/dock.hpp"
#include "rover_msgs/action/drive_to.hpp"
#include "tf2_ros/buffer.h"
#include "tf2_ros/transform_listener.h"

namespace rover_drive
{

class DriveServer : public rover_core::ManagedNode
{
public:
  explicit DriveServer(const rclcpp::NodeOptions & options = rclcpp::NodeOptions());

  rover_core::CallbackReturn on_configure(const rclcpp_lifecycle::State & state) override;

private:
  using ActionT = rover_msgs::action::DriveTo;

  void step();

  rclcpp_lifecycle::LifecyclePublisher<geometry_msgs::msg::Twist>::SharedPtr cmd_pub_;
  rclcpp::Subscription<nav_msgs::msg::Odometry>::SharedPtr odom_sub_;
  rover_core::ActionHost<ActionT>::SharedPtr drive_;
  rclcpp_action::Client<rover_msgs::action::Dock>::SharedPtr dock_client_;
  std::shared_ptr<tf2_ros::Buffer> tf_buffer_;
  std::shared_ptr<tf2_ros::TransformListener> tf_listener_;
};

}  // namespace rover_drive

#endif  // ROVER_DRIVE__DRIVE_SERVER_HPP_
