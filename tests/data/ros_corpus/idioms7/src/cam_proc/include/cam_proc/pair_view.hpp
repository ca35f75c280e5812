#ifndef CAM_PROC__PAIR_VIEW_HPP_
#define CAM_PROC__PAIR_VIEW_HPP_

#include <image_transport/subscriber_filter.hpp>
#include <message_filters/subscriber.h>
#include <rclcpp/rclcpp.hpp>
#include <stereo_msgs/msg/disparity_image.hpp>

namespace cam_proc
{
using stereo_msgs::msg::DisparityImage;

class PairView : public rclcpp::Node
{
public:
  explicit PairView(const rclcpp::NodeOptions & options);

private:
  image_transport::SubscriberFilter left_, right_;
  message_filters::Subscriber<DisparityImage> disparity_;
};
}  // namespace cam_proc

#endif  // CAM_PROC__PAIR_VIEW_HPP_
