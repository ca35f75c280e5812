// Right worker: the same class name as the left one, another program. It
// waits for one calibration message before it starts.
#include <ros/ros.h>
#include <std_msgs/Float64.h>
#include <std_msgs/Empty.h>

class Worker {
 public:
  Worker() {
    ros::SubscribeOptions ops;
    ops.init<std_msgs::Float64>("wheel/right/speed", 10, boost::bind(&Worker::onSpeed, this, _1));
    speed_sub_ = nh_.subscribe(ops);
    auto calibration = ros::topic::waitForMessage<std_msgs::Empty>("calibrated", nh_, ros::Duration(5.0));
    ready_pub_ = nh_.advertise<std_msgs::Empty>("wheel/right/ready", 1, true);
  }

 private:
  void onSpeed(const std_msgs::Float64::ConstPtr& msg) {}
  ros::NodeHandle nh_;
  ros::Subscriber speed_sub_;
  ros::Publisher ready_pub_;
};

int main(int argc, char** argv) {
  ros::init(argc, argv, "right_worker");
  Worker worker;
  ros::spin();
  return 0;
}
