#include "footfall/service/terrain_registry.h"

#include "footfall/service/pinned_file.h"
#include "footfall/terrain/large_memory.h"
#include "footfall/terrain/text_stream.h"

#include <fcntl.h>
#include <limits.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <new>
#include <random>
#include <vector>

namespace footfall {

namespace {

// An upload as the log names one: "upload N 'NAME' (R of T samples received)".
std::string UploadText(uint32_t upload, const std::string& name, size_t received, uint64_t total) {
  return "upload " + std::to_string(upload) + " '" + name + "' (" + std::to_string(received) +
         " of " + std::to_string(total) + " samples received)";
}

// True when canonical `path` is an ancestor of `root` (a walk from "/" passes it on the way in).
bool AboveRoot(const std::string& root, const std::string& path) {
  return path == "/" || root.compare(0, path.size() + 1, path + "/") == 0;
}

std::vector<std::string> Components(const std::string& path) {
  std::vector<std::string> parts;
  size_t begin = 0;
  while (begin <= path.size()) {
    const size_t end = std::min(path.find('/', begin), path.size());
    if (end > begin) parts.push_back(path.substr(begin, end - begin));
    begin = end + 1;
  }
  return parts;
}

// Where resolving a path that realpath cannot resolve goes.
enum class Lead {
  kInside,        // it fails inside the root (a name missing there)
  kOutside,       // it leaves the root before it fails
  kTooManyLinks,  // it follows more links than the system would (a loop), all within the root
};

// [Units: links] As many as the system follows before it gives up (Linux's MAXSYMLINKS).
constexpr int kMaxLinks = 40;
// [Units: links] How far a chain is followed to tell whether it leads outside the root (beyond
// kMaxLinks it is refused either way, but every path that leads outside gets one answer,
// whether or not its target exists); a loop within the root ends here.
constexpr int kMaxLinksFollowed = 1000;

// For an absolute path that realpath cannot resolve: whether resolving it leaves `root` before
// it fails (a prefix resolves outside, or the part that fails is a link whose target leads
// out). Decided without looking at anything outside the root that the path names, so the answer
// does not reveal whether such things exist.
Lead Resolving(const std::string& root, const std::string& path, int links) {
  if (links > kMaxLinksFollowed) return Lead::kTooManyLinks;
  const Lead inside = links > kMaxLinks ? Lead::kTooManyLinks : Lead::kInside;
  const std::vector<std::string> parts = Components(path);
  std::string at = "/";  // canonical, inside the root or above it
  for (size_t i = 0; i < parts.size(); ++i) {
    const std::string next = (at == "/" ? "" : at) + "/" + parts[i];
    char buffer[PATH_MAX];
    if (realpath(next.c_str(), buffer)) {
      at = buffer;
      if (!PathInside(root, at) && !AboveRoot(root, at)) return Lead::kOutside;
      continue;
    }
    if (!PathInside(root, at)) return Lead::kOutside;
    const ssize_t n = readlink(next.c_str(), buffer, sizeof buffer - 1);
    if (n < 0) return inside;  // missing below a directory of the root
    buffer[n] = '\0';
    std::string rest = buffer[0] == '/' ? std::string(buffer) : at + "/" + buffer;
    for (size_t j = i + 1; j < parts.size(); ++j) rest += "/" + parts[j];
    return Resolving(root, rest, links + 1);
  }
  return PathInside(root, at) ? inside : Lead::kOutside;
}

// What a file type is, for messages about files that are not regular.
const char* FileKind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  return "not a regular file";
}

}  // namespace

