// footfalld: the footfall terrain query server (ONC RPC over TCP).
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <system_error>
#include <thread>

#include <CLI/CLI.hpp>

#include "footfall/service/pinned_file.h"
#include "footfall/service/rpc_server.h"
#include "footfall/terrain/decimal_number.h"
#include "footfall/terrain/large_memory.h"
#include "footfall/terrain/output_file.h"
#include "footfall/terrain/process_start.h"
#include "footfall/version.h"
#include "service_log.h"

namespace {

footfall::RpcServer* g_server = nullptr;

void OnStopSignal(int) {
  if (g_server) g_server->Stop();
}

bool IsIpv6Address(const std::string& text) {
  in6_addr address;
  return inet_pton(AF_INET6, text.c_str(), &address) == 1;
}

// "ADDR:PORT", ":PORT", "PORT" or "ADDR" (the default port 7407); an IPv6 address in brackets
// ("[::1]:7407", "[::1]") or bare, as `footfall --server` reads it: "::1" takes the default
// port, "::1:7408" is ::1 at port 7408 (what precedes the last colon is an address).
// ("::1:48113" was refused as an address that does not resolve, "::1:4811" listened on the
// address ::1:4811, and "0.0.0.0" was taken for a port.)
bool ParseListen(const std::string& text, std::string* host, int* port) {
  if (text.empty()) return false;
  std::string h, p;
  const size_t colon = text.rfind(':');
  if (!text.empty() && text.front() == '[') {
    const size_t close = text.find(']');
    if (close == std::string::npos || close == 1) return false;
    h = text.substr(1, close - 1);
    const std::string rest = text.substr(close + 1);
    if (rest.empty()) {
      p = "7407";
    } else if (rest.front() == ':') {
      p = rest.substr(1);
    } else {
      return false;
    }
  } else if (std::count(text.begin(), text.end(), ':') > 1) {
    if (IsIpv6Address(text) && !IsIpv6Address(text.substr(0, colon))) {
      h = text, p = "7407";  // a bare IPv6 address: its last group is no port
    } else {
      h = text.substr(0, colon), p = text.substr(colon + 1);
      if (!IsIpv6Address(h)) return false;
    }
  } else if (colon != std::string::npos) {
    h = text.substr(0, colon), p = text.substr(colon + 1);
  } else if (!text.empty() && std::all_of(text.begin(), text.end(),
                                          [](unsigned char c) { return c >= '0' && c <= '9'; })) {
    p = text;
  } else {
    h = text, p = "7407";  // an address alone
    if (std::any_of(h.begin(), h.end(), [](unsigned char c) { return std::isspace(c); }))
      return false;
  }
  // Digits alone: strtol would also take a leading space or sign (": 80", ":+80").
  if (p.empty() || p.size() > 5 ||
      !std::all_of(p.begin(), p.end(), [](unsigned char c) { return c >= '0' && c <= '9'; }))
    return false;
  const long value = std::strtol(p.c_str(), nullptr, 10);
  if (value > 65535) return false;
  *host = h.empty() ? "127.0.0.1" : h;
  *port = static_cast<int>(value);
  return true;
}

// A timeout flag's check: a finite number of seconds from `lo` (exclusive unless `zero_ok`) to
// 1e9. CLI11's own number checks let NaN through, and print the limits of double in full.
CLI::Validator Seconds(bool zero_ok) {
  const std::string expected =
      std::string("a number of seconds ") + (zero_ok ? "from 0" : "above 0") + " to 1e+09";
  return CLI::Validator(
      [expected, zero_ok](std::string& input) -> std::string {
        char* end = nullptr;
        const double x = std::strtod(input.c_str(), &end);
        const bool ok = !input.empty() && *end == '\0' && std::isfinite(x) && x <= 1e9 &&
                        (zero_ok ? x >= 0 : x > 0);
        return ok ? std::string() : "'" + input + "' is not " + expected;
      },
      "SECONDS");
}

// A count flag's check: a whole number written in digits alone, from lo to hi (hi < 10^18),
// refused as "'1.5' is not a whole number from LO to HI", as footfall's own flags say it
// (CLI11's range check said "Value 1.5 not in range [1 - 64]", and its conversion "Could not
// convert").
CLI::Validator WholeRange(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& input) {
        // Without its leading zeros: CLI11 converts in base 0, which read "010" as octal 8.
        const std::string digits = footfall::WithoutLeadingZeros(input);
        if (!footfall::WholeNumberProblem(digits, lo, hi).empty())
          return footfall::WholeNumberProblem(input, lo, hi);
        input = digits;
        return std::string();
      },
      "INT in [" + std::to_string(lo) + " - " + std::to_string(hi) + "]");
}

