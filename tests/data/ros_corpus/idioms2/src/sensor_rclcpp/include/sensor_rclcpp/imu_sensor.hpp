#ifndef SENSOR_RCLCPP__IMU_SENSOR_HPP_
#define SENSOR_RCLCPP__IMU_SENSOR_HPP_

#include <string>
#include <rclcpp/rclcpp.hpp>
#include <sensor_msgs/msg/imu.hpp>
#include <sensor_msgs/msg/magnetic_field.hpp>

namespace sensor_rclcpp
{
class ImuSensor
{
public:
  explicit ImuSensor(
    rclcpp::Node::SharedPtr node,
    const std::string & imu_topic = "imu/data",
    const std::string & mag_topic = "imu/mag");

private:
  rclcpp::Publisher<sensor_msgs::msg::Imu>::SharedPtr imu_pub_;
  rclcpp::Publisher<sensor_msgs::msg::MagneticField>::SharedPtr mag_pub_;
};
}  // namespace sensor_rclcpp

#endif  // SENSOR_RCLCPP__IMU_SENSOR_HPP_
