// Switches the dock's lamp; made by the dock server.
#ifndef ROVER_DOCK__LAMP_CLIENT_HPP_
#define ROVER_DOCK__LAMP_CLIENT_HPP_

#include "rclcpp/rclcpp.hpp"
#include "rclcpp_lifecycle/lifecycle_node.hpp"
#include "std_srvs/srv/set_bool.hpp"

namespace rover_dock
{

class LampClient
{
public:
  using Request = std_srvs::srv::SetBool;

  explicit LampClient(rclcpp_lifecycle::LifecycleNode * node);

private:
  rclcpp::Client<Request>::SharedPtr client_;
};

}  // namespace rover_dock

#endif  // ROVER_DOCK__LAMP_CLIENT_HPP_
