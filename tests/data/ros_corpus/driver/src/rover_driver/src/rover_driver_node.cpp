#include <ros/ros.h>

#include "rover_driver/rover_driver.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "rover_driver");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  rover_driver::RoverDriver driver(nh, pnh);
  driver.spin();
  return 0;
}
