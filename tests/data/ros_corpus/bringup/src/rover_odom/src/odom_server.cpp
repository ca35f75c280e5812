#include <memory>
#include <string>

#include "nav_msgs/msg/odometry.hpp"
#include "rover_core/managed_node.hpp"

namespace rover_odom
{

// A node of its own inside the server's process.
class Odometer : public rover_core::ManagedNode
{
public:
  explicit Odometer(const rclcpp::NodeOptions & options = rclcpp::NodeOptions())
  : rover_core::ManagedNode("odometer", options)
  {
    odom_pub_ = create_publisher<nav_msgs::msg::Odometry>("odom", 10);
  }

  Odometer(const std::string & name, const rclcpp::NodeOptions & options)
  : rover_core::ManagedNode(name, options)
  {
    odom_pub_ = create_publisher<nav_msgs::msg::Odometry>("odom", 10);
  }

private:
  rclcpp_lifecycle::LifecyclePublisher<nav_msgs::msg::Odometry>::SharedPtr odom_pub_;
};

// Reads the odometer it is lent; makes nothing.
class OdomReport
{
public:
  explicit OdomReport(Odometer & odometer)
  : odometer_(odometer)
  {
  }

private:
  Odometer & odometer_;
};

class OdomServer : public rover_core::ManagedNode
{
public:
  OdomServer()
  : rover_core::ManagedNode("odom_server")
  {
    odometer_ = std::make_shared<Odometer>("wheel_odometer", rclcpp::NodeOptions());
    report_ = std::make_unique<OdomReport>(*odometer_);
  }

private:
  std::shared_ptr<Odometer> odometer_;
  std::unique_ptr<OdomReport> report_;
};

}  // namespace rover_odom

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = std::make_shared<rover_odom::OdomServer>();
  rclcpp::spin(node->get_node_base_interface());
  rclcpp::shutdown();
  return 0;
}
