#include "process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace footfall::test {
namespace {

using Clock = std::chrono::steady_clock;

// In the child: applies env entries, redirects, and execs. Never returns.
[[noreturn]] void Exec(const std::vector<std::string>& argv, const std::vector<std::string>& env,
                       int in_fd, int out_fd, int err_fd) {
  for (const std::string& e : env) {
    const size_t eq = e.find('=');
    const std::string name = e.substr(0, eq), value = e.substr(eq + 1);
    if (value.empty())
      unsetenv(name.c_str());
    else
      setenv(name.c_str(), value.c_str(), 1);
  }
  if (in_fd >= 0) dup2(in_fd, 0);
  if (out_fd >= 0) dup2(out_fd, 1);
  if (err_fd >= 0) dup2(err_fd, 2);
  setpgid(0, 0);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  execvp(args[0], args.data());
  dprintf(2, "cannot run %s: %s\n", args[0], std::strerror(errno));
  _exit(127);
}

bool WaitPid(pid_t pid, double timeout_s, int* code) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    int status = 0;
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) {
      *code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      return true;
    }
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

void Kill(pid_t pid) {
  kill(-pid, SIGKILL);
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
}

// The directories TempDir made, removed with their files when the test program exits.
class MadeDirs {
 public:
  ~MadeDirs() {
    for (const std::string& d : dirs_) Remove(d);
  }
  void Add(const std::string& dir) {
    std::lock_guard<std::mutex> lock(mutex_);
    dirs_.push_back(dir);
  }
  static void Remove(const std::string& dir) {
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> dirs_;
};

MadeDirs& Made() {
  static MadeDirs made;
  return made;
}

}  // namespace

std::string TempDir() {
  std::string pattern =
      (std::filesystem::temp_directory_path() / "footfall-viewer-test-XXXXXX").string();
  if (!mkdtemp(&pattern[0])) throw std::runtime_error("mkdtemp failed");
  Made().Add(pattern);
  return pattern;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void WriteFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

RunResult Run(const std::vector<std::string>& argv, const std::vector<std::string>& env,
              double timeout_s, const std::string& stdin_text) {
  const std::string dir = TempDir();
  const std::string in_path = dir + "/stdin", out_path = dir + "/stdout",
                    err_path = dir + "/stderr";
  WriteFile(in_path, stdin_text);
  RunResult result;
  const pid_t pid = fork();
  if (pid == 0) {
    const int in = open(in_path.c_str(), O_RDONLY);
    const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    Exec(argv, env, in, out, err);
  }
  if (!WaitPid(pid, timeout_s, &result.exit_code)) {
    Kill(pid);
    result.timed_out = true;
    result.exit_code = -1;
  }
  result.out = ReadFile(out_path);
  result.err = ReadFile(err_path);
  MadeDirs::Remove(dir);
  return result;
}

Child::Child(const std::vector<std::string>& argv, const std::vector<std::string>& env) {
  const std::string dir = TempDir();
  out_path_ = dir + "/stdout", err_path_ = dir + "/stderr";
  pid_ = fork();
  if (pid_ == 0) {
    const int in = open("/dev/null", O_RDONLY);
    const int out = open(out_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(err_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    Exec(argv, env, in, out, err);
  }
}

Child::~Child() {
  if (pid_ > 0) Kill(pid_);
}

bool Child::WaitForOutput(const std::string& text, double timeout_s) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (Clock::now() < deadline) {
    if (Out().find(text) != std::string::npos) return true;
    int status = 0;
    if (pid_ > 0 && waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return Out().find(text) != std::string::npos;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

bool Child::Wait(double timeout_s, int* exit_code) {
  if (pid_ <= 0) {
    *exit_code = -1;
    return true;
  }
  if (!WaitPid(pid_, timeout_s, exit_code)) {
    Kill(pid_);
    pid_ = -1;
    return false;
  }
  pid_ = -1;
  return true;
}

std::string Child::Out() const { return ReadFile(out_path_); }
std::string Child::Err() const { return ReadFile(err_path_); }

namespace {

struct Xvfb {
  pid_t pid = -1;
  std::string display;
  ~Xvfb() {
    if (pid > 0) Kill(pid);
  }
};

}  // namespace

std::string XDisplay() {
  static Xvfb server;
  if (!server.display.empty()) return "DISPLAY=" + server.display;
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const int null = open("/dev/null", O_RDWR);
    Exec({"Xvfb", "-displayfd", std::to_string(fds[1]), "-screen", "0", "1280x1024x24", "-nolisten",
          "tcp"},
         {}, null, null, null);
  }
  close(fds[1]);
  server.pid = pid;
  // Xvfb writes its display number and a newline once it accepts clients.
  std::string number;
  const auto deadline = Clock::now() + std::chrono::seconds(20);
  while (number.find('\n') == std::string::npos && Clock::now() < deadline) {
    pollfd p{fds[0], POLLIN, 0};
    if (poll(&p, 1, 100) <= 0) continue;
    char buffer[32];
    const ssize_t n = read(fds[0], buffer, sizeof buffer);
    if (n <= 0) break;
    number.append(buffer, static_cast<size_t>(n));
  }
  close(fds[0]);
  if (number.find('\n') == std::string::npos) {
    throw std::runtime_error(
        "could not start Xvfb (install the viewer group: scripts/install-deps.sh viewer)");
  }
  server.display = ":" + number.substr(0, number.find('\n'));
  return "DISPLAY=" + server.display;
}

}  // namespace footfall::test
