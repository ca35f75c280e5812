#ifndef ROVER_DRIVER_BATTERY_MONITOR_H
#define ROVER_DRIVER_BATTERY_MONITOR_H

#include <memory>
#include <string>

#include <ros/ros.h>
#include <sensor_msgs/BatteryState.h>

#include "rover_driver/serial_link.h"

namespace rover_driver {

class BatteryMonitor {
 public:
  BatteryMonitor(ros::NodeHandle& nh, std::shared_ptr<SerialLink> link, const std::string& topic);
  void poll();

 private:
  std::shared_ptr<SerialLink> link_;
  ros::Publisher battery_pub_;
};

}  // namespace rover_driver

#endif
