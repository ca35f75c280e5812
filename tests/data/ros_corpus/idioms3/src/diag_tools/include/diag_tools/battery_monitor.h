#ifndef DIAG_TOOLS_BATTERY_MONITOR_H
#define DIAG_TOOLS_BATTERY_MONITOR_H
#include <ros/ros.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <self_test/self_test.h>
#include <sensor_msgs/BatteryState.h>

namespace diag_tools
{
// the monitor is itself the diagnostic updater
class BatteryMonitor : private diagnostic_updater::Updater
{
public:
  explicit BatteryMonitor(ros::NodeHandle nh);

private:
  void batteryCallback(const sensor_msgs::BatteryState::ConstPtr& msg);
  void check(diagnostic_updater::DiagnosticStatusWrapper& stat);

  ros::Subscriber battery_sub_;
  self_test::TestRunner self_test_;
  float voltage_ = 0.0f;
};
}  // namespace diag_tools
#endif
