// TerrainRegistry: the terrains footfalld serves, by handle, with the uploads in progress and a
// ring of recently answered queries (for live viewers). Not thread-safe: the RPC loop owns it.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "footfall/import/terrain_loader.h"
#include "footfall/service/pinned_file.h"
#include "footfall/terrain/grid.h"

namespace footfall {

struct RegistryLimits {
  size_t max_terrains = 256;        // loaded at once
  size_t max_client_terrains = 64;  // loaded at once by one client (connection)
  double orphan_idle_s = 600;  // [Units: s] an orphaned terrain without queries this long is freed
  size_t max_total_samples = 1u << 28;  // over all terrains and uploads
  size_t max_uploads = 32;              // in progress at once
  size_t max_client_uploads = 4;        // in progress at once on one connection
  // [Units: s] an upload that receives no samples this long is dropped (empty chunks do not
  // count; asking to finish it while footfalld is too busy to build it does)
  double upload_idle_s = 120;
  size_t recent_capacity = 4096;  // queries kept for FF_RECENT
};

struct LoadedTerrain {
  std::string name;
  TerrainGrid grid;
  // The client (connection) that loaded it, the only one that may unload it; 0 once that client
  // has gone (the terrain is orphaned).
  uint64_t owner = 0;
  // The last query on it from any client, or when it was orphaned if later.
  std::chrono::steady_clock::time_point used;
};

// A server-side load between its three stages: checked and pinned by
// TerrainRegistry::PrepareLoad (the registry's thread), read, resampled and built by RunLoad (any
// thread: it touches no registry state), added by TerrainRegistry::FinishLoad (the registry's
// thread again). A load can take seconds, so footfalld runs the middle stage off its RPC thread.
struct PendingLoad {
  std::string relative_path;           // as the client named it (an upload: its name)
  TerrainLoadOptions options;          // max_samples lowered to what was left of the budget
  bool budget_binds = false;           // the budget, not the client, set options.max_samples
  bool per_load_binds = false;         // ... MaxSamplesPerLoad did
  uint64_t owner = 0;                  // the client (connection) that asked
  std::unique_ptr<PinnedFile> pinned;  // a file to read; or, when null, `samples`
  RawSamples samples;                  // an upload's samples (kept in the budget: `reserved`)
  uint64_t reserved = 0;
  // A terrain slot is held for it (against RegistryLimits::max_client_terrains and
  // max_terrains) from its Prepare stage until FinishLoad or DropLoad, so that a load or upload
  // whose grid is built always has its place.
  bool holds_slot = false;
  bool upload = false;  // an upload's samples (FF_UPLOAD_FINISH), not a file
  // Set (from any thread) when the client that asked has gone: RunLoad stops at its next stage
  // with kUnavailable, and nothing more is built for nobody.
  std::atomic<bool> cancelled{false};
  // RunLoad's result: on kOk the built grid, else the error (naming relative_path).
  Status status = Status::kInternalError;
  std::string message;
  TerrainGrid grid;
  TerrainLoadReport report;  // a file's: how it was read (a mesh's separation)
};

// The most samples one server-side load of a mesh or height map may be sampled to: 20,000,000,
// or fewer when this machine's memory could not hold two such loads sampling at once.
uint64_t MaxSamplesPerLoad();

// The middle stage of a load: reads and resamples the pinned file, validates the samples and
// builds the grid into `load`, whose status and message say how it went. A load cancelled
// meanwhile (PendingLoad::cancelled) ends at the next stage, kUnavailable.
void RunLoad(PendingLoad* load);

// One answered query, as the live view shows it.
struct RecentQuery {
  uint64_t sequence = 0;
  uint32_t terrain = 0;
  int op = 0;  // 0 snap, 1 normal, 2 next (ff_op)
  Vec3 point, direction;
  double tolerance = 0;
  Foothold result;
};

class TerrainRegistry {
 public:
  // `data_root` confines server-side loads; empty refuses them.
  TerrainRegistry(std::string data_root, RegistryLimits limits);

