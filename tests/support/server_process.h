// ServerProcess: a real footfalld started for a test on loopback, stopped (SIGTERM, then
// SIGKILL) when the object goes away.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace footfall::test {

class ServerProcess {
 public:
  // The footfalld binary under test.
  static const char* Path();
  // Starts footfalld with --listen 127.0.0.1:PORT (0: any free port; an --listen among the extra
  // arguments replaces it) and extra arguments, and
  // waits until it listens. Throws std::runtime_error if it does not start within 10 s.
  // `max_open_files` > 0: the server runs with RLIMIT_NOFILE (soft and hard) at that many.
  explicit ServerProcess(int port = 0, std::vector<std::string> extra_args = {"--no-rpcbind"},
                         long max_open_files = 0);
  ~ServerProcess();
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  // Sends SIGKILL and reaps the process.
  void Kill();
  // Sends SIGTERM and waits up to 5 s; returns the wait status, or -1 if it did not exit.
  int Terminate();
  // Resident memory of the server process, in KiB.
  long RssKiB() const;
  // CPU time the server process has used so far (user and system, all threads) [Units: s].
  double CpuSeconds() const;
  // Everything the server wrote to stderr so far.
  std::string Log() const;

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  std::string dir_;
};

}  // namespace footfall::test
