#ifndef HELPERS_CPP_CAMERA_ALIGNER_H
#define HELPERS_CPP_CAMERA_ALIGNER_H

#include <memory>
#include <string>

#include <actionlib/server/simple_action_server.h>
#include <helpers_cpp/AlignAction.h>
#include <image_transport/image_transport.h>
#include <interactive_markers/interactive_marker_server.h>
#include <message_filters/subscriber.h>
#include <message_filters/time_synchronizer.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

namespace helpers_cpp {

class CameraAligner {
 public:
  explicit CameraAligner(const std::string& action_name);

 private:
  void onPair(const sensor_msgs::ImageConstPtr& image, const sensor_msgs::CameraInfoConstPtr& info);
  void onAlign(const helpers_cpp::AlignGoalConstPtr& goal);

  ros::NodeHandle nh_;
  image_transport::ImageTransport it_;
  image_transport::Publisher overlay_pub_;
  image_transport::CameraPublisher rectified_pub_;
  message_filters::Subscriber<sensor_msgs::Image> image_sub_;
  message_filters::Subscriber<sensor_msgs::CameraInfo> info_sub_;
  std::unique_ptr<message_filters::TimeSynchronizer<sensor_msgs::Image, sensor_msgs::CameraInfo>> sync_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  std::shared_ptr<interactive_markers::InteractiveMarkerServer> markers_;
  actionlib::SimpleActionServer<helpers_cpp::AlignAction> align_server_;
};

}  // namespace helpers_cpp

#endif
