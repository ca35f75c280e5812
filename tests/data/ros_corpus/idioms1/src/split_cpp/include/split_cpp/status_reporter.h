#ifndef SPLIT_CPP_STATUS_REPORTER_H
#define SPLIT_CPP_STATUS_REPORTER_H

#include <cstdint>
#include <string>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

namespace split_cpp {

// Publishes the node's status text and serves a reset, both under the
// private namespace of the node (the handle is made here, not passed in).
class StatusReporter {
 public:
  explicit StatusReporter(const std::string& status_topic);
  void report(int64_t count);

 private:
  ros::NodeHandle pnh_{"~"};
  ros::Publisher status_pub_;
  ros::ServiceServer reset_srv_;
  bool onReset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
};

}  // namespace split_cpp

#endif
