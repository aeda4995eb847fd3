#include "footfall/client/terrain_session.h"

#include <cstdlib>

namespace footfall {

Status TerrainSession::LoadFile(const std::string& path, const TerrainLoadOptions& options,
                                TerrainHandle* out) {
  RawSamples samples;
  std::string error;
  const Status status = LoadTerrain(path, options, &samples, &error);
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

Status ParseHostPort(const std::string& text, RpcOptions* options, std::string* error) {
  const size_t colon = text.rfind(':');
  std::string host = colon == std::string::npos ? "" : text.substr(0, colon);
  const std::string port_text = colon == std::string::npos ? text : text.substr(colon + 1);
  char* end = nullptr;
  const long port = std::strtol(port_text.c_str(), &end, 10);
  if (port_text.empty() || *end != '\0' || port < 1 || port > 65535) {
    if (error) *error = "'" + text + "': expected HOST:PORT with a port from 1 to 65535";
    return Status::kInvalidArgument;
  }
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  options->host = host.empty() ? "127.0.0.1" : host;
  options->port = static_cast<int>(port);
  return Status::kOk;
}

}  // namespace footfall
