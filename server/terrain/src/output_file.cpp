#include "footfall/terrain/output_file.h"

#include <fcntl.h>
#include <pthread.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <new>
#include <thread>

#include "footfall/terrain/process_start.h"

namespace footfall {
namespace {

// How long a FIFO written to may wait for a reader: tries x interval.
constexpr int kFifoWaitTries = 50;
constexpr int kFifoWaitMicroseconds = 100000;

Status Fail(const std::string& what, const std::string& path, int error_number,
            std::string* error) {
  if (error)
    *error = what + " '" + path + "'" + (what == "cannot open" ? " for writing" : "") + ": " +
             std::strerror(error_number ? error_number : EIO);
  return Status::kIoError;
}

// Runs `write` on an open stream and closes it; the errno of the first failure, or 0.
int WriteAndClose(std::FILE* file, const std::function<bool(std::FILE*)>& write) {
  errno = 0;
  bool ok = false;
  int failure = 0;
  try {
    ok = write(file);
  } catch (...) {
    failure = ENOMEM;
  }
  if (!ok && failure == 0) failure = errno ? errno : EIO;
  if (std::fflush(file) != 0 && failure == 0) failure = errno ? errno : EIO;
  if (std::ferror(file) && failure == 0) failure = EIO;
  // A regular file reaches the disk before it counts as written (and before it replaces the
  // old one): a full or failing disk or quota reported only at write-back is an error here.
  struct stat st;
  if (failure == 0 && ::fstat(::fileno(file), &st) == 0 && S_ISREG(st.st_mode) &&
      ::fsync(::fileno(file)) != 0)
    failure = errno ? errno : EIO;
  if (std::fclose(file) != 0 && failure == 0) failure = errno ? errno : EIO;
  return failure;
}

// The process's umask, for the permissions of a new file (mkstemp makes it 0600).
mode_t CurrentUmask() {
  const mode_t mask = umask(022);
  umask(mask);
  return mask;
}

// The file that writing `path` creates or replaces: symbolic links followed, also a link naming
// a file not there yet (it is created where the link points).
std::string FollowLinks(const std::string& path, bool* loop = nullptr) {
  std::string p = path;
  if (loop) *loop = false;
  for (int hops = 0;; ++hops) {
    struct stat st;
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) break;
    if (hops == 40) {  // a loop of links, or a chain longer than the system follows
      if (loop) *loop = true;
      break;
    }
    char to[PATH_MAX];
    const ssize_t n = ::readlink(p.c_str(), to, sizeof to - 1);
    if (n <= 0) break;
    const std::string target(to, static_cast<size_t>(n));
    const size_t slash = p.rfind('/');
    p = target[0] == '/' || slash == std::string::npos ? target : p.substr(0, slash + 1) + target;
  }
  return p;
}

// The temporary files being written or waiting in a set, for RemoveTemporaryFileOnSignal's
// handler: a slot each, claimed and freed without locks (the handler may run at any time).
constexpr size_t kTemporarySlots = 256;
std::atomic<const char*> g_temporaries[kTemporarySlots];

// Claims a slot for `name` (which must outlive the claim); the slot's index, or -1 when all are
// taken.
int ClaimTemporarySlot(const char* name) {
  for (size_t i = 0; i < kTemporarySlots; ++i) {
    const char* expected = nullptr;
    if (g_temporaries[i].compare_exchange_strong(expected, name)) return static_cast<int>(i);
  }
  return -1;
}

void FreeTemporarySlot(int slot) {
  if (slot >= 0) g_temporaries[slot].store(nullptr);
}

// Set while a set's files are renamed: a signal taken on another thread then waits for the
// renames to end (they take microseconds), so that it never leaves some renamed and some not.
std::atomic<bool> g_committing{false};

void RemoveTemporariesAndReraise(int signal_number) {
  while (g_committing.load()) {
  }
  for (auto& temporary : g_temporaries) {
    const char* name = temporary.load();
    if (name != nullptr) ::unlink(name);
  }
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

// The signals RemoveTemporaryFileOnSignal handles, held back while a set is replaced. SIGABRT
// too: a library that aborts (tinygltf's assertions when memory runs out as it serialises)
// left the temporary files of every output written so far.
constexpr int kCleanedUpSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGABRT};

// Makes the rename of a file in `dir` ("" for the working directory) reach the disk with its
// directory (best effort: the file is written).
void SyncDirectory(const std::string& dir) {
  const int dir_fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

// How a file is written: where (links followed), and whether in place or by rename.
struct WritePlan {
  std::string target;
  bool exists = false;
  bool in_place = false;
  struct stat st {};
};

// Decides how `path` is written, or why it cannot be (the checks ReplaceFile makes before it
// writes anything).
Status PlanWrite(const std::string& path, WritePlan* plan, std::string* error) {
  bool loop = false;
  plan->target = FollowLinks(path, &loop);
  if (loop) return Fail("cannot open", path, ELOOP, error);
  const std::string& target = plan->target;
  plan->exists = ::stat(target.c_str(), &plan->st) == 0;
  const struct stat& st = plan->st;
  // A file its owner made read-only stays refused, as opening it for writing would be.
  if (plan->exists && ::access(target.c_str(), W_OK) != 0)
    return Fail("cannot open", path, errno, error);
  // A directory is no file to write (refused up front, before a long job writes the others).
  if (plan->exists && S_ISDIR(st.st_mode)) return Fail("cannot open", path, EISDIR, error);
  // Devices and FIFOs are written as they are.
  if (plan->exists && !S_ISREG(st.st_mode)) {
    plan->in_place = true;
    return Status::kOk;
  }
  const size_t slash = target.rfind('/');
  const std::string dir = slash == std::string::npos ? "." : target.substr(0, slash + 1);
  // Another user's file that this one may write, in a sticky directory (/tmp) neither owns: no
  // rename may replace it, so it is written in place (as before; a failed write can cut it).
  struct stat dir_st;
  if (::stat(dir.c_str(), &dir_st) != 0) return Fail("cannot open", path, errno, error);
  if (plan->exists && ::geteuid() != 0 && st.st_uid != ::geteuid() && (dir_st.st_mode & S_ISVTX) &&
      dir_st.st_uid != ::geteuid()) {
    plan->in_place = true;
    return Status::kOk;
  }
  // The temporary file is made in the directory. Where none may be made, a file there that may
  // be written is written in place (as before; a failed write can cut it).
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    const int why = errno;
    if (plan->exists) {
      plan->in_place = true;
      return Status::kOk;
    }
    if (error)
      *error = "cannot create '" + path + "': the directory '" + dir + "' takes no new file (" +
               std::strerror(why) + ")";
    return Status::kIoError;
  }
  return Status::kOk;
}

}  // namespace

