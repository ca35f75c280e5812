#ifndef ROVER_DRIVER_ODOMETRY_H
#define ROVER_DRIVER_ODOMETRY_H

#include <string>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rover_driver/WheelTicks.h>
#include <tf2_ros/transform_broadcaster.h>

namespace rover_driver {

// Dead reckoning from the wheel ticks: the odometry topic and the
// odom -> base_link transform.
class Odometry {
 public:
  Odometry(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  void reset();

 private:
  void onTicks(const rover_driver::WheelTicksConstPtr& ticks);

  std::string odom_frame_;
  std::string base_frame_;
  ros::Subscriber ticks_sub_;
  ros::Publisher odom_pub_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  double x_{0.0}, y_{0.0}, theta_{0.0};
};

}  // namespace rover_driver

#endif
