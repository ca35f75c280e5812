#ifndef TWIN_DRIVE__ODOMETER_HPP_
#define TWIN_DRIVE__ODOMETER_HPP_
#include <memory>
#include <nav_msgs/msg/odometry.hpp>
#include <rclcpp/rclcpp.hpp>
#include <tf2_ros/transform_broadcaster.h>

namespace twin_drive
{
class Odometer : public rclcpp::Node
{
public:
  Odometer();

private:
  rclcpp::Publisher<nav_msgs::msg::Odometry>::SharedPtr odom_pub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
};
}  // namespace twin_drive
#endif  // TWIN_DRIVE__ODOMETER_HPP_
