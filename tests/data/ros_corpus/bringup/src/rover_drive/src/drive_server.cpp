#include "rover_drive/drive_server.hpp"

namespace rover_drive
{

DriveServer::DriveServer(const rclcpp::NodeOptions & options)
: rover_core::ManagedNode("drive_server", options)
{
}

rover_core::CallbackReturn DriveServer::on_configure(const rclcpp_lifecycle::State &)
{
  tf_buffer_ = std::make_shared<tf2_ros::Buffer>(get_clock());
  tf_listener_ = std::make_shared<tf2_ros::TransformListener>(*tf_buffer_);
  cmd_pub_ = create_publisher<geometry_msgs::msg::Twist>("cmd_vel", 1);
  odom_sub_ = create_subscription<nav_msgs::msg::Odometry>(
    "odom", 10, [](nav_msgs::msg::Odometry::ConstSharedPtr) {});
  drive_ = create_action_server<ActionT>(
    "drive_to",
    [this]() {step();});
  dock_client_ = create_action_client<rover_msgs::action::Dock>("dock");
  return rover_core::CallbackReturn::SUCCESS;
}

void DriveServer::step()
{
  cmd_pub_->publish(geometry_msgs::msg::Twist());
}

}  // namespace rover_drive

#include "rclcpp_components/register_node_macro.hpp"
RCLCPP_COMPONENTS_REGISTER_NODE(rover_drive::DriveServer)
