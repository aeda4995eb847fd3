#include "footfall/client/terrain_session.h"

#include <arpa/inet.h>

#include <algorithm>
#include <cstdlib>

namespace footfall {

Status TerrainSession::LoadFile(const std::string& path, const TerrainLoadOptions& options,
                                TerrainHandle* out) {
  RawSamples samples;
  std::string error;
  last_file_report_ = TerrainLoadReport{};
  const Status status = LoadTerrain(path, options, &samples, &error, &last_file_report_);
  if (status != Status::kOk) return Fail(status, error);
  return LoadSamples(samples, path, out);
}

Foothold TerrainSession::Snap(TerrainHandle terrain, const Vec3& point) {
  Foothold f;
  const Status status = Snap(terrain, &point, 1, &f);
  if (status != Status::kOk) f = Foothold{}, f.status = status;
  return f;
}

Foothold TerrainSession::Next(TerrainHandle terrain, const StepQuery& query, double tolerance) {
  Foothold f;
  const Status status = Next(terrain, &query, 1, tolerance, &f);
  if (status != Status::kOk) f = Foothold{}, f.status = status;
  return f;
}

namespace {

bool IsIpv6Address(const std::string& text) {
  in6_addr address;
  return inet_pton(AF_INET6, text.c_str(), &address) == 1;
}

}  // namespace

bool ParseHost(const std::string& text, std::string* host) {
  std::string bare = text;
  if (bare.size() >= 2 && bare.front() == '[' && bare.back() == ']') {
    bare = bare.substr(1, bare.size() - 2);
    // Brackets hold an IPv6 address, nothing else ("[]" was an empty host, which every call
    // then failed to resolve).
    if (!IsIpv6Address(bare)) return false;
  }
  // Brackets left over, or colons in what is not an IPv6 address ("[::1" was host "[:" at port
  // 1, named "[[:]:1" when it could not be resolved; "127.0.0.1:7407" a host of that name).
  if (bare.find_first_of("[]") != std::string::npos ||
      (bare.find(':') != std::string::npos && !IsIpv6Address(bare)))
    return false;
  *host = bare;
  return true;
}

Status ParseHostPort(const std::string& text, RpcOptions* options, std::string* error) {
  const size_t colon = text.rfind(':');
  // A bare IPv6 address (`::1`, `fe80::1`), as footfalld's --listen takes it: its default port.
  // (`::1:7407` is ::1 at port 7407: what precedes its last colon is an address.)
  if (colon != std::string::npos && IsIpv6Address(text) && !IsIpv6Address(text.substr(0, colon))) {
    options->host = text;
    options->port = RpcOptions{}.port;
    return Status::kOk;
  }
  std::string host = colon == std::string::npos ? "" : text.substr(0, colon);
  const std::string port_text = colon == std::string::npos ? text : text.substr(colon + 1);
  // Digits alone: strtol would also take a leading space or sign ("host: 7407", "host:+7407").
  const bool digits = !port_text.empty() && port_text.size() <= 5 &&
                      std::all_of(port_text.begin(), port_text.end(),
                                  [](unsigned char c) { return c >= '0' && c <= '9'; });
  const long port = digits ? std::strtol(port_text.c_str(), nullptr, 10) : 0;
  if (port < 1 || port > 65535) {
    if (error) *error = "'" + text + "': expected HOST:PORT with a port from 1 to 65535";
    return Status::kInvalidArgument;
  }
  if (!ParseHost(host, &host)) {
    if (error)
      *error = "'" + text +
               "': expected HOST:PORT, an IPv6 address in brackets ([::1]:7407) or alone (::1)";
    return Status::kInvalidArgument;
  }
  options->host = host.empty() ? "127.0.0.1" : host;
  options->port = static_cast<int>(port);
  return Status::kOk;
}

std::string FormatHostPort(const std::string& host, int port) {
  // Only IPv6 addresses hold colons (host names and IPv4 addresses never do).
  const bool v6 = host.find(':') != std::string::npos;
  return (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

}  // namespace footfall