  // Loads a file under the data root with `options` (their max_samples lowered to what is left
  // of the budget). kAccessDenied for paths escaping it (.., symlinks).
  // Meshes and height maps are refused before sampling when the sampler's estimate exceeds the
  // samples left in the budget (RegistryLimits::max_total_samples).
  // The terrain belongs to client `owner`; kLimitExceeded when that client already holds
  // RegistryLimits::max_client_terrains.
  // LoadFile is PrepareLoad, RunLoad and FinishLoad in a row.
  Status LoadFile(const std::string& relative_path, TerrainLoadOptions options, uint64_t owner,
                  uint32_t* handle, std::string* message);
  // LoadFile's first stage: every check that needs no reading (quota, path, file type), the file
  // pinned, the budget applied. On kOk, *load is ready for RunLoad.
  Status PrepareLoad(const std::string& relative_path, TerrainLoadOptions options, uint64_t owner,
                     PendingLoad* load, std::string* message);
  // LoadFile's last stage: the load's error, or its grid added for load->owner if the quota,
  // the terrain limit and the budget still allow (other loads may have finished meanwhile).
  Status FinishLoad(PendingLoad* load, uint32_t* handle, std::string* message);
  // Starts an upload for client `owner` (a connection), reserving its announced total against
  // the sample budget until it finishes, fails, expires or DropClient(owner). kLimitExceeded
  // when the budget cannot hold it, or when `owner` already holds its quota of terrains.
  Status BeginUpload(const std::string& name, uint64_t total, uint64_t owner, uint32_t* upload,
                     std::string* message);
  // Appends a chunk to `owner`'s upload; a bad chunk ends the upload.
  Status AppendUpload(uint32_t upload, uint64_t owner, const RawSamples& chunk,
                      std::string* message);
  // Makes the upload a terrain belonging to `owner`.
  Status FinishUpload(uint32_t upload, uint64_t owner, uint32_t* handle, std::string* message);
  // FinishUpload's first stage, for RunLoad and FinishLoad: the complete upload's samples move
  // to *load, still counted in the budget until FinishLoad or DropLoad. When `owner` or the
  // server has no terrain slot left, kLimitExceeded and the upload is kept: the client may
  // unload a terrain and finish it again.
  Status PrepareFinishUpload(uint32_t upload, uint64_t owner, PendingLoad* load,
                             std::string* message);
  // Forgets a prepared load that will not be finished (its client went away).
  void DropLoad(PendingLoad* load);
  // Counts as activity on `owner`'s complete upload, for RegistryLimits::upload_idle_s: its
  // finish was refused because footfalld was busy, and the client will ask again.
  void TouchUpload(uint32_t upload, uint64_t owner);
  // Ends the uploads of a client that went away, releasing their reservations, and orphans its
  // terrains (they stay queryable until RegistryLimits::orphan_idle_s pass without a query).
  // Returns the handles orphaned; `dropped_uploads` [opt] gets each upload ended, described as
  // "upload N 'NAME' (R of T samples received)".
  std::vector<uint32_t> DropClient(uint64_t owner,
                                   std::vector<std::string>* dropped_uploads = nullptr);
  // Unloads a terrain of client `requester`, or an orphan: kAccessDenied for another client's
  // terrain, kUnknownTerrain for no terrain.
  Status Unload(uint32_t handle, uint64_t requester, std::string* message);
  // The terrain, for reading its description (not a query); nullptr if there is none.
  const LoadedTerrain* Find(uint32_t handle) const;
  // The terrain, for a query: marks it used now, which keeps an orphan alive.
  const LoadedTerrain* Use(uint32_t handle);
  std::vector<uint32_t> Handles() const;
  const RegistryLimits& limits() const { return limits_; }

  // Drops uploads idle longer than the limit (each noted for TakeExpiredUploads).
  void ExpireUploads();
  // The uploads dropped for idleness since the last call, each as "upload ID 'NAME' (R of T
  // samples received)", for the log.
  std::vector<std::string> TakeExpiredUploads();
  // Frees orphaned terrains without a query for RegistryLimits::orphan_idle_s; returns their
  // handles.
  std::vector<uint32_t> ExpireOrphans();
  // The orphans freed early since the last call, to make room for a new terrain or upload at
  // RegistryLimits::max_terrains or the sample budget (the least recently queried first).
  std::vector<uint32_t> TakeEvicted();

