#include "rover_driver/imu_sensor.h"

namespace rover_driver {

ImuSensor::ImuSensor(ros::NodeHandle& nh, std::shared_ptr<SerialLink> link, const std::string& topic,
                     const std::string& frame_id)
    : link_(link), frame_id_(frame_id) {
  imu_pub_ = nh.advertise<sensor_msgs::Imu>(topic, 50);
}

void ImuSensor::poll() {
  std::vector<uint8_t> reply;
  if (!link_->request(0x30, {}, reply)) {
    return;
  }
  sensor_msgs::Imu imu;
  imu.header.stamp = ros::Time::now();
  imu.header.frame_id = frame_id_;
  imu_pub_.publish(imu);
}

}  // namespace rover_driver