// A path flag's check: not empty (CLI11 said "Directory does not exist: " for an empty
// --data-root, and an empty --port-file was ignored).
CLI::Validator NonEmptyPath(const char* what) {
  return CLI::Validator(
      [what](std::string& input) -> std::string {
        return input.empty() ? std::string("expected ") + what + ", got an empty name" : "";
      },
      "");
}

// --data-root's check: a folder that exists. (CLI11's ExistingDirectory looks the path up in a
// function that may not throw: memory running out there was an abort.)
CLI::Validator ExistingFolder() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        struct stat st;
        if (stat(input.c_str(), &st) != 0) {
          // (A folder behind one that may not be searched is there: "no such folder" was
          // said of it too.)
          const int err = errno;
          return "'" + input + "': " +
                 (err == ENOENT || err == ENOTDIR ? "no such folder" : "cannot be reached") + " (" +
                 std::strerror(err) + ")";
        }
        return S_ISDIR(st.st_mode) ? std::string() : "'" + input + "' is not a folder";
      },
      "DIR");
}

// --max-samples: a whole number of samples up to 1e12 (CLI11 took "-5" for a huge budget).
CLI::Validator SampleCount() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        // Digits, or a number written with an exponent ("2e7"), rewritten as digits for CLI11.
        char* end = nullptr;
        const double x = std::strtod(input.c_str(), &end);
        const bool ok = !input.empty() && *end == '\0' && std::isdigit(uint8_t(input[0])) &&
                        input.find_first_not_of("0123456789.eE+") == std::string::npos &&
                        std::isfinite(x) && x >= 0 && x <= 1e12 && x == std::floor(x);
        if (!ok) return "'" + input + "' is not a whole number of samples from 0 to 1e12";
        input = std::to_string(static_cast<unsigned long long>(x));
        return std::string();
      },
      "SAMPLES");
}

// Writes `port` and a line end to `path`. On failure false, with a message naming the file.
bool WritePortFile(const std::string& path, int port, std::string* message) {
  // Written whole beside it and renamed over it: a supervisor waiting for the file never reads
  // it empty, and a failed write (a full disk) leaves no empty file behind.
  std::string error;
  if (footfall::ReplaceFile(path, std::to_string(port) + "\n", &error) == footfall::Status::kOk)
    return true;
  *message = "--port-file " + path + ": cannot write the port there: " + error;
  return false;
}

}  // namespace

// Raises the soft limit on open descriptors to the hard one: at the limit, libtirpc closes the
// least recently active connections to accept new ones (an idle client that owns terrains
// among them), so the limit is what a flood of connections must reach.
static void RaiseOpenFileLimit() {
  struct rlimit limit;
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0 || limit.rlim_cur >= limit.rlim_max) return;
  const rlim_t before = limit.rlim_cur;
  // (An unlimited hard limit still stops at the kernel's nr_open: ask for a million.)
  limit.rlim_cur = limit.rlim_max == RLIM_INFINITY ? rlim_t{1} << 20 : limit.rlim_max;
  if (setrlimit(RLIMIT_NOFILE, &limit) == 0)
    std::fprintf(stderr, "footfalld: open descriptor limit raised from %llu to %llu\n",
                 static_cast<unsigned long long>(before),
                 static_cast<unsigned long long>(limit.rlim_cur));
}

