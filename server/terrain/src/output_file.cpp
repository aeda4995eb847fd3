#include "footfall/terrain/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

namespace footfall {
namespace {

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
  if (std::fclose(file) != 0 && failure == 0) failure = errno ? errno : EIO;
  return failure;
}

// The process's umask, for the permissions of a new file (mkstemp makes it 0600).
mode_t CurrentUmask() {
  const mode_t mask = umask(022);
  umask(mask);
  return mask;
}

}  // namespace

Status ReplaceFile(const std::string& path, const std::function<bool(std::FILE*)>& write,
                   std::string* error) {
  // A symbolic link is followed to the file it names (when there is one).
  std::string target = path;
  struct stat link_st;
  if (::lstat(path.c_str(), &link_st) == 0 && S_ISLNK(link_st.st_mode)) {
    char resolved[PATH_MAX];
    if (::realpath(path.c_str(), resolved) != nullptr) target = resolved;
  }
  struct stat st;
  const bool exists = ::stat(target.c_str(), &st) == 0;
  auto in_place = [&]() {
    std::FILE* file = std::fopen(target.c_str(), "wb");
    if (!file) return Fail("cannot open", path, errno, error);
    const int failure = WriteAndClose(file, write);
    return failure ? Fail("cannot write", path, failure, error) : Status::kOk;
  };
  if (exists && !S_ISREG(st.st_mode)) return in_place();
  const size_t slash = target.rfind('/');
  const std::string dir = slash == std::string::npos ? "" : target.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? target : target.substr(slash + 1);
  std::string temp = dir + "." + name + ".XXXXXX";
  const int fd = ::mkstemp(&temp[0]);
  if (fd < 0) {
    const int why = errno;
    // A directory that takes no new file may still let an existing file be rewritten.
    if (exists && (why == EACCES || why == EPERM || why == EROFS || why == ENAMETOOLONG))
      return in_place();
    return Fail("cannot open", path, why, error);
  }
  ::fchmod(fd, exists ? (st.st_mode & 07777) : (0666 & ~CurrentUmask()));
  std::FILE* file = ::fdopen(fd, "wb");
  if (!file) {
    const int why = errno;
    ::close(fd);
    ::unlink(temp.c_str());
    return Fail("cannot write", path, why, error);
  }
  const int failure = WriteAndClose(file, write);
  if (failure != 0) {
    ::unlink(temp.c_str());
    return Fail("cannot write", path, failure, error);
  }
  if (::rename(temp.c_str(), target.c_str()) != 0) {
    const int why = errno;
    ::unlink(temp.c_str());
    return Fail("cannot write", path, why, error);
  }
  return Status::kOk;
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
