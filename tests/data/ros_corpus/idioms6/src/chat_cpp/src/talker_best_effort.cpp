#include <memory>

#include "rclcpp/rclcpp.hpp"
#include "std_msgs/msg/string.hpp"
#include "std_msgs/msg/u_int32.hpp"

// The same greeting with best-effort delivery, and how many it dropped.
class BestEffortTalker : public rclcpp::Node
{
public:
  BestEffortTalker()
  : Node("talker")
  {
    pub_ = create_publisher<std_msgs::msg::String>("chatter", rclcpp::QoS(10).best_effort());
    drops_pub_ = create_publisher<std_msgs::msg::UInt32>("~/dropped", 1);
  }

private:
  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr pub_;
  rclcpp::Publisher<std_msgs::msg::UInt32>::SharedPtr drops_pub_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<BestEffortTalker>());
  rclcpp::shutdown();
  return 0;
}
