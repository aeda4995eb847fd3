// footfalld's count flags refused in the words of footfall's own: "--threads: 'X' is not a whole
// number from LO to HI", exit 2.
#include <sys/wait.h>

#include <cstdio>
#include <string>

#include <catch2/catch.hpp>

#include "server_process.h"

using footfall::test::ServerProcess;

namespace {

// Runs footfalld with `args` (shell words, quoted by the caller); its stderr and exit code.
std::string RunFootfalld(const std::string& args, int* exit_code) {
  const std::string command = std::string("timeout 5 ") + ServerProcess::Path() +
                              " --listen 127.0.0.1:0 --no-rpcbind " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string out;
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) out.append(buffer, n);
  const int status = pclose(pipe);
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

}  // namespace

TEST_CASE("footfalld refuses a bad --threads or --max-client-terrains as footfall does", "[rpc]") {
  struct Case {
    const char* flag;
    const char* value;
    const char* range;
  };
  const Case cases[] = {
      {"--threads", "1.5", "1 to 64"},
      {"--threads", "0", "1 to 64"},
      {"--threads", "65", "1 to 64"},
      {"--threads", "-1", "1 to 64"},
      {"--threads", "abc", "1 to 64"},
      {"--threads", "1e1", "1 to 64"},
      {"--threads", "99999999999999999999", "1 to 64"},
      {"--max-client-terrains", "0", "1 to 256"},
      {"--max-client-terrains", "2.5", "1 to 256"},
  };
  for (const Case& c : cases) {
    INFO(c.flag << " " << c.value);
    int code = 0;
    const std::string err = RunFootfalld(std::string(c.flag) + " '" + c.value + "'", &code);
    INFO(err);
    CHECK(code == 2);
    const std::string expected =
        std::string(c.flag) + ": '" + c.value + "' is not a whole number from " + c.range;
    CHECK(err.find(expected) != std::string::npos);
  }
}

TEST_CASE("footfalld refuses an empty --data-root or --port-file naming what it expected",
          "[rpc]") {
  // (An empty --data-root said "Directory does not exist: ", an empty --port-file was ignored.)
  int code = 0;
  std::string err = RunFootfalld("--data-root ''", &code);
  INFO(err);
  CHECK(code == 2);
  CHECK(err.find("--data-root: expected a folder, got an empty name") != std::string::npos);
  err = RunFootfalld("--port-file ''", &code);
  INFO(err);
  CHECK(code == 2);
  CHECK(err.find("--port-file: expected a file, got an empty name") != std::string::npos);
}
