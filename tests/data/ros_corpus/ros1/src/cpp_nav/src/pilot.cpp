// A roscpp node written as a class: handles and members made in the constructor.
#include <ros/ros.h>
#include <actionlib/server/simple_action_server.h>
#include <actionlib/client/simple_action_client.h>
#include <geometry_msgs/Twist.h>
#include <sensor_msgs/LaserScan.h>
#include <std_srvs/SetBool.h>
#include <corpus_msgs/PlanPath.h>
#include <corpus_msgs/DriveAction.h>
#include <corpus_msgs/DockAction.h>

namespace cpp_nav {

class Pilot {
 public:
  Pilot() : pnh_("~"), drive_(nh_, "drive", false) {
    pnh_.param("cmd_topic", cmd_topic_, std::string("cmd_vel"));
    std::string scan_topic;
    nh_.param<std::string>("scan_topic", scan_topic, "scan");
    cmd_pub_ = nh_.advertise<geometry_msgs::Twist>(cmd_topic_, 1);
    scan_sub_ = nh_.subscribe(scan_topic, 5, &Pilot::onScan, this);
    status_pub_ = pnh_.advertise<std_msgs::String>("status", 1);
    enable_srv_ = nh_.advertiseService("enable", &Pilot::onEnable, this);
    plan_client_ = nh_.serviceClient<corpus_msgs::PlanPath>("/planner/plan_path");
    dock_ = std::make_shared<actionlib::SimpleActionClient<corpus_msgs::DockAction>>("dock", true);
  }

  void onScan(const sensor_msgs::LaserScan::ConstPtr& msg) {}
  bool onEnable(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) { return true; }

 private:
  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  std::string cmd_topic_;
  ros::Publisher cmd_pub_, status_pub_;
  ros::Subscriber scan_sub_;
  ros::ServiceServer enable_srv_;
  ros::ServiceClient plan_client_;
  actionlib::SimpleActionServer<corpus_msgs::DriveAction> drive_;
  std::shared_ptr<actionlib::SimpleActionClient<corpus_msgs::DockAction>> dock_;
};

}  // namespace cpp_nav

int main(int argc, char** argv) {
  ros::init(argc, argv, "pilot");
  cpp_nav::Pilot pilot;
  ros::spin();
  return 0;
}
