#include "service_log.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>

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

// The token bucket of LogLimited.
struct ErrorLineBudget {
  std::mutex mutex;
  double tokens = kErrorLineBurst;
  std::chrono::steady_clock::time_point refilled = std::chrono::steady_clock::now();
  uint64_t unwritten = 0;
  std::chrono::steady_clock::time_point first_unwritten;
};
ErrorLineBudget g_error_lines;

// True when an error line may be written now; false counts it as unwritten.
bool TakeErrorLine() {
  std::lock_guard<std::mutex> lock(g_error_lines.mutex);
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - g_error_lines.refilled).count();
  g_error_lines.refilled = now;
  g_error_lines.tokens =
      std::min(kErrorLineBurst, g_error_lines.tokens + elapsed * kErrorLinesPerSecond);
  if (g_error_lines.tokens >= 1) {
    g_error_lines.tokens -= 1;
    return true;
  }
  if (g_error_lines.unwritten++ == 0) g_error_lines.first_unwritten = now;
  return false;
}

// The client whose request (or load) is being handled, for the log lines it causes; null
// between requests.
const std::string* g_log_client = nullptr;

}  // namespace

void Log(const std::string& line) {
  // Every line may hold text from a client (paths, names, messages quoting them): escaped.
  if (line.compare(0, 7, "error: ") == 0) return LogLimited(line);
  std::fprintf(stderr, "footfalld: %s\n", EscapeControl(line).c_str());
}

void LogLimited(const std::string& line) {
  if (TakeErrorLine()) std::fprintf(stderr, "footfalld: %s\n", EscapeControl(line).c_str());
}

void ReportUnwrittenErrors() {
  std::lock_guard<std::mutex> lock(g_error_lines.mutex);
  if (g_error_lines.unwritten == 0) return;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                                       g_error_lines.first_unwritten)
                             .count();
  std::fprintf(stderr,
               "footfalld: %llu lines (errors, batches past their time limit) not written in the "
               "last %.1f s (more than %g at once or %g a second); every request was answered\n",
               static_cast<unsigned long long>(g_error_lines.unwritten), seconds, kErrorLineBurst,
               kErrorLinesPerSecond);
  g_error_lines.unwritten = 0;
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
