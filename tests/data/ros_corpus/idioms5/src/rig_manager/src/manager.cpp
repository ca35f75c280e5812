#include <memory>
#include <string>

#include "rclcpp/rclcpp.hpp"
#include "std_msgs/msg/bool.hpp"
#include "std_msgs/msg/string.hpp"
#include "std_srvs/srv/trigger.hpp"
#include "source.hpp"

namespace rig_manager
{

// Manages the rig: its services are named after the node itself.
class Manager : public rclcpp::Node
{
public:
  Manager()
  : Node("rig_manager")
  {
    manage_srv_ = create_service<std_srvs::srv::Trigger>(
      get_name() + std::string("/manage_nodes"),
      [](const std::shared_ptr<std_srvs::srv::Trigger::Request>,
      std::shared_ptr<std_srvs::srv::Trigger::Response>) {});
    active_srv_ = create_service<std_srvs::srv::Trigger>(
      std::string(get_name()) + "/is_active",
      [](const std::shared_ptr<std_srvs::srv::Trigger::Request>,
      std::shared_ptr<std_srvs::srv::Trigger::Response>) {});
    activated_pub_ = create_publisher<std_msgs::msg::Bool>(
      std::string(this->get_name()) + "/nodes_activated", rclcpp::QoS(1).transient_local());

    declare_parameter("status_topic", std::string("status"));
    std::string status_topic;
    get_parameter("status_topic", status_topic);
    status_pub_ = create_publisher<std_msgs::msg::String>(status_topic, 1);

    front_ = std::make_unique<Source>(this, "front");
    rear_ = std::make_unique<Source>(this, "rear");
  }

private:
  rclcpp::Service<std_srvs::srv::Trigger>::SharedPtr manage_srv_;
  rclcpp::Service<std_srvs::srv::Trigger>::SharedPtr active_srv_;
  rclcpp::Publisher<std_msgs::msg::Bool>::SharedPtr activated_pub_;
  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr status_pub_;
  std::unique_ptr<Source> front_;
  std::unique_ptr<Source> rear_;
};

}  // namespace rig_manager

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<rig_manager::Manager>());
  rclcpp::shutdown();
  return 0;
}
