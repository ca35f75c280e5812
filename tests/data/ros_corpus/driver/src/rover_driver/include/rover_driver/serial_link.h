#ifndef ROVER_DRIVER_SERIAL_LINK_H
#define ROVER_DRIVER_SERIAL_LINK_H

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace rover_driver {

// The base's serial protocol: framed requests and replies over a tty.
class SerialLink {
 public:
  SerialLink(const std::string& port, int baud);
  ~SerialLink();
  bool open();
  bool request(uint8_t command, const std::vector<uint8_t>& payload, std::vector<uint8_t>& reply);

 private:
  std::string port_;
  int baud_;
  int fd_{-1};
  std::mutex mutex_;
};

}  // namespace rover_driver

#endif
