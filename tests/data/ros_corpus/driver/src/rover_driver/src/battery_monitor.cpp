#include "rover_driver/battery_monitor.h"

namespace rover_driver {

BatteryMonitor::BatteryMonitor(ros::NodeHandle& nh, std::shared_ptr<SerialLink> link, const std::string& topic)
    : link_(link) {
  battery_pub_ = nh.advertise<sensor_msgs::BatteryState>(topic, 1);
}

void BatteryMonitor::poll() {
  std::vector<uint8_t> reply;
  if (!link_->request(0x40, {}, reply) || reply.size() < 2) {
    return;
  }
  sensor_msgs::BatteryState state;
  state.header.stamp = ros::Time::now();
  state.voltage = (reply[0] | reply[1] << 8) / 100.0f;
  battery_pub_.publish(state);
}

}  // namespace rover_driver
