#ifndef ROVER_DRIVER_IMU_SENSOR_H
#define ROVER_DRIVER_IMU_SENSOR_H

#include <memory>
#include <string>

#include <ros/ros.h>
#include <sensor_msgs/Imu.h>

#include "rover_driver/serial_link.h"

namespace rover_driver {

class ImuSensor {
 public:
  ImuSensor(ros::NodeHandle& nh, std::shared_ptr<SerialLink> link, const std::string& topic,
            const std::string& frame_id = "imu_link");
  void poll();

 private:
  std::shared_ptr<SerialLink> link_;
  std::string frame_id_;
  ros::Publisher imu_pub_;
};

}  // namespace rover_driver

#endif
