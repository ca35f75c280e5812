#include "rover_dock/dock_server.hpp"

namespace rover_dock
{

DockServer::DockServer(const rclcpp::NodeOptions & options)
: rover_core::ManagedNode("dock_server", options)
{
}

rover_core::CallbackReturn DockServer::on_configure(const rclcpp_lifecycle::State &)
{
  auto node = shared_from_this();
  dock_server_ = node->create_action_server<Dock>("dock", [] {});
  undock_server_ = node->create_action_server<Undock>(
    "undock", [] {});
  battery_sub_ = create_subscription<Charge>("battery", 1, [](Charge::ConstSharedPtr) {});
  charger_ = std::make_unique<ChargerClient>(this);
  lamp_ = std::make_unique<LampClient>(this);
  return rover_core::CallbackReturn::SUCCESS;
}

}  // namespace rover_dock

#include "rclcpp_components/register_node_macro.hpp"
RCLCPP_COMPONENTS_REGISTER_NODE(rover_dock::DockServer)
