// PinnedFile: a server-side terrain file is read through the file descriptor that was checked,
// not opened again by name, so a path whose components are swapped meanwhile cannot lead the
// server out of its data root.
#include "footfall/service/pinned_file.h"

#include <limits.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <catch2/catch.hpp>

using namespace footfall;

namespace {

// A fresh directory under TMPDIR (canonical), removed with everything in it at the end.
struct ScratchDir {
  std::string path;
  ScratchDir() {
    const char* tmp = getenv("TMPDIR");
    std::string t = std::string(tmp && *tmp ? tmp : "/tmp") + "/footfall_pin_XXXXXX";
    REQUIRE(mkdtemp(t.data()));
    char real[PATH_MAX];
    REQUIRE(realpath(t.c_str(), real));
    path = real;
  }
  ~ScratchDir() { std::system(("rm -rf '" + path + "'").c_str()); }
};

void Write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST_CASE("PinnedFile reads the file it checked, whatever its path leads to afterwards",
          "[service]") {
  ScratchDir scratch;
  const std::string root = scratch.path + "/root", outside = scratch.path + "/outside";
  REQUIRE(mkdir(root.c_str(), 0700) == 0);
  REQUIRE(mkdir((root + "/sub").c_str(), 0700) == 0);
  REQUIRE(mkdir(outside.c_str(), 0700) == 0);
  const std::string file = root + "/sub/a.pts";
  Write(file, "0 0 0 0 1 0\n");
  Write(outside + "/a.pts", "secret\n");
  std::string message, dir;
  {
    PinnedFile pinned;
    REQUIRE(pinned.Open(root, file, "sub/a.pts", &message) == Status::kOk);
    // Named for the loaders with the original's extension, in a private directory.
    CHECK(pinned.path().size() > 4);
    CHECK(pinned.path().substr(pinned.path().size() - 4) == ".pts");
    dir = pinned.path().substr(0, pinned.path().rfind('/'));
    // The file is replaced under its name, then its directory by a link leading outside: the
    // pinned name still reads what was checked.
    Write(root + "/sub/b.pts", "1 1 1 0 1 0\n");
    REQUIRE(std::rename((root + "/sub/b.pts").c_str(), file.c_str()) == 0);
    REQUIRE(std::rename((root + "/sub").c_str(), (root + "/old").c_str()) == 0);
    REQUIRE(symlink(outside.c_str(), (root + "/sub").c_str()) == 0);
    CHECK(Read(pinned.path()) == "0 0 0 0 1 0\n");
  }
  // The private directory is gone with it.
  struct stat st {};
  CHECK(stat(dir.c_str(), &st) != 0);

  // Opened after the swap, the same canonical path now lies outside: refused.
  PinnedFile swapped;
  CHECK(swapped.Open(root, file, "sub/a.pts", &message) == Status::kAccessDenied);
  CHECK(message == "'sub/a.pts' leads outside the data root");
  CHECK(swapped.path().empty());
  // A link as the last component is not followed; a FIFO is not a terrain file.
  REQUIRE(symlink((outside + "/a.pts").c_str(), (root + "/link.pts").c_str()) == 0);
  PinnedFile link;
  CHECK(link.Open(root, root + "/link.pts", "link.pts", &message) == Status::kIoError);
  REQUIRE(mkfifo((root + "/fifo.pts").c_str(), 0600) == 0);
  PinnedFile fifo;
  CHECK(fifo.Open(root, root + "/fifo.pts", "fifo.pts", &message) == Status::kInvalidArgument);
}

TEST_CASE("PinnedFile names the file for the loaders by the extension the client gave",
          "[service]") {
  // A client's "hills.pts" may be a link into a store whose files have no extension (or another
  // one): the format is the one the client's name says, as for a local file of that name.
  ScratchDir scratch;
  const std::string root = scratch.path;
  REQUIRE(mkdir((root + "/store").c_str(), 0700) == 0);
  Write(root + "/store/0a1b2c", "0 0 0 0 1 0\n");
  Write(root + "/store/mesh.obj", "0 0 0 0 1 0\n");
  std::string message;
  PinnedFile blob;
  REQUIRE(blob.Open(root, root + "/store/0a1b2c", "hills.pts", &message) == Status::kOk);
  CHECK(blob.path().substr(blob.path().rfind('/')) == "/terrain.pts");
  CHECK(Read(blob.path()) == "0 0 0 0 1 0\n");
  PinnedFile renamed;
  REQUIRE(renamed.Open(root, root + "/store/mesh.obj", "sub.d/points.xyz", &message) ==
          Status::kOk);
  CHECK(renamed.path().substr(renamed.path().rfind('/')) == "/terrain.xyz");
  PinnedFile bare;
  REQUIRE(bare.Open(root, root + "/store/mesh.obj", "sub.d/points", &message) == Status::kOk);
  CHECK(bare.path().substr(bare.path().rfind('/')) == "/terrain");
}
