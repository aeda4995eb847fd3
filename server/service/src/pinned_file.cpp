#include "footfall/service/pinned_file.h"

#include <fcntl.h>
#include <limits.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>

#include "service_log.h"

namespace footfall {
namespace {

// The private names of the open PinnedFiles (link -> its directory).
std::mutex g_names_mutex;
std::map<std::string, std::string> g_names;

}  // namespace

void RemovePinnedNames() {
  std::lock_guard<std::mutex> lock(g_names_mutex);
  for (const auto& [link, dir] : g_names) unlink(link.c_str()), rmdir(dir.c_str());
  g_names.clear();
}

bool PathInside(const std::string& root, const std::string& path) {
  return root == "/" || path == root || path.compare(0, root.size() + 1, root + "/") == 0;
}

PinnedFile::~PinnedFile() {
  {
    std::lock_guard<std::mutex> lock(g_names_mutex);
    g_names.erase(link_);
  }
  if (!link_.empty()) unlink(link_.c_str());
  if (!dir_.empty()) rmdir(dir_.c_str());
  if (fd_ >= 0) close(fd_);
}

namespace {

// Makes a new private directory in $TMPDIR (else /tmp) into *dir; false with *message saying
// where and why not.
bool MakePrivateDirectory(std::string* dir, std::string* message) {
  const char* tmp = getenv("TMPDIR");
  const std::string base = tmp && *tmp ? tmp : "/tmp";
  std::string made = base + "/footfalld-XXXXXX";
  if (!mkdtemp(made.data())) {
    const int error = errno;
    *message = "cannot make a private directory to read it from in " + EscapeControl(base) + ": " +
               std::strerror(error) +
               " (footfalld's TMPDIR, else /tmp, must be a folder it may write)";
    return false;
  }
  *dir = made;
  return true;
}

}  // namespace

bool CanMakePrivateDirectory(std::string* message) {
  std::string dir;
  if (!MakePrivateDirectory(&dir, message)) return false;
  rmdir(dir.c_str());
  return true;
}

Status PinnedFile::Open(const std::string& root, const std::string& path, const std::string& shown,
                        std::string* message) {
  fd_ = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC | O_NOFOLLOW);
  if (fd_ < 0) {
    const int error = errno;
    *message = "'" + shown + "': cannot open: " + std::strerror(error);
    return error == EACCES ? Status::kAccessDenied : Status::kIoError;
  }
  // Where the opened file lies now, whatever the path's components were swapped for.
  const std::string self = "/proc/self/fd/" + std::to_string(fd_);
  char real[PATH_MAX];
  const ssize_t n = readlink(self.c_str(), real, sizeof real - 1);
  if (n < 0) {
    *message = "'" + shown + "': cannot tell where the opened file lies";
    return Status::kIoError;
  }
  real[n] = '\0';
  if (!PathInside(root, real)) {
    *message = "'" + shown + "' leads outside the data root";
    return Status::kAccessDenied;
  }
  struct stat st {};
  if (fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
    *message = "'" + shown + "' is not a regular file: expected a regular terrain file";
    return Status::kInvalidArgument;
  }
  // A private name for it: <tmp>/footfalld-XXXXXX/terrain.<ext> -> /proc/self/fd/N.
  std::string why;
  if (!MakePrivateDirectory(&dir_, &why)) {
    *message = "'" + shown + "': " + why;
    return Status::kIoError;
  }
  // The format is the one the client's name says, as for a local file of that name: not the
  // resolved target's (a link into an extensionless blob store).
  const size_t slash = shown.rfind('/'), dot = shown.rfind('.');
  const std::string ext = dot != std::string::npos && (slash == std::string::npos || dot > slash)
                              ? shown.substr(dot)
                              : "";
  const std::string link = dir_ + "/terrain" + ext;
  if (symlink(self.c_str(), link.c_str()) != 0) {
    *message = "'" + shown + "': cannot make a private name to read it from";
    return Status::kIoError;
  }
  link_ = link;
  std::lock_guard<std::mutex> lock(g_names_mutex);
  g_names.emplace(link_, dir_);
  return Status::kOk;
}

}  // namespace footfall