  void Record(const RecentQuery& query);
  // Queries with sequence > after, oldest first, at most `max`; *latest is the newest sequence.
  std::vector<RecentQuery> RecentAfter(uint64_t after, size_t max, uint64_t* latest) const;

 private:
  // Frees the least recently queried orphan; false when there is none.
  bool EvictOldestOrphan();
  // Whether `samples` more fit in the budget, orphans freed as needed, least recently queried
  // first. Frees none when they would not fit with every orphan gone: a request refused
  // anyway cost other clients their orphans.
  bool MakeRoomForSamples(uint64_t samples);
  // Whether `samples` more would fit in the budget once every orphan were freed.
  bool FitsWithoutOrphans(uint64_t samples) const;
  uint64_t OrphanSamples() const;  // samples of orphaned terrains
  Status Add(const std::string& name, RawSamples samples, uint64_t owner, uint32_t* handle,
             std::string* message);
  // Adds a built grid; kLimitExceeded when the quota, the terrain limit or the budget refuse it.
  Status AddGrid(const std::string& name, TerrainGrid grid, uint64_t owner, uint32_t* handle,
                 std::string* message);
  // kLimitExceeded, with a message, when `owner` holds its quota of terrains (loaded, or being
  // loaded: slots held by prepared loads count).
  Status CheckQuota(uint64_t owner, std::string* message) const;
  // PrepareLoad's checks of the file, once `load` holds its slot.
  Status PrepareLoadFile(const std::string& relative_path, TerrainLoadOptions options,
                         PendingLoad* load, std::string* message);
  // CheckQuota, then the server's terrain limit (orphans count as room: AddGrid frees them);
  // on kOk, `load` holds a slot until FinishLoad or DropLoad.
  Status HoldSlot(uint64_t owner, PendingLoad* load, std::string* message);
  // Samples held by loaded terrains plus those reserved by uploads in progress or being built.
  uint64_t TotalSamples() const;
  // Why `owner` has no upload `upload`: dropped by --upload-timeout, or never begun here.
  std::string NoUpload(uint32_t upload, uint64_t owner) const;
  // "the sample budget (--max-samples N, M in use)", for messages.
  std::string Budget() const;

  struct Upload {
    std::string name;
    uint64_t owner = 0;
    uint64_t total = 0;  // announced, and reserved
    RawSamples samples;
    std::chrono::steady_clock::time_point touched;
  };
  std::string data_root_;  // canonical, or empty
  RegistryLimits limits_;
  uint32_t next_handle_;
  uint32_t next_upload_ = 1;
  std::map<uint32_t, std::unique_ptr<LoadedTerrain>> terrains_;
  std::vector<uint32_t> evicted_;             // orphans freed to make room, until TakeEvicted
  std::vector<std::string> expired_uploads_;  // until TakeExpiredUploads
  // Uploads dropped by ExpireUploads, and their owners: a later chunk is told why.
  static constexpr size_t kRememberedExpiries = 1024;
  std::deque<std::pair<uint32_t, uint64_t>> expired_ids_;
  std::map<uint32_t, Upload> uploads_;
  uint64_t building_ = 0;  // samples of finished uploads whose grids are being built
  std::map<uint64_t, size_t> held_slots_;  // terrain slots held by prepared loads, per owner
  size_t held_slots_total_ = 0;
  std::deque<RecentQuery> recent_;
  uint64_t sequence_ = 0;
};

// Resolves `relative` under the canonical directory `root`, refusing escapes: absolute paths,
// "..", and symlinks leading outside (kAccessDenied); an empty path or one with a NUL byte is
// kInvalidArgument. On success *resolved is the canonical path.
Status ResolveUnderRoot(const std::string& root, const std::string& relative, std::string* resolved,
                        std::string* message);

// Refuses (kInvalidArgument) anything at `path` but a regular file: FIFOs, devices, sockets and
// directories, whose reading could block the server or never end. Never blocks; messages name
// the file as `shown`.
Status CheckRegularFile(const std::string& path, const std::string& shown, std::string* message);

}  // namespace footfall
