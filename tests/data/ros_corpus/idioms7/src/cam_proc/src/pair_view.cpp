#include "cam_proc/pair_view.hpp"

#include <rclcpp_components/register_node_macro.hpp>

namespace cam_proc
{
PairView::PairView(const rclcpp::NodeOptions & options)
: rclcpp::Node("pair_view", options)
{
  auto base = get_node_base_interface();
  std::string pair = base->resolve_topic_or_service_name("pair", false);
  std::string image = base->resolve_topic_or_service_name("image", false);
  // the node's namespace would sit in the middle of this name: not read
  std::string left = rclcpp::expand_topic_or_service_name(
    pair + "/left" + rclcpp::expand_topic_or_service_name(image, get_name(), get_namespace()),
    get_name(), get_namespace());
  std::string disparity = rclcpp::expand_topic_or_service_name(
    pair + "/disparity", get_name(), get_namespace());

  left_.subscribe(this, left, "raw");
  right_.subscribe(this, pair + "/right/image", "raw");
  disparity_.subscribe(this, disparity);
}
}  // namespace cam_proc

RCLCPP_COMPONENTS_REGISTER_NODE(cam_proc::PairView)
