#include "rig_util/lifecycle_node.hpp"

namespace rig_util
{

LifecycleNode::LifecycleNode(
  const std::string & node_name,
  const std::string & ns,
  const rclcpp::NodeOptions & options)
: rclcpp_lifecycle::LifecycleNode(node_name, ns, options)
{
}

LifecycleNode::~LifecycleNode()
{
}

}  // namespace rig_util