// A file written to its temporary file, waiting for its set's Commit.
struct WaitingFile {
  std::string path;       // as given, for messages
  std::string target;     // links followed
  std::string dir;        // the target's directory, "" for the working directory
  std::string temporary;  // its name is in g_temporaries[slot] until renamed or removed
  int slot = -1;
};

struct OutputFileSet::State {
  std::vector<std::unique_ptr<WaitingFile>> waiting;
};

namespace {

// The set open on this thread, or null.
thread_local OutputFileSet::State* t_open_set = nullptr;

}  // namespace

OutputFileSet::OutputFileSet() : state_(std::make_unique<State>()) {
  if (t_open_set == nullptr) t_open_set = state_.get();
}

OutputFileSet::~OutputFileSet() {
  if (t_open_set == state_.get()) t_open_set = nullptr;
  for (const auto& file : state_->waiting) {
    ::unlink(file->temporary.c_str());
    FreeTemporarySlot(file->slot);
  }
}

std::vector<std::string> OutputFileSet::Commit() {
  if (t_open_set == state_.get()) t_open_set = nullptr;
  std::vector<std::string> failures;
  sigset_t held, before;
  sigemptyset(&held);
  for (int signal_number : kCleanedUpSignals) sigaddset(&held, signal_number);
  pthread_sigmask(SIG_BLOCK, &held, &before);  // (signals taken on other threads wait too)
  g_committing.store(true);
  try {
    for (const auto& file : state_->waiting) {
      if (::rename(file->temporary.c_str(), file->target.c_str()) != 0) {
        const int why = errno;
        ::unlink(file->temporary.c_str());
        FreeTemporarySlot(file->slot);  // before the message, which may run out of memory
        file->slot = -1;
        std::string message;
        Fail("cannot write", file->path, why, &message);
        failures.push_back(message);
        continue;
      }
      FreeTemporarySlot(file->slot);
      file->slot = -1;
    }
  } catch (...) {
    // Memory ran out describing a failure: the signal handler may not wait for ever.
    g_committing.store(false);
    pthread_sigmask(SIG_SETMASK, &before, nullptr);
    throw;
  }
  g_committing.store(false);
  pthread_sigmask(SIG_SETMASK, &before, nullptr);
  std::vector<std::string> synced;
  for (const auto& file : state_->waiting) {
    if (std::find(synced.begin(), synced.end(), file->dir) != synced.end()) continue;
    SyncDirectory(file->dir);
    synced.push_back(file->dir);
  }
  state_->waiting.clear();
  return failures;
}

void RemoveTemporaryFileOnSignal() {
  // A signal ignored when the program started stays ignored (`nohup footfall generate` died at
  // the hangup, writing nothing).
  for (int signal_number : kCleanedUpSignals)
    if (!SignalIgnored(signal_number)) std::signal(signal_number, RemoveTemporariesAndReraise);
  // A thread that only waits, with no signal blocked, to take them while the others block
  // every signal: libtirpc does for the length of each call, and Ctrl-C waited minutes for a
  // --server-terrain load to finish. Without one (no thread may start: ulimit -u), signals
  // wait for those calls.
  static std::once_flag waiter;
  std::call_once(waiter, [] {
    try {
      std::thread([] {
        for (;;) ::pause();
      }).detach();
    } catch (const std::system_error&) {
    }
  });
  // Past the file size limit a write fails (EFBIG) and is reported, instead of killing the
  // process with the temporary file left behind.
  std::signal(SIGXFSZ, SIG_IGN);
}

