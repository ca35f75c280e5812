#include <functional>
#include <memory>

#include "geometry_msgs/msg/twist.hpp"
#include "rig_util/lifecycle_node.hpp"
#include "rig_util/odom_smoother.hpp"
#include "rig_util/twist_helpers.hpp"

namespace rig_relay
{

// Relays velocity commands through the helper library's wrappers.
class Relay : public rig_util::LifecycleNode
{
public:
  Relay()
  : rig_util::LifecycleNode("relay")
  {
  }

  CallbackReturn on_configure(const rclcpp_lifecycle::State &) override
  {
    auto node = shared_from_this();
    cmd_in_ = std::make_unique<rig_util::TwistSubscriber>(
      node, "cmd_vel_in", std::bind(&Relay::onCommand, this, std::placeholders::_1));
    cmd_out_ = std::make_unique<rig_util::TwistPublisher>(node, "cmd_vel_out", 1);
    odom_ = std::make_unique<rig_util::OdomSmoother>(node, 0.5);
    return CallbackReturn::SUCCESS;
  }

  CallbackReturn on_activate(const rclcpp_lifecycle::State &) override
  {
    createBond();
    return CallbackReturn::SUCCESS;
  }

private:
  void onCommand(geometry_msgs::msg::Twist::SharedPtr)
  {
  }

  std::unique_ptr<rig_util::TwistSubscriber> cmd_in_;
  std::unique_ptr<rig_util::TwistPublisher> cmd_out_;
  std::unique_ptr<rig_util::OdomSmoother> odom_;
};

}  // namespace rig_relay

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = std::make_shared<rig_relay::Relay>();
  rclcpp::spin(node->get_node_base_interface());
  rclcpp::shutdown();
  return 0;
}
