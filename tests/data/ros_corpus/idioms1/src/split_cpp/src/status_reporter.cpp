#include "split_cpp/status_reporter.h"

#include <cinttypes>
#include <std_msgs/String.h>
#include <std_srvs/Trigger.h>

#include "split_cpp/c_checksum.h"

namespace split_cpp {

StatusReporter::StatusReporter(const std::string& status_topic) {
  status_pub_ = pnh_.advertise<std_msgs::String>(status_topic, 1, true);
  reset_srv_ = pnh_.advertiseService("reset", &StatusReporter::onReset, this);
}

void StatusReporter::report(int64_t count) {
  std_msgs::String msg;
  char text[64];
  snprintf(text, sizeof(text), "frames: %" PRId64, count);
  msg.data = text;
  status_pub_.publish(msg);
}

bool StatusReporter::onReset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res) {
  res.success = true;
  return true;
}

}  // namespace split_cpp
