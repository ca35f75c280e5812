#ifndef ROVER_DOCK__DOCK_SERVER_HPP_
#define ROVER_DOCK__DOCK_SERVER_HPP_

#include "rover_core/managed_node.hpp"
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

  rover_core::ActionHost<Dock>::SharedPtr dock_server_;
  rover_core::ActionHost<Undock>::SharedPtr undock_server_;
};

}  // namespace rover_dock

#endif  // ROVER_DOCK__DOCK_SERVER_HPP_
