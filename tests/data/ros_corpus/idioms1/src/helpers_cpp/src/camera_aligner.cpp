#include "helpers_cpp/camera_aligner.h"

namespace helpers_cpp {

CameraAligner::CameraAligner(const std::string& action_name)
    : it_(nh_),
      image_sub_(nh_, "camera/image_raw", 2),
      tf_listener_(tf_buffer_),
      align_server_(nh_, action_name, boost::bind(&CameraAligner::onAlign, this, _1), false) {
  info_sub_.subscribe(nh_, "camera/camera_info", 2);
  sync_.reset(new message_filters::TimeSynchronizer<sensor_msgs::Image, sensor_msgs::CameraInfo>(
      image_sub_, info_sub_, 10));
  overlay_pub_ = it_.advertise("overlay", 1);
  rectified_pub_ = it_.advertiseCamera("rectified/image", 1);
  markers_.reset(new interactive_markers::InteractiveMarkerServer("align_markers"));
  align_server_.start();
}

void CameraAligner::onPair(const sensor_msgs::ImageConstPtr& image, const sensor_msgs::CameraInfoConstPtr& info) {}

void CameraAligner::onAlign(const helpers_cpp::AlignGoalConstPtr& goal) {
  align_server_.setSucceeded();
}

}  // namespace helpers_cpp