Status ResolveUnderRoot(const std::string& root, const std::string& relative, std::string* resolved,
                        std::string* message) {
  if (root.empty()) {
    *message = "server-side loads are disabled (footfalld has no --data-root)";
    return Status::kAccessDenied;
  }
  const size_t nul = relative.find('\0');
  if (nul != std::string::npos) {
    *message = "path has a NUL byte at offset " + std::to_string(nul) +
               ": expected a path without NUL bytes";
    return Status::kInvalidArgument;
  }
  if (relative.empty()) {
    *message = "expected a path relative to the data root, got an empty path";
    return Status::kInvalidArgument;
  }
  if (relative[0] == '/') {
    *message = "'" + relative + "': expected a path relative to the data root";
    return Status::kAccessDenied;
  }
  // A root removed or renamed while footfalld runs: every path read as leading outside it.
  char root_now[PATH_MAX];
  struct stat root_stat {};
  const char* gone = nullptr;
  if (!realpath(root.c_str(), root_now))
    gone = std::strerror(errno);
  else if (root_now != root)
    gone = "its name now leads elsewhere";
  else if (stat(root_now, &root_stat) != 0 || !S_ISDIR(root_stat.st_mode))
    gone = "it is no longer a folder";
  if (gone) {
    *message = std::string("footfalld's data root is gone (") + gone +
               "): it loads no file until the folder is back where it was";
    return Status::kIoError;
  }
  // Every path that leaves the root gets this one answer, whether or not its target exists.
  const std::string outside = "'" + relative + "' leads outside the data root";
  // '..' is refused whatever it leads to; read without the file system (no answer tells what
  // exists), a path whose '..' stays within the root is told so.
  int depth = 0;
  bool climbs = false, leaves = false;
  for (const std::string& part : Components(relative)) {
    if (part == "..") {
      climbs = true;
      leaves |= --depth < 0;
    } else if (part != "." && !part.empty()) {
      ++depth;
    }
  }
  if (climbs) {
    *message =
        leaves ? outside : "'" + relative + "': '..' is not allowed in a path under the data root";
    return Status::kAccessDenied;
  }
  const std::string joined = root + "/" + relative;
  char buffer[PATH_MAX];
  if (!realpath(joined.c_str(), buffer)) {
    const int error = errno;
    const Lead lead = Resolving(root, joined, 0);
    if (lead == Lead::kOutside) {
      *message = outside;
      return Status::kAccessDenied;
    }
    // (Links followed in the folders on the way count too: the system's ELOOP says so.)
    if (lead == Lead::kTooManyLinks || (lead == Lead::kInside && error == ELOOP)) {
      *message = "'" + relative + "': more than " + std::to_string(kMaxLinks) +
                 " symbolic links on its way under the data root (a loop of links?)";
      return Status::kIoError;
    }
    if (error == EACCES) {
      *message = "'" + relative +
                 "': permission denied: footfalld's user may not search a folder on its way "
                 "under the data root";
      return Status::kAccessDenied;
    }
    // (Within the root, the system's reason is told: every failure was "no such file".)
    if (error == ENOTDIR) {
      *message = "'" + relative +
                 "': not a directory: a file on its way under the data root is "
                 "followed by more of the path";
    } else if (error == ENAMETOOLONG) {
      *message = "'" + relative + "': file name too long (a name on its way is over " +
                 std::to_string(NAME_MAX) + " bytes, or the whole path over " +
                 std::to_string(PATH_MAX) + ")";
    } else if (error == ENOENT) {
      *message = "'" + relative + "': no such file under the data root";
    } else {
      *message = "'" + relative + "': cannot resolve under the data root: " + std::strerror(error);
    }
    return Status::kIoError;
  }
  const std::string canonical = buffer;
  if (!PathInside(root, canonical)) {
    *message = outside;
    return Status::kAccessDenied;
  }
  *resolved = canonical;
  return Status::kOk;
}

Status CheckRegularFile(const std::string& path, const std::string& shown, std::string* message) {
  struct stat before {};
  if (stat(path.c_str(), &before) != 0) {
    *message = "'" + shown + "': no such file under the data root";
    return Status::kIoError;
  }
  auto refuse = [&](mode_t mode) {
    *message = "'" + shown + "' is " + FileKind(mode) + ": expected a regular terrain file";
    return Status::kInvalidArgument;
  };
  if (!S_ISREG(before.st_mode)) return refuse(before.st_mode);
  // Opened without blocking, in case it was replaced since, and checked again through the fd.
  const int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    *message = "'" + shown + "': cannot open: " + std::strerror(error);
    return error == EACCES ? Status::kAccessDenied : Status::kIoError;
  }
  struct stat opened {};
  const bool same =
      fstat(fd, &opened) == 0 && opened.st_dev == before.st_dev && opened.st_ino == before.st_ino;
  close(fd);
  if (!same || !S_ISREG(opened.st_mode)) return refuse(opened.st_mode);
  return Status::kOk;
}

