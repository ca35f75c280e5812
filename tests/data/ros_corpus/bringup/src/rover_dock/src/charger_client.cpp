#include "rover_dock/charger_client.hpp"

namespace rover_dock
{

ChargerClient::ChargerClient(rclcpp_lifecycle::LifecycleNode * node)
{
  client_ = node->create_client<Request>("charge");
}

}  // namespace rover_dock
