#include "diag_tools/battery_monitor.h"

using namespace diag_tools;

BatteryMonitor::BatteryMonitor(ros::NodeHandle nh)
  : Updater(nh)
{
  setHardwareID("battery");
  add("Voltage", this, &BatteryMonitor::check);
  battery_sub_ = nh.subscribe("battery", 1, &BatteryMonitor::batteryCallback, this);
}

void BatteryMonitor::batteryCallback(const sensor_msgs::BatteryState::ConstPtr& msg)
{
  voltage_ = msg->voltage;
  update();
}

void BatteryMonitor::check(diagnostic_updater::DiagnosticStatusWrapper& stat)
{
  stat.summary(voltage_ > 11.0f ? 0 : 1, "voltage");
}
