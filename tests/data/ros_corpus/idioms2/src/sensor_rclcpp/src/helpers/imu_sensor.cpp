#include "sensor_rclcpp/imu_sensor.hpp"

namespace sensor_rclcpp
{
ImuSensor::ImuSensor(
  rclcpp::Node::SharedPtr node, const std::string & imu_topic, const std::string & mag_topic)
{
  imu_pub_ = node->create_publisher<sensor_msgs::msg::Imu>(imu_topic, rclcpp::SensorDataQoS());
  mag_pub_ = node->create_publisher<sensor_msgs::msg::MagneticField>(mag_topic, 10);
}
}  // namespace sensor_rclcpp
