// ReplaceFile: what a failed write leaves behind (the old file, whole, and nothing else), and
// how it treats permissions, symbolic links, devices, missing and read-only directories, and
// other users' files.
#include <dirent.h>
#include <grp.h>
#include <pwd.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/terrain/output_file.h"

using namespace footfall;

namespace {

struct Dir {
  std::string path;
  Dir() {
    char name[] = "/tmp/footfall_output_XXXXXX";
    path = ::mkdtemp(name);
  }
  ~Dir() { std::system(("rm -rf '" + path + "'").c_str()); }
  std::vector<std::string> Entries() const {
    std::vector<std::string> names;
    DIR* d = ::opendir(path.c_str());
    while (dirent* e = ::readdir(d))
      if (std::string(e->d_name) != "." && std::string(e->d_name) != "..")
        names.push_back(e->d_name);
    ::closedir(d);
    return names;
  }
};

std::string Read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

mode_t Mode(const std::string& path) {
  struct stat st;
  REQUIRE(::stat(path.c_str(), &st) == 0);
  return st.st_mode & 07777;
}

}  // namespace

TEST_CASE("ReplaceFile replaces a file whole, or leaves it as it was", "[terrain][output_file]") {
  Dir dir;
  const std::string file = dir.path + "/walk.json";
  std::string error;
  REQUIRE(ReplaceFile(file, "old content\n", &error) == Status::kOk);
  CHECK(Read(file) == "old content\n");
  // New files get the permissions the umask allows, as fopen would give them.
  const mode_t mask = ::umask(022);
  ::umask(mask);
  CHECK(Mode(file) == (0666 & ~mask));

  // A write that fails half-way (a full disk) leaves the old file whole and no temporary file.
  const Status failed = ReplaceFile(
      file,
      [](std::FILE* f) {
        std::fputs("half of the new", f);
        return false;
      },
      &error);
  CHECK(failed == Status::kIoError);
  CHECK_THAT(error, Catch::StartsWith("cannot write '" + file + "': "));
  CHECK(Read(file) == "old content\n");
  CHECK(dir.Entries() == std::vector<std::string>{"walk.json"});
  // So does an exception thrown while writing (out of memory).
  CHECK(ReplaceFile(
            file, [](std::FILE*) -> bool { throw std::bad_alloc(); }, &error) == Status::kIoError);
  CHECK(Read(file) == "old content\n");
  CHECK(dir.Entries().size() == 1);

  // A replaced file keeps its permissions.
  ::chmod(file.c_str(), 0640);
  REQUIRE(ReplaceFile(file, "new content\n", &error) == Status::kOk);
  CHECK(Read(file) == "new content\n");
  CHECK(Mode(file) == 0640);
  CHECK(dir.Entries().size() == 1);
}

TEST_CASE("ReplaceFile follows symbolic links and writes devices in place",
          "[terrain][output_file]") {
  Dir dir;
  const std::string target = dir.path + "/target.mel", link = dir.path + "/link.mel";
  std::string error;
  REQUIRE(ReplaceFile(target, "one", &error) == Status::kOk);
  REQUIRE(::symlink(target.c_str(), link.c_str()) == 0);
  REQUIRE(ReplaceFile(link, "two", &error) == Status::kOk);
  struct stat st;
  REQUIRE(::lstat(link.c_str(), &st) == 0);
  CHECK(S_ISLNK(st.st_mode));  // the link stays a link
  CHECK(Read(target) == "two");

  // Devices are written in place (never renamed over): /dev/null takes anything, /dev/full
  // says why it does not.
  CHECK(ReplaceFile("/dev/null", "x", &error) == Status::kOk);
  REQUIRE(::stat("/dev/null", &st) == 0);
  CHECK(S_ISCHR(st.st_mode));
  CHECK(ReplaceFile("/dev/full", std::string(100000, 'x'), &error) == Status::kIoError);
  CHECK_THAT(error, Catch::Contains("cannot write '/dev/full': No space left on device"));

  // A missing directory or a directory as the target: refused with the reason.
  CHECK(ReplaceFile(dir.path + "/no/such/walk.json", "x", &error) == Status::kIoError);
  CHECK_THAT(error, Catch::Contains("cannot open '" + dir.path +
                                    "/no/such/walk.json' for writing: No such file or directory"));
  CHECK(ReplaceFile(dir.path, "x", &error) == Status::kIoError);
  CHECK_THAT(error, Catch::Contains("Is a directory"));
}

