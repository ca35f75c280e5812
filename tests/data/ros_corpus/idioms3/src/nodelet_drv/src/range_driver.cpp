#include "nodelet_drv/range_driver.h"
#include <sensor_msgs/Range.h>
#include <std_srvs/Trigger.h>

namespace nodelet_drv
{
RangeDriver::RangeDriver(ros::NodeHandle nh, ros::NodeHandle private_nh, const std::string& node_name)
  : diagnostics_(nh, private_nh, node_name)
{
  range_pub_ = nh.advertise<sensor_msgs::Range>("range", 10);
  calibrate_srv_ = private_nh.advertiseService("calibrate", &RangeDriver::calibrate, this);
  reconfigure_.reset(new ReconfigureServer(private_nh));
  reconfigure_->setCallback(boost::bind(&RangeDriver::reconfigure, this, _1, _2));
  diagnostic_updater::FrequencyStatusParam freq(&min_rate_, &max_rate_);
  range_freq_.reset(new diagnostic_updater::TopicDiagnostic("range", diagnostics_, freq,
                                                            diagnostic_updater::TimeStampStatusParam()));
}

bool RangeDriver::poll()
{
  diagnostics_.update();
  return true;
}
}  // namespace nodelet_drv
