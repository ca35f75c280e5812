// An older nodelet: the class in its source, registered with PLUGINLIB_DECLARE_CLASS.
#include <vector>
#include <ros/ros.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.h>
#include <sensor_msgs/Range.h>

namespace nodelet_drv
{
class MedianFilterNodelet : public nodelet::Nodelet
{
  ros::Subscriber sub_;
  ros::Publisher pub_;
  std::vector<float> window_;

  virtual void onInit()
  {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& private_nh = getPrivateNodeHandle();
    pub_ = private_nh.advertise<sensor_msgs::Range>("filtered", 5);
    sub_ = nh.subscribe("range", 5, &MedianFilterNodelet::callback, this);
  }

  void callback(const sensor_msgs::RangeConstPtr& msg)
  {
    window_.push_back(msg->range);
    pub_.publish(msg);
  }
};
}  // namespace nodelet_drv

PLUGINLIB_DECLARE_CLASS(nodelet_drv, MedianFilter, nodelet_drv::MedianFilterNodelet, nodelet::Nodelet)
