#include "daemon/stop_signal.h"

#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <system_error>

namespace kinograph::daemon {

StopSignal::StopSignal() : fd_(eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK)) {
  if (fd_ < 0) throw std::system_error(errno, std::generic_category(), "eventfd");
}

StopSignal::~StopSignal() { close(fd_); }

void StopSignal::request() noexcept {
  flag_.store(true);
  const int saved = errno;  // a handler must leave errno as the interrupted code had it
  const std::uint64_t one = 1;
  // Cannot fail short of 2^64 - 2 requests; a failed write still leaves the flag set.
  [[maybe_unused]] const ssize_t n = write(fd_, &one, sizeof one);
  errno = saved;
}

}  // namespace kinograph::daemon