TerrainRegistry::TerrainRegistry(std::string data_root, RegistryLimits limits) : limits_(limits) {
  if (!data_root.empty()) {
    char buffer[PATH_MAX];
    if (realpath(data_root.c_str(), buffer)) data_root_ = buffer;
  }
  // Handles start at a random base, so a client never mistakes a restarted server's terrain
  // for one it loaded before.
  std::random_device device;
  next_handle_ = (device() & 0x7FFFFFF0u) + 1;
}

uint64_t TerrainRegistry::TotalSamples() const {
  uint64_t total = 0;
  for (const auto& t : terrains_) total += t.second->grid.size();
  for (const auto& u : uploads_) total += u.second.total;
  return total + building_;
}

std::string TerrainRegistry::Budget() const {
  return "the sample budget (--max-samples " + std::to_string(limits_.max_total_samples) + ", " +
         std::to_string(TotalSamples()) + " in use by loaded terrains and uploads in progress)";
}

Status TerrainRegistry::CheckQuota(uint64_t owner, std::string* message) const {
  size_t held = 0;
  for (const auto& t : terrains_) held += t.second->owner == owner;
  const auto loading = held_slots_.find(owner);
  const size_t being_loaded = loading == held_slots_.end() ? 0 : loading->second;
  if (held + being_loaded < limits_.max_client_terrains) return Status::kOk;
  *message = "this connection holds " + std::to_string(held) + " terrains" +
             (being_loaded ? " and loads " + std::to_string(being_loaded) + " more" : "") +
             ", the most one connection may hold (--max-client-terrains " +
             std::to_string(limits_.max_client_terrains) + "): unload one first";
  return Status::kLimitExceeded;
}

Status TerrainRegistry::HoldSlot(uint64_t owner, PendingLoad* load, std::string* message) {
  const Status status = CheckQuota(owner, message);
  if (status != Status::kOk) return status;
  size_t orphans = 0;
  for (const auto& t : terrains_) orphans += t.second->owner == 0;
  if (terrains_.size() - orphans + held_slots_total_ >= limits_.max_terrains) {
    *message = "too many terrains loaded or being loaded (limit " +
               std::to_string(limits_.max_terrains) + ")";
    return Status::kLimitExceeded;
  }
  ++held_slots_[owner];
  ++held_slots_total_;
  load->holds_slot = true;
  return Status::kOk;
}

Status TerrainRegistry::Add(const std::string& name, RawSamples samples, uint64_t owner,
                            uint32_t* handle, std::string* message) {
  Status status = CheckQuota(owner, message);
  if (status != Status::kOk) return status;
  if (!MakeRoomForSamples(samples.size())) {
    *message =
        "'" + name + "': " + std::to_string(samples.size()) + " samples do not fit in " + Budget();
    return Status::kLimitExceeded;
  }
  status = ValidateAndNormalize(&samples, message);
  if (status != Status::kOk) return status;
  TerrainGrid grid;
  status = TerrainGrid::Build(samples, GridOptions{}, &grid, message);
  if (status != Status::kOk) return status;
  return AddGrid(name, std::move(grid), owner, handle, message);
}

Status TerrainRegistry::AddGrid(const std::string& name, TerrainGrid grid, uint64_t owner,
                                uint32_t* handle, std::string* message) {
  Status status = CheckQuota(owner, message);
  if (status != Status::kOk) return status;
  // Refused before any orphan is freed for it (the budget counts orphans as room).
  const size_t samples = grid.stats().samples;
  if (!FitsWithoutOrphans(samples)) {
    *message = "'" + name + "': " + std::to_string(samples) + " samples do not fit in " + Budget();
    return Status::kLimitExceeded;
  }
  if (terrains_.size() >= limits_.max_terrains && !EvictOldestOrphan()) {
    *message = "too many terrains loaded (limit " + std::to_string(limits_.max_terrains) + ")";
    return Status::kLimitExceeded;
  }
  if (!MakeRoomForSamples(samples)) {
    *message = "'" + name + "': " + std::to_string(samples) + " samples do not fit in " + Budget();
    return Status::kLimitExceeded;
  }
  auto terrain = std::make_unique<LoadedTerrain>();
  terrain->name = name;
  terrain->owner = owner;
  terrain->used = std::chrono::steady_clock::now();
  terrain->grid = std::move(grid);
  uint32_t h = next_handle_++;
  while (h == 0 || terrains_.count(h)) h = next_handle_++;
  terrains_.emplace(h, std::move(terrain));
  *handle = h;
  return Status::kOk;
}

