// A node's action server that runs one piece of work per goal.
#ifndef ROVER_CORE__ACTION_HOST_HPP_
#define ROVER_CORE__ACTION_HOST_HPP_

#include <functional>
#include <memory>
#include <string>

#include "rclcpp/rclcpp.hpp"
#include "rclcpp_action/rclcpp_action.hpp"

namespace rover_core
{

template<typename ActionT>
class ActionHost
{
public:
  using SharedPtr = std::shared_ptr<ActionHost<ActionT>>;
  using Work = std::function<void ()>;
  using GoalHandle = rclcpp_action::ServerGoalHandle<ActionT>;

  // Made from any node: its interfaces are handed to the constructor below.
  template<typename NodeT>
  ActionHost(NodeT node, const std::string & served, Work work)
  : ActionHost(
      node->get_node_base_interface(), node->get_node_clock_interface(),
      node->get_node_logging_interface(), node->get_node_waitables_interface(),
      served, work)
  {}

  ActionHost(
    rclcpp::node_interfaces::NodeBaseInterface::SharedPtr base,
    rclcpp::node_interfaces::NodeClockInterface::SharedPtr clock,
    rclcpp::node_interfaces::NodeLoggingInterface::SharedPtr logging,
    rclcpp::node_interfaces::NodeWaitablesInterface::SharedPtr waitables,
    const std::string & served, Work work)
  : served_(served), work_(work)
  {
    server_ = rclcpp_action::create_server<ActionT>(
      base, clock, logging, waitables, served_,
      [](const rclcpp_action::GoalUUID &, std::shared_ptr<const typename ActionT::Goal>) {
        return rclcpp_action::GoalResponse::ACCEPT_AND_EXECUTE;
      },
      [](const std::shared_ptr<GoalHandle>) {return rclcpp_action::CancelResponse::ACCEPT;},
      [this](const std::shared_ptr<GoalHandle>) {work_();});
  }

  const std::string & served() const {return served_;}

private:
  std::string served_;
  Work work_;
  typename rclcpp_action::Server<ActionT>::SharedPtr server_;
};

}  // namespace rover_core

#endif  // ROVER_CORE__ACTION_HOST_HPP_
