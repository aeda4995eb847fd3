// PinnedFile: a terrain file under footfalld's data root, held open from the moment it is
// checked until it has been read, so that what is read is what was checked.
//
// The loaders open files by name (and pick the format from the name's extension). Between a
// check of a path and a later open of it, a component of the path could be swapped for a
// symlink leading out of the data root. A PinnedFile opens the path once (the last component
// not followed), checks where the opened file really lies (inside the root, a regular file),
// and gives the loaders a name of its own, in a private directory, that reaches that very open
// file whatever happens to the path meanwhile.
#pragma once

#include <string>

#include "footfall/terrain/status.h"

namespace footfall {

// True when the canonical `path` is the canonical directory `root` or lies below it.
bool PathInside(const std::string& root, const std::string& path);

// Whether PinnedFile::Open can make its private directories (in $TMPDIR, else /tmp): false with
// *message saying where and why not, for footfalld to warn at start.
bool CanMakePrivateDirectory(std::string* message);

// Removes the private names of every PinnedFile still open, for a process that ends without
// destroying them (footfalld abandoning a load at SIGTERM). Thread-safe.
void RemovePinnedNames();

class PinnedFile {
 public:
  PinnedFile() = default;
  ~PinnedFile();
  PinnedFile(const PinnedFile&) = delete;
  PinnedFile& operator=(const PinnedFile&) = delete;

  // Opens `path` (canonical, under the canonical directory `root`) without blocking and without
  // following a last-component symlink. kAccessDenied when the opened file lies outside `root`,
  // kInvalidArgument when it is not a regular file, kIoError when it cannot be opened or
  // pinned. Messages name the file as `shown`.
  Status Open(const std::string& root, const std::string& path, const std::string& shown,
              std::string* message);

  // A path that reads the opened file, with the extension of `shown` (the name the client
  // gave, which may be a link to a file named otherwise); empty before Open succeeds. Valid
  // while this object lives.
  const std::string& path() const { return link_; }

 private:
  int fd_ = -1;
  std::string dir_, link_;
};

}  // namespace footfall
