// CountingSession: a session that forwards every call to another (a real one) and counts the
// query calls it was given, to check how callers batch their queries.
#pragma once

#include <atomic>
#include <stdexcept>
#include <string>

#include "footfall/client/terrain_session.h"

namespace footfall::test {

// Answers as a session that is not in process, whatever the other is (as footfalld does).
class CountingSession final : public TerrainSession {
 public:
  explicit CountingSession(TerrainSession& inner) : inner_(inner) {}
  Status LoadServerFile(const std::string& path, const TerrainLoadOptions& options,
                        TerrainHandle* out) override {
    return Pass(inner_.LoadServerFile(path, options, out));
  }
  Status LoadSamples(const RawSamples& samples, const std::string& name,
                     TerrainHandle* out) override {
    return Pass(inner_.LoadSamples(samples, name, out));
  }
  Status Info(TerrainHandle terrain, TerrainInfo* out) override {
    ++info_calls;
    return Pass(inner_.Info(terrain, out));
  }
  Status Unload(TerrainHandle terrain) override { return Pass(inner_.Unload(terrain)); }
  Status Snap(TerrainHandle terrain, const Vec3* points, size_t count, Foothold* out) override {
    ++query_calls;
    if (throw_on_snap) throw std::runtime_error("snap failed inside the session");
    return Pass(inner_.Snap(terrain, points, count, out));
  }
  Status Normal(TerrainHandle terrain, const Vec3* points, size_t count, Foothold* out) override {
    ++query_calls;
    return Pass(inner_.Normal(terrain, points, count, out));
  }
  Status Next(TerrainHandle terrain, const StepQuery* queries, size_t count, double tolerance,
              Foothold* out) override {
    ++query_calls;
    return Pass(inner_.Next(terrain, queries, count, tolerance, out));
  }
  std::string Describe() const override { return "counting " + inner_.Describe(); }
  bool InProcess() const override { return false; }

  std::atomic<int> query_calls{0};  // Snap, Normal and Next
  std::atomic<int> info_calls{0};
  std::atomic<bool> throw_on_snap{false};  // Snap throws, as a failing session might

 private:
  Status Pass(Status s) { return s == Status::kOk ? s : Fail(s, inner_.last_error()); }
  TerrainSession& inner_;
};

}  // namespace footfall::test
