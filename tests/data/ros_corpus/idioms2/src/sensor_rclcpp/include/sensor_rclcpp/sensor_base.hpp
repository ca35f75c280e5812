#ifndef SENSOR_RCLCPP__SENSOR_BASE_HPP_
#define SENSOR_RCLCPP__SENSOR_BASE_HPP_

#include <string>
#include <rclcpp/rclcpp.hpp>

namespace sensor_rclcpp
{
// What every sensor keeps: the node it publishes through and its frame.
class SensorBase
{
public:
  SensorBase(rclcpp::Node::SharedPtr node, const std::string & frame_id)
  : node_(node), frame_id_(frame_id) {}
  virtual ~SensorBase() = default;

protected:
  rclcpp::Node::SharedPtr node_;
  std::string frame_id_;
};
}  // namespace sensor_rclcpp

#endif  // SENSOR_RCLCPP__SENSOR_BASE_HPP_
