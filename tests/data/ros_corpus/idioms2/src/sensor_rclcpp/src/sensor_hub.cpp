#include "sensor_rclcpp/sensor_hub.hpp"

namespace sensor_rclcpp
{
SensorHub::SensorHub(const std::string & node_name)
: Node(node_name)
{
  node_handle_ = std::shared_ptr<rclcpp::Node>(this, [](rclcpp::Node *) {});
  imu_ = std::make_unique<ImuSensor>(node_handle_);
  sensors_.push_back(new Battery(node_handle_, "battery_state"));
  sensors_.push_back(new Battery(node_handle_, "aux/battery_state"));

  tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>(*this);
  static_broadcaster_ = std::make_shared<tf2_ros::StaticTransformBroadcaster>(this);
  tf_buffer_ = std::make_unique<tf2_ros::Buffer>(get_clock());
  tf_listener_ = std::make_shared<tf2_ros::TransformListener>(*tf_buffer_);
  params_ = std::make_shared<rclcpp::ParameterEventHandler>(this);
  camera_pub_ = image_transport::create_publisher(this, "camera/image");
  markers_ = std::make_unique<interactive_markers::InteractiveMarkerServer>("hub_markers", this);

  diagnostics_ = create_sub_node("diagnostics");
  diag_pub_ = diagnostics_->create_publisher<diagnostic_msgs::msg::DiagnosticArray>("status", 1);
  raw_pub_ = create_generic_publisher("raw_frames", "sensor_msgs/msg/CompressedImage", 5);
  text_pub_ = create_publisher<AdaptedText>("hub_text", 10);
  calibrate_server_ = rclcpp_action::create_server<Calibrate>(
    get_node_base_interface(), get_node_clock_interface(), get_node_logging_interface(),
    get_node_waitables_interface(), "calibrate",
    [](const rclcpp_action::GoalUUID &, std::shared_ptr<const Calibrate::Goal>) {
      return rclcpp_action::GoalResponse::ACCEPT_AND_EXECUTE;
    },
    [](std::shared_ptr<rclcpp_action::ServerGoalHandle<Calibrate>>) {
      return rclcpp_action::CancelResponse::ACCEPT;
    },
    [](std::shared_ptr<rclcpp_action::ServerGoalHandle<Calibrate>>) {});
  joint_sub_ = std::make_shared<message_filters::Subscriber<sensor_msgs::msg::JointState>>(
    this, "joint_states");
}
}  // namespace sensor_rclcpp
