#ifndef NODELET_DRV_RANGE_DRIVER_H
#define NODELET_DRV_RANGE_DRIVER_H
#include <string>
#include <ros/ros.h>
#include <dynamic_reconfigure/server.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/publisher.h>
#include <nodelet_drv/RangeConfig.h>

namespace nodelet_drv
{
typedef dynamic_reconfigure::Server<nodelet_drv::RangeConfig> ReconfigureServer;

class RangeDriver
{
public:
  RangeDriver(ros::NodeHandle nh, ros::NodeHandle private_nh, const std::string& node_name);
  bool poll();

private:
  void reconfigure(nodelet_drv::RangeConfig& config, uint32_t level);
  bool calibrate(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);

  ros::Publisher range_pub_;
  ros::ServiceServer calibrate_srv_;
  boost::shared_ptr<ReconfigureServer> reconfigure_;
  diagnostic_updater::Updater diagnostics_;
  boost::shared_ptr<diagnostic_updater::TopicDiagnostic> range_freq_;
  double min_rate_ = 5.0;
  double max_rate_ = 15.0;
};
}  // namespace nodelet_drv
#endif
