#include <memory>
#include <rclcpp/rclcpp.hpp>
#include "twin_drive/odometer.hpp"
#include "twin_drive/wheel.hpp"

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::executors::SingleThreadedExecutor executor;
  auto left = std::make_shared<twin_drive::Wheel>("left_wheel", "left_axle");
  auto right = std::make_shared<twin_drive::Wheel>("right_wheel");
  auto odometer = std::make_shared<twin_drive::Odometer>();
  executor.add_node(left);
  executor.add_node(right);
  executor.add_node(odometer);
  executor.spin();
  rclcpp::shutdown();
  return 0;
}