Status TerrainRegistry::LoadFile(const std::string& relative_path, TerrainLoadOptions options,
                                 uint64_t owner, uint32_t* handle, std::string* message) {
  PendingLoad load;
  const Status status = PrepareLoad(relative_path, std::move(options), owner, &load, message);
  if (status != Status::kOk) return status;
  RunLoad(&load);
  return FinishLoad(&load, handle, message);
}

Status TerrainRegistry::PrepareLoad(const std::string& relative_path, TerrainLoadOptions options,
                                    uint64_t owner, PendingLoad* load, std::string* message) {
  // A slot before reading or sampling anything; given back on every refusal below.
  load->owner = owner;
  Status status = HoldSlot(owner, load, message);
  if (status != Status::kOk) return status;
  status = PrepareLoadFile(relative_path, std::move(options), load, message);
  if (status != Status::kOk) DropLoad(load);
  return status;
}

Status TerrainRegistry::PrepareLoadFile(const std::string& relative_path,
                                        TerrainLoadOptions options, PendingLoad* load,
                                        std::string* message) {
  std::string path;
  Status status = ResolveUnderRoot(data_root_, relative_path, &path, message);
  if (status != Status::kOk) return status;
  status = CheckRegularFile(path, relative_path, message);
  if (status != Status::kOk) return status;
  // Held open from here: what is read is the file just checked, wherever its path leads now.
  auto pinned = std::make_unique<PinnedFile>();
  status = pinned->Open(data_root_, path, relative_path, message);
  if (status != Status::kOk) return status;
  // Meshes are refused on the sampler's estimate, before any sampling. Orphans count as room:
  // AddGrid frees them as needed.
  const uint64_t used = TotalSamples() - OrphanSamples();
  const uint64_t left = used < limits_.max_total_samples ? limits_.max_total_samples - used : 0;
  const uint64_t per_load = MaxSamplesPerLoad();
  load->budget_binds = left < options.max_samples && left <= per_load;
  load->per_load_binds = per_load < options.max_samples && per_load < left;
  options.max_samples =
      static_cast<size_t>(std::min<uint64_t>({options.max_samples, left, per_load}));
  // Two meshes are resampled at once, one thread each: the query threads keep their share.
  options.threads = 1;
  load->relative_path = relative_path;
  load->options = std::move(options);
  load->pinned = std::move(pinned);
  return Status::kOk;
}

uint64_t MaxSamplesPerLoad() {
  // kSamplingBytesPerSample each, and two loads run at once.
  constexpr uint64_t kMostPerLoad = 20000000, kLoadsAtOnce = 2;
  const double memory = UsableMemoryBytes();
  const uint64_t fits =
      memory > 0 ? static_cast<uint64_t>(memory / (kSamplingBytesPerSample * kLoadsAtOnce))
                 : kMostPerLoad;
  return std::max<uint64_t>(1000, std::min(kMostPerLoad, fits));
}

void RunLoad(PendingLoad* load) {
  RawSamples samples = std::move(load->samples);
  std::string error;
  const std::string pinned = load->pinned ? load->pinned->path() : "";
  load->status = Status::kOk;
  // Between stages: a client gone meanwhile has its load stopped, its samples freed.
  auto go_on = [load, &error] {
    if (load->status != Status::kOk) return false;
    if (!load->cancelled.load()) return true;
    load->status = Status::kUnavailable;
    error = "'" + load->relative_path + "': cancelled, its client has gone";
    return false;
  };
  if (load->pinned && go_on())
    load->status = LoadTerrain(pinned, load->options, &samples, &error, &load->report);
  if (go_on()) load->status = ValidateAndNormalize(&samples, &error);
  if (go_on()) load->status = TerrainGrid::Build(samples, GridOptions{}, &load->grid, &error);
  // Report the path as the client gave it, not the server's layout.
  const size_t at = pinned.empty() ? std::string::npos : error.find(pinned);
  if (at != std::string::npos) error.replace(at, pinned.size(), load->relative_path);
  load->message = std::move(error);
  load->pinned.reset();  // read: the private name goes
}

