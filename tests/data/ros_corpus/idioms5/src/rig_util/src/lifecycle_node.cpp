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

void LifecycleNode::createBond()
{
  bond_ = std::make_unique<bond::Bond>(
    std::string("bond"), this->get_name(), shared_from_this());
  bond_->setHeartbeatPeriod(0.1);
  bond_->start();
}

void LifecycleNode::destroyBond()
{
  bond_.reset();
}

}  // namespace rig_util
