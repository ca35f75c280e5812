#include <memory>

#include "nav_msgs/msg/occupancy_grid.hpp"
#include "rover/core/pose_relay.hpp"
#include "rover_core/managed_node.hpp"

namespace rover_map
{

class MapServer : public rover_core::ManagedNode
{
public:
  explicit MapServer(const rclcpp::NodeOptions & options = rclcpp::NodeOptions())
  : rover_core::ManagedNode("map_server", options)
  {
  }

  rover_core::CallbackReturn on_configure(const rclcpp_lifecycle::State &) override
  {
    map_pub_ = create_publisher<nav_msgs::msg::OccupancyGrid>(
      "map", rclcpp::QoS(1).transient_local().reliable());
    relay_ = std::make_unique<rover::core::PoseRelay>(this, "initialpose", "map_origin");
    return rover_core::CallbackReturn::SUCCESS;
  }

private:
  rclcpp_lifecycle::LifecyclePublisher<nav_msgs::msg::OccupancyGrid>::SharedPtr map_pub_;
  std::unique_ptr<rover::core::PoseRelay> relay_;
};

}  // namespace rover_map

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = std::make_shared<rover_map::MapServer>();
  rclcpp::spin(node->get_node_base_interface());
  rclcpp::shutdown();
  return 0;
}