namespace {

// footfalld's work, from its command line to its stop; its exit status.
int Serve(int argc, char** argv) {
  // Sockets and files opened later never take descriptor 0, 1 or 2 (with all three closed,
  // the log went into the first client's connection, which then hung).
  footfall::OpenClosedStandardStreams();
  footfall::WaitForSlowLogReaders();  // a non-blocking stderr lost log lines without a word
  CLI::App app{"footfalld: serves footfall terrain queries over ONC RPC (TCP)"};
  app.set_version_flag("--version", "footfalld " FOOTFALL_VERSION,
                       "Print footfalld's version and exit");
  std::string listen = "127.0.0.1:7407";
  footfall::RpcServerOptions options;
  std::string port_file;
  bool no_rpcbind = false;
  app.add_option("--listen", listen, "ADDR:PORT to listen on (port 0 picks a free one)");
  app.add_option("--data-root", options.data_root,
                 "Directory that confines server-side terrain loads (none: refused)")
      ->check(NonEmptyPath("a folder"))
      ->check(ExistingFolder());
  app.add_flag("--no-rpcbind", no_rpcbind, "Do not register with rpcbind");
  options.batch_threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  app.add_option("--threads", options.batch_threads,
                 "Threads per batch query (default: the hardware's cores)")
      ->transform(WholeRange(1, 64));
  // (Its count is asked of the option itself: App::count looks the name up in a function that
  // may not throw, so memory running out there was an abort.)
  const CLI::Option* max_samples =
      app.add_option("--max-samples", options.limits.max_total_samples,
                     "Samples held over all terrains and uploads (default 268435456, 2^28, or what "
                     "memory holds at 100 bytes per sample)")
          ->transform(SampleCount());
  app.add_option("--orphan-timeout", options.limits.orphan_idle_s,
                 "Seconds without queries after which a terrain whose connection has closed is "
                 "freed (default 600)")
      ->check(Seconds(true));
  app.add_option("--batch-time-limit", options.batch_time_limit_s,
                 "Seconds a batch may take before its remaining queries are answered "
                 "limit_exceeded, for the client to ask again, so that other clients are served "
                 "meanwhile (default 1)")
      ->check(Seconds(false));
  app.add_option("--upload-timeout", options.limits.upload_idle_s,
                 "Seconds an upload may go without samples before it is dropped (default 120)")
      ->check(Seconds(false));
  app.add_option("--max-client-terrains", options.limits.max_client_terrains,
                 "Terrains one connection may hold loaded at once (default 64)")
      ->transform(WholeRange(1, 256));
  app.add_option("--unread-timeout", options.unread_timeout_s,
                 "Seconds a client may leave its replies unread, with no room for another, "
                 "before its connection is closed (default 30)")
      ->check(Seconds(false));
  app.add_option("--request-timeout", options.request_timeout_s,
                 "Seconds a client may leave a request half sent before its connection is "
                 "closed (default 30; connections idle between requests are kept)")
      ->check(Seconds(false));
  app.add_option("--port-file", port_file,
                 "Write the bound port to this file before serving (exit 1 if it cannot)")
      ->check(NonEmptyPath("a file"));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    errno = 0;                       // what the write of the text sets, not an earlier call's
    if (app.exit(e) != 0) return 2;  // a refused flag: 2, as for --listen
    // --help or --version: exit 0 only when its text was written.
    return footfall::FlushStandardOutput("footfalld") ? 0 : 1;
  }
  std::string error;
  if (!ParseListen(listen, &options.listen_host, &options.port)) {
    std::fprintf(
        stderr,
        "footfalld: --listen '%s': expected ADDR:PORT with a port from 0 to 65535 (an IPv6 "
        "address in brackets: [::1]:7407)\n",
        listen.c_str());
    return 2;
  }
  options.use_rpcbind = !no_rpcbind;
  // A root this user may not search would refuse every load: said now, not at the first one.
  if (!options.data_root.empty() &&
      faccessat(AT_FDCWD, options.data_root.c_str(), X_OK, AT_EACCESS) != 0) {
    std::fprintf(stderr,
                 "footfalld: --data-root %s: this user (uid %u) may not search it (%s), so no "
                 "load could succeed: give a folder it may read\n",
                 options.data_root.c_str(), static_cast<unsigned>(geteuid()), std::strerror(errno));
    return 2;
  }

