// Turns radiation readings into a status and a velocity command.
#include <ros/ros.h>
#include <geometry_msgs/Twist.h>
#include <rover_msgs/Reading.h>
#include <rover_msgs/Status.h>

ros::Publisher status_pub;
ros::Publisher cmd_pub;

void radiationCallback(const rover_msgs::Reading::ConstPtr& msg)
{
  rover_msgs::Status s;
  s.level = msg->value > 250 ? rover_msgs::Status::RED : rover_msgs::Status::GREEN;
  status_pub.publish(s);
  geometry_msgs::Twist stop;
  cmd_pub.publish(stop);
}

int main(int argc, char** argv)
{
  ros::init(argc, argv, "controller");
  ros::NodeHandle nh;
  ros::Subscriber sub = nh.subscribe("radiation", 10, radiationCallback);
  status_pub = nh.advertise<rover_msgs::Status>("status", 10);
  cmd_pub = nh.advertise<geometry_msgs::Twist>("cmd_vel", 1);
  ros::spin();
  return 0;
}
