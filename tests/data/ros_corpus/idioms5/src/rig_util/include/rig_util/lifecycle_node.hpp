#ifndef RIG_UTIL__LIFECYCLE_NODE_HPP_
#define RIG_UTIL__LIFECYCLE_NODE_HPP_

#include <memory>
#include <string>

#include "bondcpp/bond.hpp"
#include "rclcpp/rclcpp.hpp"
#include "rclcpp_lifecycle/lifecycle_node.hpp"

namespace rig_util
{

// The base every node of the rig derives from.
class LifecycleNode : public rclcpp_lifecycle::LifecycleNode
{
public:
  LifecycleNode(
    const std::string & node_name,
    const std::string & ns = "",
    const rclcpp::NodeOptions & options = rclcpp::NodeOptions());
  virtual ~LifecycleNode();

protected:
  // The heartbeat a lifecycle manager watches.
  void createBond();
  void destroyBond();

  std::unique_ptr<bond::Bond> bond_;
};

}  // namespace rig_util

#endif  // RIG_UTIL__LIFECYCLE_NODE_HPP_
