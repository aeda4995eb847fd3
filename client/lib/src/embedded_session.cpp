// The embedded backend: the terrain engine in this process.
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "footfall/client/terrain_session.h"
#include "footfall/terrain/batch_pool.h"
#include "handle_counter.h"

namespace footfall {
namespace {

class EmbeddedSession final : public TerrainSession {
 public:
  // Batches are shared with the threads - 1 persistent workers of the process's shared pool.
  EmbeddedSession(int threads, TerrainHandle first_handle)
      : pool_(SharedBatchPool(threads)), handles_(first_handle) {}

  Status LoadServerFile(const std::string& path, const TerrainLoadOptions& options,
                        TerrainHandle* out) override {
    return TerrainSession::LoadFile(path, options, out);
  }

  Status LoadSamples(const RawSamples& samples, const std::string& name,
                     TerrainHandle* out) override {
    if (samples.size() == 0)
      return Fail(Status::kInvalidArgument, name + ": no samples (a terrain needs at least one)");
    RawSamples copy = samples;
    std::string error;
    Status status = ValidateAndNormalize(&copy, &error);
    if (status != Status::kOk) return Fail(status, name + ": " + error);
    Entry entry;
    entry.name = name;
    status = TerrainGrid::Build(copy, GridOptions{}, &entry.grid, &error);
    if (status != Status::kOk) return Fail(status, name + ": " + error);
    const TerrainHandle handle =
        handles_.Next([this](TerrainHandle h) { return terrains_.count(h) != 0; });
    terrains_.emplace(handle, std::move(entry));
    *out = handle;
    return Status::kOk;
  }

  Status Info(TerrainHandle terrain, TerrainInfo* out) override {
    const Entry* e = Find(terrain);
    if (!e) return Unknown(terrain);
    out->name = e->name;
    out->stats = e->grid.stats();
    return Status::kOk;
  }

  Status Unload(TerrainHandle terrain) override {
    if (terrains_.erase(terrain) == 0) return Unknown(terrain);
    return Status::kOk;
  }

  Status Snap(TerrainHandle terrain, const Vec3* points, size_t count, Foothold* out) override {
    const Entry* e = Find(terrain);
    if (!e) return Unknown(terrain);
    e->grid.SnapBatch(points, count, out, pool_.get());
    return Status::kOk;
  }

  Status Normal(TerrainHandle terrain, const Vec3* points, size_t count, Foothold* out) override {
    return Snap(terrain, points, count, out);
  }

  Status Next(TerrainHandle terrain, const StepQuery* queries, size_t count, double tolerance,
              Foothold* out) override {
    const Entry* e = Find(terrain);
    if (!e) return Unknown(terrain);
    if (!std::isfinite(tolerance))
      return FailFromAnyThread(Status::kInvalidArgument, "tolerance is not finite");
    e->grid.NextBatch(queries, count, tolerance, out, pool_.get());
    return Status::kOk;
  }

  std::string Describe() const override { return "embedded"; }
  bool InProcess() const override { return true; }

 private:
  struct Entry {
    std::string name;
    TerrainGrid grid;
  };
  const Entry* Find(TerrainHandle terrain) const {
    auto it = terrains_.find(terrain);
    return it == terrains_.end() ? nullptr : &it->second;
  }
  Status Unknown(TerrainHandle terrain) {
    return FailFromAnyThread(Status::kUnknownTerrain,
                             "no terrain with handle " + std::to_string(terrain));
  }
  // Fail for the queries, which several threads may make at once (InProcess): their failures
  // write last_error_ one at a time (two at once corrupted the string).
  Status FailFromAnyThread(Status status, std::string message) {
    std::lock_guard<std::mutex> lock(fail_mutex_);
    return Fail(status, std::move(message));
  }

  std::shared_ptr<BatchPool> pool_;  // the process's shared pool (null: one thread)
  HandleCounter handles_;
  std::map<TerrainHandle, Entry> terrains_;
  std::mutex fail_mutex_;
};

}  // namespace

std::unique_ptr<TerrainSession> MakeEmbeddedSession(int threads, TerrainHandle first_handle) {
  return std::make_unique<EmbeddedSession>(threads, first_handle);
}

}  // namespace footfall
