#include "rover_driver/serial_link.h"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

namespace rover_driver {

SerialLink::SerialLink(const std::string& port, int baud) : port_(port), baud_(baud) {}

SerialLink::~SerialLink() {
  if (fd_ >= 0) {
    ::close(fd_);
  }
}

bool SerialLink::open() {
  fd_ = ::open(port_.c_str(), O_RDWR | O_NOCTTY);
  return fd_ >= 0;
}

bool SerialLink::request(uint8_t command, const std::vector<uint8_t>& payload, std::vector<uint8_t>& reply) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<uint8_t> frame{0xAA, command, static_cast<uint8_t>(payload.size())};
  frame.insert(frame.end(), payload.begin(), payload.end());
  if (::write(fd_, frame.data(), frame.size()) != static_cast<ssize_t>(frame.size())) {
    return false;
  }
  reply.resize(32);
  ssize_t got = ::read(fd_, reply.data(), reply.size());
  reply.resize(got > 0 ? got : 0);
  return got > 0;
}

}  // namespace rover_driver
