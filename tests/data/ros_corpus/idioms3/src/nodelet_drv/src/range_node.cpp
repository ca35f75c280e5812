#include <ros/ros.h>
#include "nodelet_drv/range_driver.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "range_node");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  nodelet_drv::RangeDriver driver(nh, private_nh, ros::this_node::getName());
  while (ros::ok() && driver.poll())
  {
    ros::spinOnce();
  }
  return 0;
}