TEST_CASE("ReplaceFile writes a FIFO once a process reads it, and gives up on one none reads",
          "[terrain][output_file]") {
  Dir dir;
  const std::string fifo = dir.path + "/walk.json";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  std::string error;
  // No reader: a clear error after a bounded wait (it waited forever, and the outputs after it
  // were never written).
  CHECK(ReplaceFile(fifo, "x", &error) == Status::kIoError);
  CHECK_THAT(error, Catch::Contains("cannot open '" + fifo +
                                    "' for writing: no process reads the FIFO (waited 5 s)"));
  // A reader that comes a little later gets the content.
  const pid_t reader = ::fork();
  REQUIRE(reader >= 0);
  if (reader == 0) {
    ::usleep(300000);
    std::ifstream in(fifo, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    std::_Exit(text.str() == "walk" ? 0 : 1);
  }
  CHECK(ReplaceFile(fifo, "walk", &error) == Status::kOk);
  int status = 0;
  REQUIRE(::waitpid(reader, &status, 0) == reader);
  CHECK((WIFEXITED(status) && WEXITSTATUS(status) == 0));
}

TEST_CASE("ReplaceFile creates the file a dangling link names, and takes long names",
          "[terrain][output_file]") {
  Dir dir;
  std::string error;
  // A link to a file not there yet: the file is made where it points, the link kept.
  REQUIRE(::symlink("made.json", (dir.path + "/link.json").c_str()) == 0);
  REQUIRE(ReplaceFile(dir.path + "/link.json", "new", &error) == Status::kOk);
  struct stat st;
  REQUIRE(::lstat((dir.path + "/link.json").c_str(), &st) == 0);
  CHECK(S_ISLNK(st.st_mode));
  CHECK(Read(dir.path + "/made.json") == "new");
  // A name of 250 bytes: its ".NAME.XXXXXX" temporary name would be too long.
  const std::string long_name = dir.path + "/" + std::string(245, 'w') + ".json";
  CHECK(ReplaceFile(long_name, "long", &error) == Status::kOk);
  CHECK(Read(long_name) == "long");
  CHECK(dir.Entries().size() == 3);
}

TEST_CASE("ReplaceFile keeps a hard link's old content, refuses loops and files it may not write",
          "[terrain][output_file]") {
  Dir dir;
  std::string error;
  const std::string a = dir.path + "/a.mel", b = dir.path + "/b.mel";
  REQUIRE(ReplaceFile(a, "old", &error) == Status::kOk);
  REQUIRE(::link(a.c_str(), b.c_str()) == 0);
  REQUIRE(ReplaceFile(a, "new", &error) == Status::kOk);
  CHECK(Read(a) == "new");
  CHECK(Read(b) == "old");  // nothing lost under the other name (written in place, a failed
                            // write cut both)
  // CheckWritable says the same before anything is written.
  CHECK(CheckWritable(a, &error) == Status::kOk);
  CHECK(CheckWritable(dir.path + "/new.json", &error) == Status::kOk);
  CHECK(CheckWritable(dir.path + "/no/such/x.json", &error) == Status::kIoError);
  CHECK_THAT(error, Catch::Contains("No such file or directory"));
  // A directory: refused before anything is written (ReplaceFile failed only when writing).
  CHECK(CheckWritable(dir.path, &error) == Status::kIoError);
  CHECK_THAT(error, Catch::Contains("Is a directory"));
  CHECK(ReplaceFile(dir.path, "x", &error) == Status::kIoError);
  CHECK(dir.Entries().size() == 2);  // nothing made by the checks
  // A loop of links: refused (a regular file took the link's place).
  REQUIRE(::symlink("lb.json", (dir.path + "/la.json").c_str()) == 0);
  REQUIRE(::symlink("la.json", (dir.path + "/lb.json").c_str()) == 0);
  CHECK(ReplaceFile(dir.path + "/la.json", "x", &error) == Status::kIoError);
  CHECK_THAT(error, Catch::Contains("Too many levels of symbolic links"));
  CHECK(CheckWritable(dir.path + "/la.json", &error) == Status::kIoError);
  struct stat st;
  REQUIRE(::lstat((dir.path + "/la.json").c_str(), &st) == 0);
  CHECK(S_ISLNK(st.st_mode));
  // A read-only file: refused as opening it for writing would be (root may write anything).
  const std::string locked = dir.path + "/locked.json";
  REQUIRE(ReplaceFile(locked, "kept", &error) == Status::kOk);
  ::chmod(locked.c_str(), 0444);
  const Status status = ReplaceFile(locked, "new", &error);
  if (::geteuid() == 0) {
    CHECK(status == Status::kOk);
    CHECK(Mode(locked) == 0444);
  } else {
    CHECK(status == Status::kIoError);
    CHECK_THAT(error, Catch::Contains("Permission denied"));
    CHECK(Read(locked) == "kept");
  }
}

namespace {

// Runs `body` in a child process as the user nobody when the tests run as root (root may write
// anything: the checks below need a user who may not), else as the current user. Returns the
// child's message: empty when every check passed, else the first that failed.
std::string AsUnprivileged(const std::function<std::string()>& body) {
  int fds[2];
  REQUIRE(::pipe(fds) == 0);
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(fds[0]);
    std::string message;
    if (::geteuid() == 0) {
      const passwd* nobody = ::getpwnam("nobody");
      if (!nobody || ::setgroups(0, nullptr) != 0 || ::setgid(nobody->pw_gid) != 0 ||
          ::setuid(nobody->pw_uid) != 0)
        message = "cannot become the user nobody";
    }
    if (message.empty()) message = body();
    if (!message.empty() && ::write(fds[1], message.data(), message.size()) < 0) ::_exit(2);
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string message;
  char buffer[256];
  for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;)
    message.append(buffer, static_cast<size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) message += " (the child failed)";
  return message;
}

uid_t Owner(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 ? st.st_uid : static_cast<uid_t>(-1);
}

}  // namespace

