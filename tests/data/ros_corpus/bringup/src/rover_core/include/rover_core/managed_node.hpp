// The lifecycle node every rover server derives from.
#ifndef ROVER_CORE__MANAGED_NODE_HPP_
#define ROVER_CORE__MANAGED_NODE_HPP_

#include <memory>
#include <string>

#include "rclcpp_lifecycle/lifecycle_node.hpp"
#include "rover_core/factories.hpp"

namespace rover_core
{

using CallbackReturn = rclcpp_lifecycle::node_interfaces::LifecycleNodeInterface::CallbackReturn;

class ManagedNode : public rclcpp_lifecycle::LifecycleNode
{
public:
  using SharedPtr = std::shared_ptr<ManagedNode>;

  explicit ManagedNode(const std::string & name, const rclcpp::NodeOptions & options = rclcpp::NodeOptions())
  : rclcpp_lifecycle::LifecycleNode(name, options)
  {}

  // This node as its own type (the base class's gives a LifecycleNode).
  SharedPtr shared_from_this()
  {
    return std::static_pointer_cast<ManagedNode>(rclcpp_lifecycle::LifecycleNode::shared_from_this());
  }

  // An action server on this node; the name is the caller's.
  template<typename ActionT>
  typename ActionHost<ActionT>::SharedPtr create_action_server(
    const std::string & action_name, typename ActionHost<ActionT>::Work work)
  {
    return factories::make_action_server<ActionT>(shared_from_this(), action_name, work);
  }

  // An action client on this node.
  template<typename ActionT>
  typename rclcpp_action::Client<ActionT>::SharedPtr create_action_client(const std::string & action_name)
  {
    return rclcpp_action::create_client<ActionT>(shared_from_this(), action_name);
  }
};

}  // namespace rover_core

#endif  // ROVER_CORE__MANAGED_NODE_HPP_
