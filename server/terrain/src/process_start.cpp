#include "footfall/terrain/process_start.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <iostream>

namespace footfall {

int OpenClosedStandardStreams() {
  int closed = 0;
  for (int fd = 0; fd <= 2; ++fd) {
    if (::fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    closed |= 1 << fd;
    // open returns the lowest free descriptor: this one, as those below it are open.
    const int opened = ::open("/dev/null", fd == 0 ? O_RDONLY : O_WRONLY);
    if (opened >= 0 && opened != fd) ::close(opened);
  }
  return closed;
}

namespace {

// Waits until `fd` takes more, at most `ms` milliseconds (-1: for ever); true when it does (or
// reports an error, which the next write meets).
bool WaitWritable(int fd, int ms) {
  pollfd p{fd, POLLOUT, 0};
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(std::max(ms, 0));
  for (;;) {
    int left = -1;
    if (ms >= 0) {
      left = static_cast<int>(std::max<int64_t>(
          0, std::chrono::duration_cast<std::chrono::milliseconds>(end -
                                                                   std::chrono::steady_clock::now())
                 .count()));
    }
    const int r = ::poll(&p, 1, left);
    if (r > 0) return true;
    if (r == 0 || errno != EINTR) return false;
  }
}

}  // namespace

size_t WriteWaiting(int fd, const char* data, size_t size, int first_wait_ms, int rest_wait_ms,
                    int* error) {
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n > 0) {
      done += static_cast<size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    const int why = n < 0 ? errno : EIO;
    if ((why == EAGAIN || why == EWOULDBLOCK) &&
        WaitWritable(fd, done == 0 ? first_wait_ms : rest_wait_ms))
      continue;
    *error = why;
    break;
  }
  return done;
}

bool FlushStandardOutput(const char* program) {
  if (std::cout.flush()) return true;
  const int why = errno;
  std::cerr << program << ": cannot write standard output"
            << (why ? std::string(": ") + std::strerror(why) : std::string()) << '\n';
  return false;
}

bool SignalIgnored(int signal_number) {
  struct sigaction current {};
  return ::sigaction(signal_number, nullptr, &current) == 0 && current.sa_handler == SIG_IGN;
}

std::string SystemErrorText(const std::system_error& e) {
  return std::string(e.what()) +
         (e.code() == std::errc::resource_unavailable_try_again
              ? " (a thread could not start: the limit on processes, ulimit -u, or memory)"
              : "");
}

}  // namespace footfall
