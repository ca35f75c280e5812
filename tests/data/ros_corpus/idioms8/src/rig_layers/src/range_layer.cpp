#include <string>

#include "pluginlib/class_list_macros.hpp"
#include "rig_core/layer.hpp"
#include "sensor_msgs/msg/range.hpp"

namespace rig_layers
{

// Marks what one range sensor sees. Its topic is the parameter
// "<layer name>.topic" of the node that loads it.
class RangeLayer : public rig_core::Layer
{
public:
  void configure(
    const rclcpp_lifecycle::LifecycleNode::WeakPtr & parent, const std::string & name) override
  {
    auto node = parent.lock();
    node->declare_parameter(name + ".topic", rclcpp::ParameterValue("range"));
    std::string topic;
    node->get_parameter(name + ".topic", topic);
    sub_ = node->create_subscription<sensor_msgs::msg::Range>(
      topic, rclcpp::SensorDataQoS(), [](sensor_msgs::msg::Range::ConstSharedPtr) {});
  }

  void reset() override {}

private:
  rclcpp::Subscription<sensor_msgs::msg::Range>::SharedPtr sub_;
};

}  // namespace rig_layers

PLUGINLIB_EXPORT_CLASS(rig_layers::RangeLayer, rig_core::Layer)
