#include "twin_drive/odometer.hpp"

using namespace twin_drive;

Odometer::Odometer()
: Node("odometer")
{
  odom_pub_ = create_publisher<nav_msgs::msg::Odometry>("odom", 10);
  tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>(*this);
}