void TerrainRegistry::DropLoad(PendingLoad* load) {
  building_ -= std::min(building_, load->reserved);
  load->reserved = 0;
  if (load->holds_slot) {
    load->holds_slot = false;
    --held_slots_total_;
    if (--held_slots_[load->owner] == 0) held_slots_.erase(load->owner);
  }
}

Status TerrainRegistry::FinishLoad(PendingLoad* load, uint32_t* handle, std::string* message) {
  DropLoad(load);  // counted as a terrain from here, if it is added
  if (load->status != Status::kOk) {
    *message = load->message;
    if (load->status == Status::kLimitExceeded && load->budget_binds)
      *message += " (the limit is what is left of " + Budget() + ")";
    if (load->status == Status::kLimitExceeded && load->per_load_binds)
      *message += " (the limit is footfalld's " + std::to_string(MaxSamplesPerLoad()) +
                  " samples per load of a mesh or height map, which this machine's memory "
                  "holds while sampling)";
    return load->status;
  }
  return AddGrid(load->relative_path, std::move(load->grid), load->owner, handle, message);
}

Status TerrainRegistry::BeginUpload(const std::string& name, uint64_t total, uint64_t owner,
                                    uint32_t* upload, std::string* message) {
  ExpireUploads();
  const Status quota = CheckQuota(owner, message);
  if (quota != Status::kOk) return quota;
  if (total == 0) {
    *message = "an upload of no samples (a terrain needs at least one)";
    return Status::kInvalidArgument;
  }
  size_t own = 0;
  for (const auto& u : uploads_) own += u.second.owner == owner;
  if (own >= limits_.max_client_uploads) {
    *message = "this connection has " + std::to_string(own) +
               " uploads in progress, the most one connection may have: finish one first";
    return Status::kLimitExceeded;
  }
  if (uploads_.size() >= limits_.max_uploads) {
    *message = "too many uploads in progress (limit " + std::to_string(limits_.max_uploads) + ")";
    return Status::kLimitExceeded;
  }
  if (!MakeRoomForSamples(total)) {
    *message = "an upload of " + std::to_string(total) + " samples does not fit in " + Budget();
    return Status::kLimitExceeded;
  }
  uint32_t id = next_upload_++;
  while (id == 0 || uploads_.count(id)) id = next_upload_++;
  Upload& u = uploads_[id];
  u.name = name;
  u.owner = owner;
  u.total = total;
  // Room for the announced samples, which the budget has admitted: grown chunk by chunk, the
  // arrays were copied over and over (pages are only taken as samples arrive). Without the
  // room (a memory limit), they grow as before.
  try {
    u.samples.points.reserve(total);
    u.samples.normals.reserve(total);
  } catch (const std::bad_alloc&) {
    u.samples = RawSamples{};
  }
  u.touched = std::chrono::steady_clock::now();
  *upload = id;
  return Status::kOk;
}

namespace {

// What a refused chunk's message ends with: the upload is gone (its later chunks were answered
// "no upload N in progress", with no word of why).
std::string Dropped(uint32_t upload) {
  return "; upload " + std::to_string(upload) + " is dropped: begin it again";
}

}  // namespace

std::string TerrainRegistry::NoUpload(uint32_t upload, uint64_t owner) const {
  for (const auto& [id, by] : expired_ids_) {
    if (id == upload && by == owner) {
      TextStream text;
      text << "upload " << upload << " was dropped: no samples for " << limits_.upload_idle_s
           << " s (--upload-timeout); begin it again";
      return text.str();
    }
  }
  return "no upload " + std::to_string(upload) + " in progress on this connection";
}

