#include "service_log.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <mutex>

#include "footfall/terrain/process_start.h"
#include "footfall/terrain/shown_text.h"

namespace footfall {

std::string EscapeControl(const std::string& text) {
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  const auto escape = [&](unsigned char u) {
    out += "\\x";
    out += kHex[u >> 4];
    out += kHex[u & 15];
  };
  for (size_t at = 0; at < text.size();) {
    const char c = text[at];
    const unsigned char u = static_cast<unsigned char>(c);
    const size_t length = Utf8SequenceLength(text, at);
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (length == 0) {
      escape(u);  // one byte, then read on from the next: the log stays in step
    } else if (IsControlCharacter(text, at, length)) {
      for (size_t k = 0; k < length; ++k) escape(static_cast<unsigned char>(text[at + k]));
    } else {
      out.append(text, at, length);
    }
    at += std::max<size_t>(length, 1);
  }
  return out;
}

namespace {

// A token bucket of rate-limited lines: LogLimited's, and LogLoadLimited's apart (so that a
// client's many loads leave room for the lines that say what failed).
struct LineBudget {
  explicit LineBudget(const char* lines) : what(lines) {}
  const char* what;  // the lines, for ReportUnwrittenErrors
  std::mutex mutex;
  double tokens = kErrorLineBurst;
  std::chrono::steady_clock::time_point refilled = std::chrono::steady_clock::now();
  uint64_t unwritten = 0;
  std::chrono::steady_clock::time_point first_unwritten;
};
LineBudget g_error_lines{"errors, batches past their time limit"};
LineBudget g_load_lines{"loads and unloads"};
LineBudget g_life_lines{"orphaned, freed and dropped terrains and uploads"};

// True when a line of `budget` may be written now; false counts it as unwritten.
bool TakeLine(LineBudget& budget) {
  std::lock_guard<std::mutex> lock(budget.mutex);
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - budget.refilled).count();
  budget.refilled = now;
  budget.tokens = std::min(kErrorLineBurst, budget.tokens + elapsed * kErrorLinesPerSecond);
  if (budget.tokens >= 1) {
    budget.tokens -= 1;
    return true;
  }
  if (budget.unwritten++ == 0) budget.first_unwritten = now;
  return false;
}

// The client whose request (or load) is being handled, for the log lines it causes; null
// between requests.
const std::string* g_log_client = nullptr;

// The stderr of WaitForSlowLogReaders: writes to descriptor 2, waiting when it is full.
struct PatientStderr {
  std::mutex mutex;
  uint64_t lost = 0;  // lines not written since the last one that was
};
PatientStderr g_stderr;

// Writes `size` bytes whole, waiting up to `wait_ms` for room before the first byte; a line
// begun is finished (within 5 s more). False when nothing was written.
bool WritePatiently(const char* data, size_t size, int wait_ms) {
  int error = 0;
  return WriteWaiting(STDERR_FILENO, data, size, wait_ms, 5000, &error) > 0;
}

// fopencookie's write: one call per line (the stream is line-buffered).
ssize_t WriteLogBytes(void*, const char* data, size_t size) {
  std::lock_guard<std::mutex> lock(g_stderr.mutex);
  size_t lines = 0;
  for (size_t i = 0; i < size; ++i) lines += data[i] == '\n';
  if (lines == 0) lines = 1;
  const int wait_ms = g_stderr.lost ? 0 : static_cast<int>(kLogWaitSeconds * 1000);
  if (g_stderr.lost) {
    pollfd p{STDERR_FILENO, POLLOUT, 0};
    if (poll(&p, 1, 0) > 0) {
      char note[160];
      const int n = std::snprintf(note, sizeof note,
                                  "footfalld: %llu log lines were lost: stderr was full (its "
                                  "reader fell behind)\n",
                                  static_cast<unsigned long long>(g_stderr.lost));
      if (n > 0 && WritePatiently(note, static_cast<size_t>(n), 0)) g_stderr.lost = 0;
    }
  }
  if (g_stderr.lost || !WritePatiently(data, size, wait_ms)) g_stderr.lost += lines;
  return static_cast<ssize_t>(size);  // stdio keeps no error: the next line is tried afresh
}

}  // namespace

void WaitForSlowLogReaders() {
  const int flags = fcntl(STDERR_FILENO, F_GETFL);
  if (flags < 0 || !(flags & O_NONBLOCK)) return;
  cookie_io_functions_t io{};
  io.write = WriteLogBytes;
  FILE* patient = fopencookie(nullptr, "w", io);
  if (!patient) return;
  setvbuf(patient, nullptr, _IOLBF, 4096);
  std::fflush(stderr);
  stderr = patient;  // glibc's stderr is a variable a program may set
}

void Log(const std::string& line) {
  // Every line may hold text from a client (paths, names, messages quoting them): escaped.
  if (line.compare(0, 7, "error: ") == 0) return LogLimited(line);
  std::fprintf(stderr, "footfalld: %s\n", EscapeControl(line).c_str());
}

void LogLimited(const std::string& line) {
  if (TakeLine(g_error_lines)) std::fprintf(stderr, "footfalld: %s\n", EscapeControl(line).c_str());
}

void LogLoadLimited(const std::string& line) {
  if (TakeLine(g_load_lines)) std::fprintf(stderr, "footfalld: %s\n", EscapeControl(line).c_str());
}

void LogLifeLimited(const std::string& line) {
  if (TakeLine(g_life_lines)) std::fprintf(stderr, "footfalld: %s\n", EscapeControl(line).c_str());
}

void ReportUnwrittenErrors() {
  for (LineBudget* budget : {&g_error_lines, &g_load_lines, &g_life_lines}) {
    std::lock_guard<std::mutex> lock(budget->mutex);
    if (budget->unwritten == 0) continue;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - budget->first_unwritten)
            .count();
    std::fprintf(stderr,
                 "footfalld: %llu lines (%s) not written in the last %.1f s (more than %g at "
                 "once or %g a second); every request was answered\n",
                 static_cast<unsigned long long>(budget->unwritten), budget->what, seconds,
                 kErrorLineBurst, kErrorLinesPerSecond);
    budget->unwritten = 0;
  }
}

LogClientScope::LogClientScope(const std::string* client) : saved_(g_log_client) {
  g_log_client = client;
}

LogClientScope::~LogClientScope() { g_log_client = saved_; }

std::string ClientSuffix() {
  return g_log_client && !g_log_client->empty() ? " (client " + *g_log_client + ")" : "";
}

void LogError(const char* proc, Status status, const std::string& message) {
  Log(std::string("error: ") + proc + ": " + StatusName(status) +
      (message.empty() ? "" : ": " + message) + ClientSuffix());
}

std::string SecondsText(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", seconds);
  return text;
}

}  // namespace footfall