TEST_CASE("ReplaceFile writes in place where no rename may replace the file",
          "[terrain][output_file]") {
  Dir dir;
  std::string error;
  const bool root = ::geteuid() == 0;
  ::chmod(dir.path.c_str(), 0755);
  // A writable file in a directory that takes no new file: written in place; a new file there
  // is refused, naming the directory.
  const std::string ro = dir.path + "/ro", kept = ro + "/walk.json";
  REQUIRE(::mkdir(ro.c_str(), 0755) == 0);
  REQUIRE(ReplaceFile(kept, "old", &error) == Status::kOk);
  ::chmod(kept.c_str(), 0666);
  ::chmod(ro.c_str(), 0555);
  // Another user's writable file in a sticky directory: written in place, still theirs. Only
  // root can set this up (the file must belong to a user other than the writer).
  const std::string sticky = dir.path + "/sticky", shared = sticky + "/shared.json";
  REQUIRE(::mkdir(sticky.c_str(), 0777) == 0);
  ::chmod(sticky.c_str(), 01777);
  REQUIRE(ReplaceFile(shared, "old", &error) == Status::kOk);
  ::chmod(shared.c_str(), 0666);
  const std::string message = AsUnprivileged([&]() -> std::string {
    std::string e;
    if (ReplaceFile(kept, "new", &e) != Status::kOk) return "read-only directory: " + e;
    if (Read(kept) != "new") return "read-only directory: not written";
    if (CheckWritable(ro + "/other.json", &e) != Status::kIoError ||
        e.find("the directory '" + ro + "/' takes no new file") == std::string::npos)
      return "read-only directory, new file: '" + e + "'";
    if (ReplaceFile(ro + "/other.json", "x", &e) != Status::kIoError)
      return "read-only directory, new file: written";
    if (!root) return "";
    if (ReplaceFile(shared, "new", &e) != Status::kOk) return "sticky directory: " + e;
    if (Read(shared) != "new") return "sticky directory: not written";
    return "";
  });
  CHECK(message == "");
  if (root) {
    CHECK(Owner(shared) == 0);  // still root's: written in place, not replaced
  } else {
    WARN("not run as root: another user's file in a sticky directory was not checked");
  }
  ::chmod(ro.c_str(), 0755);
}