Status TerrainRegistry::AppendUpload(uint32_t upload, uint64_t owner, const RawSamples& chunk,
                                     std::string* message) {
  auto it = uploads_.find(upload);
  if (it == uploads_.end() || it->second.owner != owner) {
    *message = NoUpload(upload, owner);
    return Status::kInvalidArgument;
  }
  Upload& u = it->second;
  if (u.samples.size() + chunk.size() > u.total) {
    *message = "upload sent more samples than the " + std::to_string(u.total) + " announced" +
               Dropped(upload);
    uploads_.erase(it);
    return Status::kInvalidArgument;
  }
  for (size_t i = 0; i < chunk.size(); ++i) {
    std::string what;
    if (CheckSample(chunk.points[i], chunk.normals[i], &what) != Status::kOk) {
      *message = "sample " + std::to_string(u.samples.size() + i) + ": " + what + Dropped(upload);
      uploads_.erase(it);
      return Status::kInvalidArgument;
    }
  }
  u.samples.points.insert(u.samples.points.end(), chunk.points.begin(), chunk.points.end());
  u.samples.normals.insert(u.samples.normals.end(), chunk.normals.begin(), chunk.normals.end());
  if (chunk.size() > 0) u.touched = std::chrono::steady_clock::now();  // samples are progress
  return Status::kOk;
}

Status TerrainRegistry::FinishUpload(uint32_t upload, uint64_t owner, uint32_t* handle,
                                     std::string* message) {
  PendingLoad load;
  const Status status = PrepareFinishUpload(upload, owner, &load, message);
  if (status != Status::kOk) return status;
  RunLoad(&load);
  return FinishLoad(&load, handle, message);
}

Status TerrainRegistry::PrepareFinishUpload(uint32_t upload, uint64_t owner, PendingLoad* load,
                                            std::string* message) {
  auto it = uploads_.find(upload);
  if (it == uploads_.end() || it->second.owner != owner) {
    *message = NoUpload(upload, owner);
    return Status::kInvalidArgument;
  }
  if (it->second.samples.size() == it->second.total) {
    // No slot for it: the upload is kept, to be finished once the client has unloaded one.
    load->owner = owner;
    const Status slot = HoldSlot(owner, load, message);
    if (slot != Status::kOk) {
      it->second.touched = std::chrono::steady_clock::now();  // asked for: not idle
      *message +=
          "; upload " + std::to_string(upload) + " is kept: unload a terrain and finish it again";
      return slot;
    }
  }
  Upload u = std::move(it->second);
  uploads_.erase(it);
  if (u.samples.size() != u.total) {
    *message = "upload ended after " + std::to_string(u.samples.size()) + " of " +
               std::to_string(u.total) + " samples" + Dropped(upload);
    return Status::kInvalidArgument;
  }
  load->relative_path = u.name;
  load->samples = std::move(u.samples);
  load->reserved = u.total;
  load->upload = true;
  building_ += u.total;
  return Status::kOk;
}

void TerrainRegistry::TouchUpload(uint32_t upload, uint64_t owner) {
  const auto it = uploads_.find(upload);
  if (it != uploads_.end() && it->second.owner == owner)
    it->second.touched = std::chrono::steady_clock::now();
}

Status TerrainRegistry::Unload(uint32_t handle, uint64_t requester, std::string* message) {
  auto it = terrains_.find(handle);
  if (it == terrains_.end()) {
    *message = "no terrain " + std::to_string(handle);
    return Status::kUnknownTerrain;
  }
  // An orphan (its connection closed) may be unloaded by any client: its owner, reconnected,
  // has another connection.
  if (it->second->owner != requester && it->second->owner != 0) {
    *message = "terrain " + std::to_string(handle) +
               " was loaded by another connection: only that connection may unload it";
    return Status::kAccessDenied;
  }
  terrains_.erase(it);
  return Status::kOk;
}

const LoadedTerrain* TerrainRegistry::Find(uint32_t handle) const {
  auto it = terrains_.find(handle);
  return it == terrains_.end() ? nullptr : it->second.get();
}

const LoadedTerrain* TerrainRegistry::Use(uint32_t handle) {
  auto it = terrains_.find(handle);
  if (it == terrains_.end()) return nullptr;
  it->second->used = std::chrono::steady_clock::now();
  return it->second.get();
}

std::vector<uint32_t> TerrainRegistry::Handles() const {
  std::vector<uint32_t> handles;
  for (const auto& t : terrains_) handles.push_back(t.first);
  return handles;
}

