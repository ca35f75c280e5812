#include "rover_driver/rover_driver.h"

namespace rover_driver {

RoverDriver::RoverDriver(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  std::string port;
  int baud;
  double wheel_separation;
  pnh.param<std::string>("port", port, "/dev/ttyUSB0");
  pnh.param("baud", baud, 115200);
  pnh.param("wheel_separation", wheel_separation, 0.32);
  pnh.param("rate", rate_hz_, 50.0);
  std::string imu_topic;
  pnh.param<std::string>("imu_topic", imu_topic, "imu/data");

  link_ = std::make_shared<SerialLink>(port, baud);
  if (!link_->open()) {
    ROS_FATAL("cannot open %s", port.c_str());
  }
  motors_ = std::make_unique<MotorController>(ros::NodeHandle(nh, "base"), link_, wheel_separation);
  imu_ = std::make_unique<ImuSensor>(nh, link_, imu_topic);
  battery_ = std::make_unique<BatteryMonitor>(nh, link_, "battery");
  odometry_ = std::make_unique<Odometry>(nh, pnh);

  enable_srv_ = pnh.advertiseService("enable_motors", &RoverDriver::onEnableMotors, this);
  reset_srv_ = nh.advertiseService("reset_odometry", &RoverDriver::onResetOdometry, this);
}

bool RoverDriver::onEnableMotors(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
  motors_->enable(req.data);
  res.success = true;
  return true;
}

bool RoverDriver::onResetOdometry(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res) {
  odometry_->reset();
  res.success = true;
  return true;
}

void RoverDriver::spin() {
  ros::Rate rate(rate_hz_);
  while (ros::ok()) {
    motors_->poll();
    imu_->poll();
    battery_->poll();
    ros::spinOnce();
    rate.sleep();
  }
}

}  // namespace rover_driver
