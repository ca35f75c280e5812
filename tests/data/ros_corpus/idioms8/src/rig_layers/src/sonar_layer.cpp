#include <string>

#include "pluginlib/class_list_macros.hpp"
#include "rig_core/layer.hpp"
#include "sensor_msgs/msg/range.hpp"

namespace rig_layers
{

// Marks what the sonar ring sees. No parameter file of the workspace loads
// it: which node runs it is decided at run time.
class SonarLayer : public rig_core::Layer
{
public:
  void configure(
    const rclcpp_lifecycle::LifecycleNode::WeakPtr & parent, const std::string & name) override
  {
    auto node = parent.lock();
    sub_ = node->create_subscription<sensor_msgs::msg::Range>(
      "sonar", rclcpp::SensorDataQoS(), [](sensor_msgs::msg::Range::ConstSharedPtr) {});
    (void)name;
  }

  void reset() override {}

private:
  rclcpp::Subscription<sensor_msgs::msg::Range>::SharedPtr sub_;
};

}  // namespace rig_layers

PLUGINLIB_EXPORT_CLASS(rig_layers::SonarLayer, rig_core::Layer)