std::vector<uint32_t> TerrainRegistry::DropClient(uint64_t owner,
                                                  std::vector<std::string>* dropped_uploads) {
  for (auto it = uploads_.begin(); it != uploads_.end();) {
    if (it->second.owner != owner) {
      ++it;
      continue;
    }
    if (dropped_uploads)
      dropped_uploads->push_back(
          UploadText(it->first, it->second.name, it->second.samples.size(), it->second.total));
    it = uploads_.erase(it);
  }
  std::vector<uint32_t> orphaned;
  const auto now = std::chrono::steady_clock::now();
  for (auto& t : terrains_) {
    if (owner == 0 || t.second->owner != owner) continue;
    t.second->owner = 0;
    t.second->used = std::max(t.second->used, now);
    orphaned.push_back(t.first);
  }
  return orphaned;
}

bool TerrainRegistry::EvictOldestOrphan() {
  auto oldest = terrains_.end();
  for (auto it = terrains_.begin(); it != terrains_.end(); ++it)
    if (it->second->owner == 0 &&
        (oldest == terrains_.end() || it->second->used < oldest->second->used))
      oldest = it;
  if (oldest == terrains_.end()) return false;
  evicted_.push_back(oldest->first);
  terrains_.erase(oldest);
  return true;
}

uint64_t TerrainRegistry::OrphanSamples() const {
  uint64_t total = 0;
  for (const auto& t : terrains_)
    if (t.second->owner == 0) total += t.second->grid.size();
  return total;
}

bool TerrainRegistry::FitsWithoutOrphans(uint64_t samples) const {
  const uint64_t most = limits_.max_total_samples, kept = TotalSamples() - OrphanSamples();
  return samples <= most && kept <= most - samples;
}

bool TerrainRegistry::MakeRoomForSamples(uint64_t samples) {
  const uint64_t most = limits_.max_total_samples;
  if (!FitsWithoutOrphans(samples)) return false;
  while (TotalSamples() > most - samples && EvictOldestOrphan()) {
  }
  return TotalSamples() <= most - samples;
}

std::vector<uint32_t> TerrainRegistry::TakeEvicted() {
  std::vector<uint32_t> evicted;
  evicted.swap(evicted_);
  return evicted;
}

std::vector<uint32_t> TerrainRegistry::ExpireOrphans() {
  const auto now = std::chrono::steady_clock::now();
  std::vector<uint32_t> freed;
  for (auto it = terrains_.begin(); it != terrains_.end();) {
    const LoadedTerrain& t = *it->second;
    const double idle_s = std::chrono::duration<double>(now - t.used).count();
    if (t.owner == 0 && idle_s >= limits_.orphan_idle_s) {
      freed.push_back(it->first);
      it = terrains_.erase(it);
    } else {
      ++it;
    }
  }
  return freed;
}

void TerrainRegistry::ExpireUploads() {
  const auto now = std::chrono::steady_clock::now();
  for (auto it = uploads_.begin(); it != uploads_.end();) {
    const double idle = std::chrono::duration<double>(now - it->second.touched).count();
    if (idle <= limits_.upload_idle_s) {
      ++it;
      continue;
    }
    expired_uploads_.push_back(
        UploadText(it->first, it->second.name, it->second.samples.size(), it->second.total));
    if (expired_ids_.size() >= kRememberedExpiries) expired_ids_.pop_front();
    expired_ids_.emplace_back(it->first, it->second.owner);
    it = uploads_.erase(it);
  }
}

std::vector<std::string> TerrainRegistry::TakeExpiredUploads() {
  std::vector<std::string> expired;
  expired.swap(expired_uploads_);
  return expired;
}

void TerrainRegistry::Record(const RecentQuery& query) {
  if (limits_.recent_capacity == 0) return;
  if (recent_.size() >= limits_.recent_capacity) recent_.pop_front();
  recent_.push_back(query);
  recent_.back().sequence = ++sequence_;
}

std::vector<RecentQuery> TerrainRegistry::RecentAfter(uint64_t after, size_t max,
                                                      uint64_t* latest) const {
  *latest = sequence_;
  std::vector<RecentQuery> out;
  for (const RecentQuery& q : recent_) {
    if (q.sequence <= after) continue;
    if (out.size() >= max) break;
    out.push_back(q);
  }
  return out;
}

}  // namespace footfall
