#include <memory>
#include <rclcpp/rclcpp.hpp>
#include <rclcpp_lifecycle/lifecycle_node.hpp>
#include <std_msgs/msg/bool.hpp>

using CallbackReturn = rclcpp_lifecycle::node_interfaces::LifecycleNodeInterface::CallbackReturn;

class Brake : public rclcpp_lifecycle::LifecycleNode
{
public:
  Brake()
  : LifecycleNode("brake")
  {
  }

  CallbackReturn on_configure(const rclcpp_lifecycle::State &) override
  {
    engaged_pub_ = create_publisher<std_msgs::msg::Bool>("brake_engaged", 10);
    request_sub_ = create_subscription<std_msgs::msg::Bool>(
      "brake_request", 10, [](std_msgs::msg::Bool::SharedPtr) {});
    return CallbackReturn::SUCCESS;
  }

private:
  rclcpp_lifecycle::LifecyclePublisher<std_msgs::msg::Bool>::SharedPtr engaged_pub_;
  rclcpp::Subscription<std_msgs::msg::Bool>::SharedPtr request_sub_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  auto node = std::make_shared<Brake>();
  rclcpp::spin(node->get_node_base_interface());
  rclcpp::shutdown();
  return 0;
}
