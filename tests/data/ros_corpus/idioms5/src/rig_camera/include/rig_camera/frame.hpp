#ifndef RIG_CAMERA__FRAME_HPP_
#define RIG_CAMERA__FRAME_HPP_

#include <string>
#include <vector>

#include "rclcpp/type_adapter.hpp"
#include "sensor_msgs/msg/image.hpp"
#include "std_msgs/msg/string.hpp"

namespace rig_camera
{

// The camera's own frame type, adapted to sensor_msgs/msg/Image.
struct Frame
{
  int width = 0;
  int height = 0;
  std::vector<unsigned char> pixels;
};

}  // namespace rig_camera

template<>
struct rclcpp::TypeAdapter<rig_camera::Frame, sensor_msgs::msg::Image>
{
  using is_specialized = std::true_type;
  using custom_type = rig_camera::Frame;
  using ros_message_type = sensor_msgs::msg::Image;
  static void convert_to_ros_message(const custom_type &, ros_message_type &) {}
  static void convert_to_custom(const ros_message_type &, custom_type &) {}
};

RCLCPP_USING_CUSTOM_TYPE_AS_ROS_MESSAGE_TYPE(std::string, std_msgs::msg::String);

#endif  // RIG_CAMERA__FRAME_HPP_
