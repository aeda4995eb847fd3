#include "footfall/terrain/process_start.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>

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
