#include <memory>
#include <string>
#include <vector>

#include "nav_msgs/msg/occupancy_grid.hpp"
#include "pluginlib/class_loader.hpp"
#include "rclcpp_lifecycle/lifecycle_node.hpp"
#include "rig_core/layer.hpp"

// Builds the rig's map from the layers its parameter "layers" lists; each
// listed name's "<name>.plugin" parameter says which class to load.
class Mapper : public rclcpp_lifecycle::LifecycleNode
{
public:
  Mapper()
  : rclcpp_lifecycle::LifecycleNode("mapper"),
    loader_("rig_core", "rig_core::Layer")
  {
    map_pub_ = create_publisher<nav_msgs::msg::OccupancyGrid>("map", rclcpp::QoS(1).transient_local());
  }

  CallbackReturn on_configure(const rclcpp_lifecycle::State &) override
  {
    declare_parameter("layers", std::vector<std::string>{});
    for (const std::string & name : get_parameter("layers").as_string_array()) {
      declare_parameter(name + ".plugin", std::string(""));
      std::string type = get_parameter(name + ".plugin").as_string();
      std::shared_ptr<rig_core::Layer> layer = loader_.createSharedInstance(type);
      layer->configure(shared_from_this(), name);
      layers_.push_back(layer);
    }
    return CallbackReturn::SUCCESS;
  }

private:
  pluginlib::ClassLoader<rig_core::Layer> loader_;
  std::vector<std::shared_ptr<rig_core::Layer>> layers_;
  rclcpp_lifecycle::LifecyclePublisher<nav_msgs::msg::OccupancyGrid>::SharedPtr map_pub_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = std::make_shared<Mapper>();
  rclcpp::spin(node->get_node_base_interface());
  rclcpp::shutdown();
  return 0;
}
