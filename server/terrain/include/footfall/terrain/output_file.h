// Writing files so that a failed write never destroys what was there: the new content goes to a
// temporary file beside the target and replaces it (a rename) only once it is complete, with the
// target's permissions (and owner, where the writer may give it). A full disk, a write error or
// an exception leaves the old file whole and no temporary file behind. Through a symbolic link
// (also one naming a file not there yet), the file it names is written (the link stays). A
// target the writer may not write is refused, as opening it would be, and so are a new file in
// a directory that takes no new file, and a loop of links. A file with other names (hard links)
// gets a new file under this name; the other names keep the old content. Written in place (where
// a failed write can cut the file): a device such as /dev/null or a FIFO (once a process reads
// it: waited for up to 5 s), another user's writable file in a sticky directory (/tmp), which no
// rename may replace, and a writable file in a directory that takes no new file (no temporary
// file can be made beside it). Not synced to disk: a power cut may still lose the new content,
// never the old one to a write error.
#pragma once

#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "footfall/terrain/status.h"

namespace footfall {

// Calls write(file) to write the new content, then replaces the file at `path` with it. `write`
// returns false when it failed (the stream's own errors are checked too). On failure returns
// kIoError with "cannot write 'PATH': REASON" (or "cannot open 'PATH' for writing: REASON") in
// *error, and the file at `path` is as it was (unless written in place).
Status ReplaceFile(const std::string& path, const std::function<bool(std::FILE*)>& write,
                   std::string* error);

// The same with the whole new content given.
Status ReplaceFile(const std::string& path, std::string_view bytes, std::string* error);

// The checks ReplaceFile makes before it writes, without writing: kIoError with its message when
// `path` could not be written (a missing directory, a read-only file, a new file in a read-only
// directory, a loop of links), so that a long job can be refused before it starts.
Status CheckWritable(const std::string& path, std::string* error);

// True when writing `a` would write the file `b` names, or the file writing `b` would write:
// the same path however spelt, links followed (also ones naming a file not there yet), or hard
// links to one file.
bool SameFile(const std::string& a, const std::string& b);

// Files replaced together, such as one walk's outputs: while a set is open on a thread, each
// ReplaceFile there writes its new content to its temporary file and leaves the target as it
// was; Commit then replaces all of them, one rename after another with SIGINT, SIGTERM, SIGHUP,
// SIGQUIT and SIGABRT held back until the last (on this thread, and RemoveTemporaryFileOnSignal's
// handler waits for the renames on any other), so that such a signal (Ctrl-C) leaves either
// every old file or every new one, never a mix. Files written in place (devices, FIFOs, see above)
// are written at once, and so is any file past the 256th waiting at a time. A set closed without
// Commit removes its temporary files: the targets stay as they were. Sets do not nest.
class OutputFileSet {
 public:
  OutputFileSet();
  ~OutputFileSet();
  OutputFileSet(const OutputFileSet&) = delete;
  OutputFileSet& operator=(const OutputFileSet&) = delete;

  // Replaces every file written in the set so far and closes it. Returns a message ("cannot
  // write 'PATH': REASON") for each that could not be replaced (that target stays as it was);
  // the others are replaced.
  std::vector<std::string> Commit();

  struct State;

 private:
  std::unique_ptr<State> state_;
};

// For programs (not libraries: it sets process-wide signal handlers): SIGINT, SIGTERM, SIGHUP,
// SIGQUIT and SIGABRT (an abort, as a library's failed assertion) remove the temporary files
// being written or waiting in a set before the process ends as they would end it (those ignored
// when the program started, as under nohup, stay ignored), and SIGXFSZ is
// ignored, so that a write past the file size limit fails with a message. A thread of its own,
// when one can start, takes those signals while the others block them (libtirpc blocks every
// signal during an RPC call), so that they end the process at once.
void RemoveTemporaryFileOnSignal();

}  // namespace footfall
