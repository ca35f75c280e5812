#include <memory>
#include "sensor_rclcpp/sensor_hub.hpp"

static constexpr char kNodeName[] = "sensor_hub";

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<sensor_rclcpp::SensorHub>(kNodeName));
  rclcpp::shutdown();
  return 0;
}
