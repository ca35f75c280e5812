#ifndef NODELET_DRV_RANGE_NODELET_H
#define NODELET_DRV_RANGE_NODELET_H
#include <boost/shared_ptr.hpp>
#include <nodelet/nodelet.h>
#include "nodelet_drv/range_driver.h"

namespace nodelet_drv
{
class RangeNodelet : public nodelet::Nodelet
{
private:
  virtual void onInit();
  boost::shared_ptr<RangeDriver> driver_;
};
}  // namespace nodelet_drv
#endif