TEST_CASE("A program's signals and file size limit leave no temporary file behind",
          "[terrain][output_file]") {
  Dir dir;
  const std::string file = dir.path + "/walk.json";
  std::string error;
  REQUIRE(ReplaceFile(file, "old", &error) == Status::kOk);
  // SIGTERM in the middle of a write: the process ends by the signal, the temporary file goes.
  const pid_t child = ::fork();
  if (child == 0) {
    RemoveTemporaryFileOnSignal();
    std::string e;
    ReplaceFile(
        file,
        [](std::FILE* f) {
          std::fputs("half", f);
          std::fflush(f);
          std::raise(SIGTERM);
          return true;
        },
        &e);
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  CHECK(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGTERM);
  CHECK(Read(file) == "old");
  CHECK(dir.Entries() == std::vector<std::string>{"walk.json"});
  // Past the file size limit: a message, not SIGXFSZ.
  const pid_t limited = ::fork();
  if (limited == 0) {
    RemoveTemporaryFileOnSignal();
    struct rlimit limit = {1000, 1000};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    std::string e;
    const Status s = ReplaceFile(file, std::string(100000, 'x'), &e);
    ::_exit(s == Status::kIoError && e.find("File too large") != std::string::npos ? 7 : 1);
  }
  ::waitpid(limited, &status, 0);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 7);
  CHECK(Read(file) == "old");
  CHECK(dir.Entries() == std::vector<std::string>{"walk.json"});
}

TEST_CASE("An output file set replaces its files together at Commit, or none of them",
          "[terrain][output_file]") {
  Dir dir;
  const std::string a = dir.path + "/walk.json", b = dir.path + "/walk.mel";
  std::string error;
  REQUIRE(ReplaceFile(a, "old a", &error) == Status::kOk);
  REQUIRE(ReplaceFile(b, "old b", &error) == Status::kOk);
  {
    OutputFileSet set;
    REQUIRE(ReplaceFile(a, "new a", &error) == Status::kOk);
    REQUIRE(ReplaceFile(b, "new b", &error) == Status::kOk);
    REQUIRE(ReplaceFile(dir.path + "/walk.gltf", "new c", &error) == Status::kOk);
    // Written, waiting: the targets are as they were until Commit.
    CHECK(Read(a) == "old a");
    CHECK(Read(b) == "old b");
    CHECK(dir.Entries().size() == 5);
    CHECK(set.Commit().empty());
    CHECK(Read(a) == "new a");
    CHECK(Read(b) == "new b");
    CHECK(Read(dir.path + "/walk.gltf") == "new c");
    CHECK(dir.Entries().size() == 3);
    // Closed by Commit: a later write replaces at once.
    REQUIRE(ReplaceFile(a, "newer a", &error) == Status::kOk);
    CHECK(Read(a) == "newer a");
  }
  {
    // Closed without Commit (an exception, say): the old files stay, no temporary file.
    OutputFileSet set;
    REQUIRE(ReplaceFile(a, "lost a", &error) == Status::kOk);
    REQUIRE(ReplaceFile(b, "lost b", &error) == Status::kOk);
  }
  CHECK(Read(a) == "newer a");
  CHECK(Read(b) == "new b");
  CHECK(dir.Entries().size() == 3);
  {
    // A file whose directory went away before Commit is said; the others are replaced.
    const std::string sub = dir.path + "/sub";
    REQUIRE(::mkdir(sub.c_str(), 0755) == 0);
    OutputFileSet set;
    REQUIRE(ReplaceFile(sub + "/walk.json", "gone", &error) == Status::kOk);
    REQUIRE(ReplaceFile(a, "kept a", &error) == Status::kOk);
    REQUIRE(std::system(("rm -rf '" + sub + "'").c_str()) == 0);
    const std::vector<std::string> failures = set.Commit();
    REQUIRE(failures.size() == 1);
    CHECK_THAT(failures[0], Catch::Contains("cannot write '" + sub + "/walk.json'"));
    CHECK(Read(a) == "kept a");
  }
}

TEST_CASE("A signal while an output file set waits leaves every old file and no temporary one",
          "[terrain][output_file]") {
  Dir dir;
  const std::string a = dir.path + "/walk.json", b = dir.path + "/walk.glb";
  std::string error;
  REQUIRE(ReplaceFile(a, "old a", &error) == Status::kOk);
  REQUIRE(ReplaceFile(b, "old b", &error) == Status::kOk);
  // SIGINT (Ctrl-C) while the second file is written, the first waiting.
  const pid_t child = ::fork();
  if (child == 0) {
    RemoveTemporaryFileOnSignal();
    OutputFileSet set;
    std::string e;
    ReplaceFile(a, "new a", &e);
    ReplaceFile(
        b,
        [](std::FILE* f) {
          std::fputs("half", f);
          std::fflush(f);
          std::raise(SIGINT);
          return true;
        },
        &e);
    set.Commit();
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  CHECK(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGINT);
  CHECK(Read(a) == "old a");
  CHECK(Read(b) == "old b");
  CHECK(dir.Entries().size() == 2);
}
