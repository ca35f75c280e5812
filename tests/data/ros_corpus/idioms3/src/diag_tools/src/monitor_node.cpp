#include <ros/ros.h>
#include "diag_tools/battery_monitor.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "battery_monitor");
  ros::NodeHandle nh;
  diag_tools::BatteryMonitor monitor(nh);
  ros::spin();
  return 0;
}
