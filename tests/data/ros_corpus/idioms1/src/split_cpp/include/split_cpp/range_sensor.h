#ifndef SPLIT_CPP_RANGE_SENSOR_H
#define SPLIT_CPP_RANGE_SENSOR_H

#include <string>
#include <ros/ros.h>
#include <sensor_msgs/Range.h>
#include <std_msgs/UInt32.h>

#include "split_cpp/visibility.h"

namespace split_cpp {

// One ultrasonic ranger: publishes on the topic it is given, through the
// handle it is given (the node gives each ranger a namespaced handle).
class RangeSensor {
 public:
  SPLIT_CPP_PUBLIC
  RangeSensor(ros::NodeHandle& nh, const std::string& topic, const std::string& frame = "sonar");
  void publish(float range);

 private:
  ros::Publisher range_pub_;
  ros::Subscriber trigger_sub_;
  std::string frame_;
  void onTrigger(const std_msgs::UInt32ConstPtr& msg);
};

}  // namespace split_cpp

#endif
