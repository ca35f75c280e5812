// Free functions that make the rover's endpoints for any node.
#ifndef ROVER_CORE__FACTORIES_HPP_
#define ROVER_CORE__FACTORIES_HPP_

#include <memory>
#include <string>

#include "rover_core/action_host.hpp"

namespace rover_core
{
namespace factories
{

template<typename ActionT, typename NodeT>
typename ActionHost<ActionT>::SharedPtr make_action_server(
  const NodeT & node, const std::string & action_name, typename ActionHost<ActionT>::Work work)
{
  return std::make_shared<ActionHost<ActionT>>(node, action_name, work);
}

}  // namespace factories
}  // namespace rover_core

#endif  // ROVER_CORE__FACTORIES_HPP_
