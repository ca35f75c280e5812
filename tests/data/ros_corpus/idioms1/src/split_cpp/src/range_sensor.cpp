#include "split_cpp/range_sensor.h"

#include <cinttypes>

namespace split_cpp {

RangeSensor::RangeSensor(ros::NodeHandle& nh, const std::string& topic, const std::string& frame)
    : frame_(frame) {
  range_pub_ = nh.advertise<sensor_msgs::Range>(topic, 5);
  trigger_sub_ = nh.subscribe("trigger", 1, &RangeSensor::onTrigger, this);
}

void RangeSensor::publish(float range) {
  sensor_msgs::Range msg;
  msg.header.frame_id = frame_;
  msg.range = range;
  range_pub_.publish(msg);
}

void RangeSensor::onTrigger(const std_msgs::UInt32ConstPtr& msg) {
  ROS_DEBUG("trigger %" PRIu32 " on %s", msg->data, frame_.c_str());
}

}  // namespace split_cpp
