#include <string>

#include "pluginlib/class_list_macros.hpp"
#include "rig_core/layer.hpp"
#include "std_msgs/msg/bool.hpp"

namespace rig_layers
{

// Marks where the bumper touched, and says when it is cleared.
class BumperLayer : public rig_core::Layer
{
public:
  void configure(
    const rclcpp_lifecycle::LifecycleNode::WeakPtr & parent, const std::string & name) override
  {
    node_ = parent;
    name_ = name;
    auto node = node_.lock();
    sub_ = node->create_subscription<std_msgs::msg::Bool>(
      "bumper", 10, [](std_msgs::msg::Bool::ConstSharedPtr) {});
    cleared_pub_ = node->create_publisher<std_msgs::msg::Bool>("bumper_cleared", 1);
  }

  void reset() override {}

private:
  rclcpp_lifecycle::LifecycleNode::WeakPtr node_;
  std::string name_;
  rclcpp::Subscription<std_msgs::msg::Bool>::SharedPtr sub_;
  rclcpp::Publisher<std_msgs::msg::Bool>::SharedPtr cleared_pub_;
};

}  // namespace rig_layers

PLUGINLIB_EXPORT_CLASS(rig_layers::BumperLayer, rig_core::Layer)