  std::signal(SIGPIPE, SIG_IGN);
  // Past the file size limit (ulimit -f) a write fails with EFBIG and is reported, instead of
  // the signal killing footfalld with its port file half made.
  std::signal(SIGXFSZ, SIG_IGN);
  setvbuf(stderr, nullptr, _IOLBF, 0);
  // Server-side loads read through a private directory: one that cannot be made is said now.
  if (!options.data_root.empty() && !footfall::CanMakePrivateDirectory(&error))
    std::fprintf(stderr, "footfalld: warning: server-side loads will fail: %s\n", error.c_str());
  // The default budget, lowered to what this machine's memory holds: a finished upload peaks
  // near 100 bytes per sample (its samples and its grid at once).
  if (max_samples->count() == 0) {
    constexpr double kPeakBytesPerSample = 100;
    const double fits = footfall::UsableMemoryBytes() / kPeakBytesPerSample;
    if (fits > 0 && fits < static_cast<double>(options.limits.max_total_samples)) {
      options.limits.max_total_samples = static_cast<size_t>(std::max(fits, 1e6));
      std::fprintf(stderr,
                   "footfalld: sample budget %zu (this machine's memory at %.0f bytes per "
                   "sample; --max-samples sets another)\n",
                   options.limits.max_total_samples, kPeakBytesPerSample);
    }
  }
  RaiseOpenFileLimit();
  bool abandoned_load = false;
  try {
    // The port file is written before footfalld says it listens: a supervisor waiting for the
    // file would wait forever, and one reading the log would take a server that exits for one
    // that serves.
    if (!port_file.empty())
      options.on_bound = [&port_file](int port, std::string* message) {
        return WritePortFile(port_file, port, message);
      };
    footfall::RpcServer server(options);
    // The stop signals are handled before Start registers with rpcbind and says it listens: a
    // supervisor that stops footfalld as soon as it reads that line killed it, still registered.
    // (Stopped while starting, it starts, then stops at once.)
    g_server = &server;
    struct Unset {  // before the server is destroyed, whichever way this block is left
      ~Unset() { g_server = nullptr; }
    } unset;
    struct sigaction action {};
    action.sa_handler = OnStopSignal;  // no SA_RESTART: poll returns EINTR at once
    sigaction(SIGTERM, &action, nullptr);
    // SIGINT and SIGHUP (a closed terminal) stop it cleanly, unregistered, unless ignored when
    // it started (`nohup footfalld`, a background job of a script): those keep serving.
    for (const int signal_number : {SIGINT, SIGHUP})
      if (!footfall::SignalIgnored(signal_number)) sigaction(signal_number, &action, nullptr);
    if (!server.Start(&error)) {
      std::fprintf(stderr, "footfalld: %s\n", error.c_str());
      return 1;
    }
    server.Run();
    abandoned_load = server.abandoned_load();
  } catch (const std::system_error& e) {  // the server, destroyed, is unregistered
    // std::thread's failure to start one (ulimit -u, or memory for its stack).
    std::fprintf(stderr, "footfalld: %s\n", footfall::SystemErrorText(e).c_str());
    return 1;
  }
  if (abandoned_load) {
    // The load's thread still reads the file: end without running static destructors (its
    // private name for the file is removed first).
    footfall::RemovePinnedNames();
    std::fflush(nullptr);
    std::_Exit(0);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Serve(argc, argv);
  } catch (const std::bad_alloc&) {
    // Memory ran out starting (its command line, its lists, its threads' records): said, not
    // an abort. Once serving, the loop and the dispatcher answer memory running out themselves.
    std::fputs("footfalld: error: out of memory; stopped\n", stderr);
    return 1;
  }
}
