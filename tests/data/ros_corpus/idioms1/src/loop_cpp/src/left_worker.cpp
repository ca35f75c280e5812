// Left worker: its options-built subscription runs on its own callback queue.
#include <ros/ros.h>
#include <ros/callback_queue.h>
#include <std_msgs/Float64.h>
#include <geometry_msgs/Twist.h>

class Worker {
 public:
  explicit Worker(ros::NodeHandle& nh) {
    ros::SubscribeOptions ops = ros::SubscribeOptions::create<std_msgs::Float64>(
        "wheel/left/speed", 10, boost::bind(&Worker::onSpeed, this, _1), ros::VoidPtr(), &queue_);
    speed_sub_ = nh.subscribe(ops);
    cmd_pub_ = nh.advertise<geometry_msgs::Twist>("wheel/left/cmd", 10);
  }

 private:
  void onSpeed(const std_msgs::Float64ConstPtr& msg) {}
  ros::CallbackQueue queue_;
  ros::Subscriber speed_sub_;
  ros::Publisher cmd_pub_;
};

int main(int argc, char** argv) {
  ros::init(argc, argv, "left_worker");
  ros::NodeHandle nh;
  Worker worker(nh);
  ros::spin();
  return 0;
}
