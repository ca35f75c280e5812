#include <memory>
#include <string>

#include <geometry_msgs/msg/point_stamped.hpp>
#include <image_transport/image_transport.hpp>
#include <rclcpp/rclcpp.hpp>
#include <rclcpp_components/register_node_macro.hpp>

namespace cam_proc
{
class Undistort : public rclcpp::Node
{
public:
  explicit Undistort(const rclcpp::NodeOptions & options)
  : rclcpp::Node("undistort", options)
  {
    auto base = get_node_base_interface();
    input_ = base->resolve_topic_or_service_name("camera/image_raw", false);
    std::string output = base->resolve_topic_or_service_name("camera/image_rect", false);

    rclcpp::PublisherOptions pub_options;
    pub_options.event_callbacks.matched_callback = [this](rclcpp::MatchedInfo &) {
        if (!sub_) {
          sub_ = image_transport::create_camera_subscription(
            this, input_, [this](auto image, auto info) {onImage(image, info);}, "raw");
        }
      };
    pub_ = image_transport::create_publisher(this, output, rmw_qos_profile_default, pub_options);
    target_ = create_publisher<geometry_msgs::msg::PointStamped>("target", 10);
  }

private:
  void onImage(
    const sensor_msgs::msg::Image::ConstSharedPtr &,
    const sensor_msgs::msg::CameraInfo::ConstSharedPtr &) {}

  std::string input_;
  image_transport::CameraSubscriber sub_;
  image_transport::Publisher pub_;
  rclcpp::Publisher<geometry_msgs::msg::PointStamped>::SharedPtr target_;
};
}  // namespace cam_proc

RCLCPP_COMPONENTS_REGISTER_NODE(cam_proc::Undistort)
