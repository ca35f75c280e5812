// Asks the charger to charge; made by the dock server.
#ifndef ROVER_DOCK__CHARGER_CLIENT_HPP_
#define ROVER_DOCK__CHARGER_CLIENT_HPP_

#include <string>

#include "rclcpp/rclcpp.hpp"
#include "rclcpp_lifecycle/lifecycle_node.hpp"
#include "rover_msgs/srv/charge.hpp"

namespace rover_dock
{

class ChargerClient
{
public:
  using Request = rover_msgs::srv::Charge;

  explicit ChargerClient(rclcpp_lifecycle::LifecycleNode * node);

private:
  rclcpp::Client<Request>::SharedPtr client_;
};

}  // namespace rover_dock

#endif  // ROVER_DOCK__CHARGER_CLIENT_HPP_
