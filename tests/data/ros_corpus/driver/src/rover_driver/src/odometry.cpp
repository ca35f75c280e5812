#include "rover_driver/odometry.h"

#include <geometry_msgs/TransformStamped.h>

namespace rover_driver {

Odometry::Odometry(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  pnh.param<std::string>("odom_frame", odom_frame_, "odom");
  pnh.param<std::string>("base_frame", base_frame_, "base_link");
  std::string odom_topic;
  pnh.param<std::string>("odom_topic", odom_topic, "odom");
  ticks_sub_ = nh.subscribe("base/wheel_ticks", 20, &Odometry::onTicks, this);
  odom_pub_ = nh.advertise<nav_msgs::Odometry>(odom_topic, 20);
}

void Odometry::reset() {
  x_ = y_ = theta_ = 0.0;
}

void Odometry::onTicks(const rover_driver::WheelTicksConstPtr& ticks) {
  nav_msgs::Odometry odom;
  odom.header.stamp = ticks->header.stamp;
  odom.header.frame_id = odom_frame_;
  odom.child_frame_id = base_frame_;
  odom.pose.pose.position.x = x_;
  odom.pose.pose.position.y = y_;
  odom_pub_.publish(odom);

  geometry_msgs::TransformStamped tf;
  tf.header = odom.header;
  tf.child_frame_id = base_frame_;
  tf.transform.translation.x = x_;
  tf.transform.translation.y = y_;
  tf.transform.rotation.w = 1.0;
  tf_broadcaster_.sendTransform(tf);
}

}  // namespace rover_driver
