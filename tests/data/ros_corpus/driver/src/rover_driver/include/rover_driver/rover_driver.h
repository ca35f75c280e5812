#ifndef ROVER_DRIVER_ROVER_DRIVER_H
#define ROVER_DRIVER_ROVER_DRIVER_H

#include <memory>
#include <string>

#include <ros/ros.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>

#include "rover_driver/battery_monitor.h"
#include "rover_driver/imu_sensor.h"
#include "rover_driver/motor_controller.h"
#include "rover_driver/odometry.h"
#include "rover_driver/serial_link.h"

namespace rover_driver {

class RoverDriver {
 public:
  RoverDriver(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  void spin();

 private:
  bool onEnableMotors(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res);
  bool onResetOdometry(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);

  std::shared_ptr<SerialLink> link_;
  std::unique_ptr<MotorController> motors_;
  std::unique_ptr<ImuSensor> imu_;
  std::unique_ptr<BatteryMonitor> battery_;
  std::unique_ptr<Odometry> odometry_;
  ros::ServiceServer enable_srv_;
  ros::ServiceServer reset_srv_;
  double rate_hz_;
};

}  // namespace rover_driver

#endif
