// Test helpers: run programs with a timeout, and a private Xvfb display for the viewer.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace footfall::test {

struct RunResult {
  int exit_code = -1;  // -1: killed by a signal or timed out
  bool timed_out = false;
  std::string out, err;
};

// Runs argv with extra environment entries ("NAME=value"; "NAME=" removes NAME), stdin from
// `stdin_text`, and kills it after timeout_s. Never hangs.
RunResult Run(const std::vector<std::string>& argv, const std::vector<std::string>& env,
              double timeout_s, const std::string& stdin_text = "");

// A program running in the background, killed when this goes out of scope. Its stdout and
// stderr go to files, readable while it runs.
class Child {
 public:
  Child(const std::vector<std::string>& argv, const std::vector<std::string>& env);
  ~Child();
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  // Waits until the stdout contains `text`, the program exits, or timeout_s passes.
  bool WaitForOutput(const std::string& text, double timeout_s);
  // Waits for the exit; false on timeout (the program is then killed).
  bool Wait(double timeout_s, int* exit_code);
  std::string Out() const;
  std::string Err() const;

 private:
  pid_t pid_ = -1;
  std::string out_path_, err_path_;
};

// "DISPLAY=:N" of an Xvfb started on first use (1280x1024x24, no TCP), stopped at exit.
// Throws with a clear message when Xvfb cannot be started.
std::string XDisplay();

// A fresh empty directory for one test's files, removed with them when the test program exits.
std::string TempDir();

std::string ReadFile(const std::string& path);
void WriteFile(const std::string& path, const std::string& text);

}  // namespace footfall::test
