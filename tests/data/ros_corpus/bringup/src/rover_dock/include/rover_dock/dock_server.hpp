#ifndef ROVER_DOCK__DOCK_SERVER_HPP_
#define ROVER_DOCK__DOCK_SERVER_HPP_

#include "rover_core/managed_node.hpp"
#include "rover_dock/charger_client.hpp"
#include "rover_dock/lamp_client.hpp"
#include "sensor_msgs/msg/battery_state.hpp"
#include "rover_msgs/action/dock.hpp"
#include "rover_msgs/action/undock.hpp"

namespace rover_dock
{

class DockServer : public rover_core::ManagedNode
{
public:
  explicit DockServer(const rclcpp::NodeOptions & options = rclcpp::NodeOptions());

  rover_core::CallbackReturn on_configure(const rclcpp_lifecycle::State & state) override;

private:
  using Dock = rover_msgs::action::Dock;
  using Undock = rover_msgs::action::Undock;
  using Charge = sensor_msgs::msg::BatteryState;

  rover_core::ActionHost<Dock>::SharedPtr dock_server_;
  rover_core::ActionHost<Undock>::SharedPtr undock_server_;
  rclcpp::Subscription<Charge>::SharedPtr battery_sub_;
  std::unique_ptr<ChargerClient> charger_;
  std::unique_ptr<LampClient> lamp_;
};

}  // namespace rover_dock

#endif  // ROVER_DOCK__DOCK_SERVER_HPP_
