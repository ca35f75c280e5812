// A component: export macro before the class name, endpoints made in the constructor.
#include <rclcpp/rclcpp.hpp>
#include <rclcpp_action/rclcpp_action.hpp>
#include <std_msgs/msg/string.hpp>
#include <std_srvs/srv/trigger.hpp>
#include <corpus_interfaces/action/sweep.hpp>
#include "visibility.hpp"

namespace comp_demo {

using Sweep = corpus_interfaces::action::Sweep;

class COMP_DEMO_PUBLIC Relay : public rclcpp::Node {
 public:
  explicit Relay(const rclcpp::NodeOptions& options) : Node("relay", options) {
    declare_parameter("output", "relayed");
    const std::string output = get_parameter("output").as_string();
    pub_ = this->create_publisher<std_msgs::msg::String>(output, 10);
    sub_ = create_subscription<std_msgs::msg::String>(
        "input", 10, [this](std_msgs::msg::String::ConstSharedPtr msg) { pub_->publish(*msg); });
    flush_ = create_service<std_srvs::srv::Trigger>("~/flush", std::bind(&Relay::onFlush, this,
                                                                         std::placeholders::_1,
                                                                         std::placeholders::_2));
    sweep_ = rclcpp_action::create_server<Sweep>(this, "sweep", nullptr, nullptr, nullptr);
  }

 private:
  void onFlush(const std::shared_ptr<std_srvs::srv::Trigger::Request>,
               std::shared_ptr<std_srvs::srv::Trigger::Response>) {}
  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr pub_;
  rclcpp::Subscription<std_msgs::msg::String>::SharedPtr sub_;
  rclcpp::Service<std_srvs::srv::Trigger>::SharedPtr flush_;
  rclcpp_action::Server<Sweep>::SharedPtr sweep_;
};

}  // namespace comp_demo

#include <rclcpp_components/register_node_macro.hpp>
RCLCPP_COMPONENTS_REGISTER_NODE(comp_demo::Relay)
