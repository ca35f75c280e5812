// A second component: a node handle member and shared_from_this() receivers.
#include <rclcpp/rclcpp.hpp>
#include <rclcpp_action/rclcpp_action.hpp>
#include <sensor_msgs/msg/battery_state.hpp>
#include <corpus_interfaces/srv/calibrate.hpp>
#include <corpus_interfaces/action/sweep.hpp>
#include "visibility.hpp"

namespace comp_demo {

class COMP_DEMO_PUBLIC Gauge : public rclcpp::Node {
 public:
  explicit Gauge(const rclcpp::NodeOptions& options) : rclcpp::Node("gauge", options) {
    std::string topic = this->declare_parameter<std::string>("battery_topic", "battery");
    battery_ = this->create_publisher<sensor_msgs::msg::BatteryState>(topic, rclcpp::SensorDataQoS());
    calibrate_ = this->create_client<corpus_interfaces::srv::Calibrate>("/calibration/run");
    timer_ = create_wall_timer(std::chrono::seconds(1), [this]() { start(); });
  }

  void start() {
    sweeper_ = rclcpp_action::create_client<corpus_interfaces::action::Sweep>(shared_from_this(), "sweep");
  }

 private:
  rclcpp::Publisher<sensor_msgs::msg::BatteryState>::SharedPtr battery_;
  rclcpp::Client<corpus_interfaces::srv::Calibrate>::SharedPtr calibrate_;
  rclcpp_action::Client<corpus_interfaces::action::Sweep>::SharedPtr sweeper_;
  rclcpp::TimerBase::SharedPtr timer_;
};

}  // namespace comp_demo

#include <rclcpp_components/register_node_macro.hpp>
RCLCPP_COMPONENTS_REGISTER_NODE(comp_demo::Gauge)
