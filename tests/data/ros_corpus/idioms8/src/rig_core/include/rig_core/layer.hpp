#ifndef RIG_CORE__LAYER_HPP_
#define RIG_CORE__LAYER_HPP_

#include <string>

#include "rclcpp_lifecycle/lifecycle_node.hpp"

namespace rig_core
{

// One layer of the rig's map. The mapper loads its layers by name at run
// time and hands each the mapper node and the layer's own name.
class Layer
{
public:
  virtual ~Layer() = default;
  virtual void configure(
    const rclcpp_lifecycle::LifecycleNode::WeakPtr & parent, const std::string & name) = 0;
  virtual void reset() = 0;
};

}  // namespace rig_core

#endif  // RIG_CORE__LAYER_HPP_
