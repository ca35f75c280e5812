#include <pluginlib/class_list_macros.h>
#include "nodelet_drv/range_nodelet.h"

typedef nodelet_drv::RangeNodelet RangeNodelet;

PLUGINLIB_EXPORT_CLASS(RangeNodelet, nodelet::Nodelet)

void RangeNodelet::onInit()
{
  ros::NodeHandle nh = getMTNodeHandle();
  ros::NodeHandle private_nh = getMTPrivateNodeHandle();
  driver_.reset(new RangeDriver(nh, private_nh, getName()));
}
