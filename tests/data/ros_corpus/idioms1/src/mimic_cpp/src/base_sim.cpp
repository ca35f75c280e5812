// A simulated base: velocity in, pose out, both under the handle "base".
#include <ros/ros.h>
#include <geometry_msgs/Pose2D.h>
#include <geometry_msgs/Twist.h>
#include <std_msgs/String.h>

class BaseSim {
 public:
  BaseSim() : base_nh_("base"), private_nh_("~") {
    cmd_sub_ = base_nh_.subscribe("cmd_vel", 1, &BaseSim::onCmd, this);
    pose_pub_ = base_nh_.advertise<geometry_msgs::Pose2D>("pose", 10);
    state_pub_ = private_nh_.advertise<std_msgs::String>("state", 1);
  }

 private:
  void onCmd(const geometry_msgs::TwistConstPtr& cmd) {}
  ros::NodeHandle base_nh_;
  ros::NodeHandle private_nh_;
  ros::Subscriber cmd_sub_;
  ros::Publisher pose_pub_;
  ros::Publisher state_pub_;
};

int main(int argc, char** argv) {
  ros::init(argc, argv, "base_sim");
  BaseSim sim;
  ros::spin();
  return 0;
}
