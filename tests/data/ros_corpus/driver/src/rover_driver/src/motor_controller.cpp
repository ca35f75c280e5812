#include "rover_driver/motor_controller.h"

namespace rover_driver {

MotorController::MotorController(ros::NodeHandle nh, std::shared_ptr<SerialLink> link, double wheel_separation)
    : nh_(nh), link_(link), wheel_separation_(wheel_separation) {
  cmd_sub_ = nh_.subscribe("cmd_vel", 10, &MotorController::onCommand, this);
  ticks_pub_ = nh_.advertise<rover_driver::WheelTicks>("wheel_ticks", 20);
}

void MotorController::onCommand(const geometry_msgs::Twist::ConstPtr& cmd) {
  if (!enabled_) {
    return;
  }
  const double left = cmd->linear.x - cmd->angular.z * wheel_separation_ / 2.0;
  const double right = cmd->linear.x + cmd->angular.z * wheel_separation_ / 2.0;
  std::vector<uint8_t> reply;
  link_->request(0x10, {static_cast<uint8_t>(left * 100), static_cast<uint8_t>(right * 100)}, reply);
}

void MotorController::poll() {
  std::vector<uint8_t> reply;
  if (!link_->request(0x20, {}, reply) || reply.size() < 8) {
    return;
  }
  rover_driver::WheelTicks ticks;
  ticks.header.stamp = ros::Time::now();
  ticks.left = reply[0] | reply[1] << 8 | reply[2] << 16 | reply[3] << 24;
  ticks.right = reply[4] | reply[5] << 8 | reply[6] << 16 | reply[7] << 24;
  ticks_pub_.publish(ticks);
}

}  // namespace rover_driver
