#ifndef SENSOR_RCLCPP__SENSOR_HUB_HPP_
#define SENSOR_RCLCPP__SENSOR_HUB_HPP_

#include <memory>
#include <string>
#include <vector>

#include <diagnostic_msgs/msg/diagnostic_array.hpp>
#include <image_transport/image_transport.hpp>
#include <interactive_markers/interactive_marker_server.hpp>
#include <message_filters/subscriber.h>
#include <rclcpp/rclcpp.hpp>
#include <rclcpp_action/rclcpp_action.hpp>
#include <sensor_msgs/msg/joint_state.hpp>
#include <std_msgs/msg/string.hpp>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include "sensor_rclcpp/action/calibrate.hpp"
#include "sensor_rclcpp/battery.hpp"
#include "sensor_rclcpp/imu_sensor.hpp"

namespace sensor_rclcpp
{
using AdaptedText = rclcpp::TypeAdapter<std::string, std_msgs::msg::String>;

class SensorHub : public rclcpp::Node
{
public:
  using Calibrate = sensor_rclcpp::action::Calibrate;
  explicit SensorHub(const std::string & node_name);

private:
  rclcpp::Node::SharedPtr node_handle_;
  std::unique_ptr<ImuSensor> imu_;
  std::vector<SensorBase *> sensors_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
  std::shared_ptr<tf2_ros::StaticTransformBroadcaster> static_broadcaster_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::shared_ptr<tf2_ros::TransformListener> tf_listener_;
  std::shared_ptr<rclcpp::ParameterEventHandler> params_;
  image_transport::Publisher camera_pub_;
  std::unique_ptr<interactive_markers::InteractiveMarkerServer> markers_;
  rclcpp::Node::SharedPtr diagnostics_;
  rclcpp::Publisher<diagnostic_msgs::msg::DiagnosticArray>::SharedPtr diag_pub_;
  rclcpp::GenericPublisher::SharedPtr raw_pub_;
  rclcpp::Publisher<AdaptedText>::SharedPtr text_pub_;
  rclcpp_action::Server<Calibrate>::SharedPtr calibrate_server_;
  std::shared_ptr<message_filters::Subscriber<sensor_msgs::msg::JointState>> joint_sub_;
};
}  // namespace sensor_rclcpp

#endif  // SENSOR_RCLCPP__SENSOR_HUB_HPP_
