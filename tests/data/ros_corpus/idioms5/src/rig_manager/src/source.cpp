#include "source.hpp"

namespace rig_manager
{

Source::Source(rclcpp::Node * node, const std::string & source_name)
: node_(node), source_name_(source_name)
{
  std::string source_topic;
  getParameters(source_topic);
  sub_ = node_->create_subscription<sensor_msgs::msg::LaserScan>(
    source_topic, rclcpp::SensorDataQoS(), [](sensor_msgs::msg::LaserScan::ConstSharedPtr) {});
}

void Source::getParameters(std::string & source_topic)
{
  node_->declare_parameter(source_name_ + ".topic", rclcpp::ParameterValue("scan"));
  node_->get_parameter(source_name_ + ".topic", source_topic);
}

}  // namespace rig_manager
