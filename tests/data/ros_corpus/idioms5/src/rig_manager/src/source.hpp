#ifndef RIG_MANAGER__SOURCE_HPP_
#define RIG_MANAGER__SOURCE_HPP_

#include <string>

#include "rclcpp/rclcpp.hpp"
#include "sensor_msgs/msg/laser_scan.hpp"

namespace rig_manager
{

// One range source; its topic is the parameter "<source name>.topic".
class Source
{
public:
  Source(rclcpp::Node * node, const std::string & source_name);

protected:
  void getParameters(std::string & source_topic);

  rclcpp::Node * node_;
  std::string source_name_;
  rclcpp::Subscription<sensor_msgs::msg::LaserScan>::SharedPtr sub_;
};

}  // namespace rig_manager

#endif  // RIG_MANAGER__SOURCE_HPP_
