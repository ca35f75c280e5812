// Makes one base follow another: reads poses from "input", writes commands
// to "output"; a launch file remaps both namespaces.
#include <ros/ros.h>
#include <geometry_msgs/Pose2D.h>
#include <geometry_msgs/Twist.h>

class Mimic {
 public:
  Mimic() {
    ros::NodeHandle input_nh("input");
    ros::NodeHandle output_nh("output");
    cmd_pub_ = output_nh.advertise<geometry_msgs::Twist>("cmd_vel", 1);
    pose_sub_ = input_nh.subscribe<geometry_msgs::Pose2D>("pose", 1, &Mimic::onPose, this);
  }

 private:
  void onPose(const geometry_msgs::Pose2DConstPtr& pose) {}
  ros::Publisher cmd_pub_;
  ros::Subscriber pose_sub_;
};

int main(int argc, char** argv) {
  ros::init(argc, argv, "mimic");
  Mimic mimic;
  ros::spin();
  return 0;
}
