// The node: two rangers on namespaced handles and a status reporter, all
// helper classes written in other files of the executable.
#include <memory>
#include <ros/ros.h>
#include <sensor_msgs/Range.h>

#include "split_cpp/range_sensor.h"
#include "split_cpp/status_reporter.h"

namespace split_cpp {

static const std::string kStatusTopic = "status";

class SplitNode {
 public:
  SplitNode()
      : nh_(),
        front_nh_(nh_, "front"),
        rear_nh_("rear"),
        front_(front_nh_, "range"),
        rear_(rear_nh_, "range", "sonar_rear"),
        reporter_(new StatusReporter(kStatusTopic)) {
    ros::NodeHandle diag_nh(nh_, "diagnostics");
    side_ = std::make_shared<RangeSensor>(diag_nh, "side_range");
  }

 private:
  ros::NodeHandle nh_;
  ros::NodeHandle front_nh_;
  ros::NodeHandle rear_nh_;
  RangeSensor front_;
  RangeSensor rear_;
  std::shared_ptr<RangeSensor> side_;
  std::unique_ptr<StatusReporter> reporter_;
};

}  // namespace split_cpp

int main(int argc, char** argv) {
  ros::init(argc, argv, "split_node");
  split_cpp::SplitNode node;
  ros::spin();
  return 0;
}
