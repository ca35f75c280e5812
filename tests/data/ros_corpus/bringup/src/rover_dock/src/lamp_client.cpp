#include "rover_dock/lamp_client.hpp"

namespace rover_dock
{

LampClient::LampClient(rclcpp_lifecycle::LifecycleNode * node)
{
  client_ = node->create_client<Request>("lamp");
}

}  // namespace rover_dock