Status CheckWritable(const std::string& path, std::string* error) {
  WritePlan plan;
  return PlanWrite(path, &plan, error);
}

Status ReplaceFile(const std::string& path, const std::function<bool(std::FILE*)>& write,
                   std::string* error) {
  WritePlan plan;
  const Status planned = PlanWrite(path, &plan, error);
  if (planned != Status::kOk) return planned;
  const std::string& target = plan.target;
  const bool exists = plan.exists;
  const struct stat& st = plan.st;
  if (plan.in_place) {
    std::FILE* file = nullptr;
    if (exists && S_ISFIFO(st.st_mode)) {
      // A FIFO opens for writing only once a process reads it: waited for a while, not forever
      // (the walk is made by then; the other outputs are still written).
      int fd = -1;
      for (int tries = 0; fd < 0 && tries < kFifoWaitTries; ++tries) {
        fd = ::open(target.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
        if (fd < 0 && errno != ENXIO) return Fail("cannot open", path, errno, error);
        if (fd < 0) ::usleep(kFifoWaitMicroseconds);
      }
      if (fd < 0) {
        if (error) {
          *error = "cannot open '" + path + "' for writing: no process reads the FIFO (waited " +
                   std::to_string(kFifoWaitTries * kFifoWaitMicroseconds / 1000000) + " s)";
        }
        return Status::kIoError;
      }
      ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
      file = ::fdopen(fd, "wb");
      if (!file) ::close(fd);
    } else {
      file = std::fopen(target.c_str(), "wb");
    }
    if (!file) return Fail("cannot open", path, errno, error);
    const int failure = WriteAndClose(file, write);
    return failure ? Fail("cannot write", path, failure, error) : Status::kOk;
  }
  const size_t slash = target.rfind('/');
  const std::string dir = slash == std::string::npos ? "" : target.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? target : target.substr(slash + 1);
  // ".NAME.XXXXXX" beside it; a name too long for that takes a short temporary name.
  auto waiting = std::make_unique<WaitingFile>();
  std::string& temp = waiting->temporary;
  temp = dir + (name.size() <= 200 ? "." + name : std::string(".footfall")) + ".XXXXXX";
  const int fd = ::mkstemp(&temp[0]);
  if (fd < 0) return Fail("cannot open", path, errno, error);
  const int slot = ClaimTemporarySlot(temp.c_str());
  if (exists) {
    ::fchmod(fd, st.st_mode & 07777);
    if (::fchown(fd, st.st_uid, st.st_gid) != 0) {
      // Not ours to give away (only root may): the file becomes the writer's, as a new one.
    }
  } else {
    ::fchmod(fd, 0666 & ~CurrentUmask());
  }
  // Every failure from here removes the temporary file, and leaves the target as it was.
  auto abandon = [&](int why) {
    ::unlink(temp.c_str());
    FreeTemporarySlot(slot);
    return Fail("cannot write", path, why, error);
  };
  std::FILE* file = ::fdopen(fd, "wb");
  if (!file) {
    const int why = errno;
    ::close(fd);
    return abandon(why);
  }
  // In an open set (with a slot for the signal handler), replaced at its Commit. Its place in
  // the set is made before the file is written: memory running out once it was written left the
  // temporary file behind.
  const bool in_set = t_open_set != nullptr && slot >= 0;
  if (in_set) {
    try {
      waiting->path = path;
      waiting->target = target;
      waiting->dir = dir;
      waiting->slot = slot;
      t_open_set->waiting.reserve(t_open_set->waiting.size() + 1);
    } catch (const std::bad_alloc&) {
      std::fclose(file);
      return abandon(ENOMEM);
    }
  }
  const int failure = WriteAndClose(file, write);
  if (failure != 0) return abandon(failure);
  if (in_set) {
    t_open_set->waiting.push_back(std::move(waiting));  // room made above
    return Status::kOk;
  }
  if (::rename(temp.c_str(), target.c_str()) != 0) return abandon(errno);
  FreeTemporarySlot(slot);
  SyncDirectory(dir);
  return Status::kOk;
}

bool SameFile(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  auto written = [](const std::string& path) {
    std::error_code ec;
    const fs::path p = fs::absolute(FollowLinks(path), ec).lexically_normal();
    const fs::path canonical = fs::weakly_canonical(p, ec);
    return ec ? p : canonical;
  };
  std::error_code ec;
  return written(a) == written(b) || fs::equivalent(a, b, ec);
}

Status ReplaceFile(const std::string& path, std::string_view bytes, std::string* error) {
  return ReplaceFile(
      path,
      [bytes](std::FILE* file) {
        return std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
      },
      error);
}

}  // namespace footfall
