// footfalld's log on stderr: one line per event, prefixed "footfalld: ", with text that may come
// from a client or the command line escaped, and the lines a client can cause rate-limited.
#pragma once

#include <string>

#include "footfall/terrain/status.h"

namespace footfall {

// `text` with backslashes, control characters (C0, DEL and C1) and bytes that are not UTF-8
// escaped (\\, \n, \r, \t, \xHH for each byte), so that text from a client cannot start a log
// line of its own nor send terminal escapes, and the log stays UTF-8; other characters are kept
// as they are.
std::string EscapeControl(const std::string& text);

// Makes every write to stderr (stdio's stderr: every log line) wait for a non-blocking stderr
// that is full, up to kLogWaitSeconds a line, when stderr is non-blocking at start (a parent
// process made it so, as Node.js does with the pipes and terminals it hands on): such lines
// were lost without a word. A line that still does not fit is counted, and the next line
// written says how many were lost; while lines are being lost, none waits (a stalled reader
// costs the server one wait, not one per line). A blocking stderr is left as it is. Call first
// thing in main, after OpenClosedStandardStreams.
constexpr double kLogWaitSeconds = 0.2;
void WaitForSlowLogReaders();

// Writes one log line (escaped). Lines starting "error: " are rate-limited as LogLimited's.
void Log(const std::string& line);

// Writes a line a client can cause as often as it likes (errors, batches cut at their time
// limit): at most kErrorLineBurst at once and kErrorLinesPerSecond after (a token
// bucket); the lines beyond are counted for ReportUnwrittenErrors. A client repeating a refused
// request thousands of times a second wrote as many lines, and could fill the disk.
constexpr double kErrorLineBurst = 100;
constexpr double kErrorLinesPerSecond = 10;
void LogLimited(const std::string& line);

// Writes a "loaded terrain" or "unloaded terrain" line within a budget of its own, as
// LogLimited's (a client loading and unloading a small terrain in a loop wrote thousands a
// second; many loads in a row must not use up the error lines' budget).
void LogLoadLimited(const std::string& line);

// Writes a line of a terrain's or an upload's end that a client going away causes ("orphaned",
// "freed orphaned terrain", an upload or a load "dropped" or "cancelled") within a budget of its
// own, as LogLimited's (a client loading and closing in a loop wrote megabytes a second).
void LogLifeLimited(const std::string& line);

// Says in one line how many rate-limited lines were not written since the first of them, if
// any. Call about once a second.
void ReportUnwrittenErrors();

// Logs "error: PROC: STATUS[: message]" and the client being served (ClientSuffix).
void LogError(const char* proc, Status status, const std::string& message);

// Names `client` (its address as text) in the log lines written while the scope lives: the
// client whose request or load is being handled. Scopes nest; the loop is single-threaded.
class LogClientScope {
 public:
  explicit LogClientScope(const std::string* client);
  ~LogClientScope();
  LogClientScope(const LogClientScope&) = delete;
  LogClientScope& operator=(const LogClientScope&) = delete;

 private:
  const std::string* saved_;
};

// " (client ADDR:PORT)" within a LogClientScope, else "".
std::string ClientSuffix();

// "N s", with decimals only when needed. [Units: s]
std::string SecondsText(double seconds);

}  // namespace footfall
