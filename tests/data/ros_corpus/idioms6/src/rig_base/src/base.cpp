#include <memory>

#include "rclcpp/rclcpp.hpp"
#include "rig_msgs/msg/motor_power.hpp"
#include "rig_msgs/msg/sound.hpp"
#include "std_msgs/msg/empty.hpp"

// The base: motor power and sound states, a reset trigger, and a watch on parameter changes.
class Base : public rclcpp::Node
{
public:
  Base()
  : Node("base")
  {
    power_pub_ = create_publisher<rig_msgs::msg::MotorPower>("motor_power", 10);
    sound_pub_ = create_publisher<rig_msgs::msg::Sound>("sound", 10);
    reset_sub_ = create_subscription<std_msgs::msg::Empty>(
      "reset", 1, [](std_msgs::msg::Empty::ConstSharedPtr) {});
    events_ = std::make_shared<rclcpp::ParameterEventHandler>(this);
  }

private:
  rclcpp::Publisher<rig_msgs::msg::MotorPower>::SharedPtr power_pub_;
  rclcpp::Publisher<rig_msgs::msg::Sound>::SharedPtr sound_pub_;
  rclcpp::Subscription<std_msgs::msg::Empty>::SharedPtr reset_sub_;
  std::shared_ptr<rclcpp::ParameterEventHandler> events_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Base>());
  rclcpp::shutdown();
  return 0;
}
