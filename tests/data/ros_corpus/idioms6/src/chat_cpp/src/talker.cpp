#include <memory>

#include "rclcpp/rclcpp.hpp"
#include "std_msgs/msg/string.hpp"

// Says hello on chatter, once a second.
class Talker : public rclcpp::Node
{
public:
  Talker()
  : Node("talker")
  {
    pub_ = create_publisher<std_msgs::msg::String>("chatter", 10);
  }

private:
  rclcpp::Publisher<std_msgs::msg::String>::SharedPtr pub_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<Talker>());
  rclcpp::shutdown();
  return 0;
}
