#include <memory>
#include <string>

#include "rclcpp/rclcpp.hpp"
#include "rig_camera/frame.hpp"

namespace rig_camera
{

using AdaptedFrame = rclcpp::TypeAdapter<Frame, sensor_msgs::msg::Image>;

// Publishes frames and a status line, both as custom types.
class Camera : public rclcpp::Node
{
public:
  Camera()
  : Node("camera")
  {
    image_pub_ = create_publisher<AdaptedFrame>("image_raw", rclcpp::SensorDataQoS());
    status_pub_ = create_publisher<std::string>("camera_status", 10);
  }

private:
  rclcpp::Publisher<AdaptedFrame>::SharedPtr image_pub_;
  rclcpp::Publisher<std::string>::SharedPtr status_pub_;
};

}  // namespace rig_camera

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<rig_camera::Camera>());
  rclcpp::shutdown();
  return 0;
}
