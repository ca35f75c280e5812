#ifndef ROVER_DRIVER_MOTOR_CONTROLLER_H
#define ROVER_DRIVER_MOTOR_CONTROLLER_H

#include <memory>

#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <rover_driver/WheelTicks.h>

#include "rover_driver/serial_link.h"

namespace rover_driver {

// Velocity commands in, encoder ticks out, under the handle it is given
// (the driver gives it the "base" namespace).
class MotorController {
 public:
  MotorController(ros::NodeHandle nh, std::shared_ptr<SerialLink> link, double wheel_separation);
  void poll();
  bool enabled() const { return enabled_; }
  void enable(bool on) { enabled_ = on; }

 private:
  void onCommand(const geometry_msgs::Twist::ConstPtr& cmd);

  ros::NodeHandle nh_;
  std::shared_ptr<SerialLink> link_;
  double wheel_separation_;
  bool enabled_{false};
  ros::Subscriber cmd_sub_;
  ros::Publisher ticks_pub_;
};

}  // namespace rover_driver

#endif
