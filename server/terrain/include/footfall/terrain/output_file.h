// Writing files so that a failed write never destroys what was there: the new content goes to a
// temporary file beside the target and replaces it (a rename) only once it is complete, with the
// target's permissions. A full disk, a write error or an exception leaves the old file whole and
// no temporary file behind. Through a symbolic link, the file it names is replaced (the link
// stays). A target that is not a regular file (a device such as /dev/null, a FIFO), or one in a
// directory that takes no new file, is written in place. Not synced to disk: a power cut may
// still lose the new content, never the old one to a write error.
#pragma once

#include <cstdio>
#include <functional>
#include <string>
#include <string_view>

#include "footfall/terrain/status.h"

namespace footfall {

// Calls write(file) to write the new content, then replaces the file at `path` with it. `write`
// returns false when it failed (the stream's own errors are checked too). On failure returns
// kIoError with "cannot write 'PATH': REASON" (or "cannot open 'PATH' for writing: REASON") in
// *error, and the file at `path` is as it was.
Status ReplaceFile(const std::string& path, const std::function<bool(std::FILE*)>& write,
                   std::string* error);

// The same with the whole new content given.
Status ReplaceFile(const std::string& path, std::string_view bytes, std::string* error);

}  // namespace footfall
