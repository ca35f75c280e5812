#include <ros/ros.h>
#include "helpers_cpp/camera_aligner.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "camera_aligner");
  // the action server takes the node's own name
  helpers_cpp::CameraAligner aligner(ros::this_node::getName());
  ros::spin();
  return 0;
}
