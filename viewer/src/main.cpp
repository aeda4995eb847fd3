// footfall-view: the debug viewer of terrains, queries, walks and live servers.
#include <cerrno>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "footfall/cli/load_flags.h"
#include "footfall/cli/number_checks.h"
#include "footfall/import/terrain_loader.h"
#include "footfall/terrain/decimal_number.h"
#include "footfall/terrain/file_extension.h"
#include "footfall/terrain/output_file.h"
#include "footfall/terrain/process_start.h"
#include "footfall/version.h"
#include "footfall/viewer/viewer_app.h"

namespace {

bool ParseNumbers(const std::string& text, size_t count, std::vector<double>* out) {
  std::string spaced = text;
  for (char& c : spaced) {
    if (c == ',') c = ' ';
  }
  std::istringstream in(spaced);
  out->clear();
  for (std::string t; in >> t;) {
    double v = 0;
    // A leading '+' as --query and --up take it ("+7": from_chars reads no sign).
    if (t.size() > 1 && t[0] == '+' && t[1] != '-' && t[1] != '+') t.erase(0, 1);
    const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || ptr != t.data() + t.size() || !std::isfinite(v)) return false;
    out->push_back(v);
  }
  return out->size() == count;
}

// footfall-view's work, from its command line to its exit status.
int View(int argc, char** argv) {
  footfall::OpenClosedStandardStreams();  // no file the viewer writes may take descriptor 1 or 2
  std::signal(SIGPIPE, SIG_IGN);
  footfall::RemoveTemporaryFileOnSignal();  // an interrupted write leaves no temporary file
  footfall::viewer::ViewerOptions o;
  CLI::App app{
      "footfall-view: draws terrain samples, queries (foot, direction, cells, candidates, chosen "
      "sample), walks and the queries of a live footfalld. Keys: drag orbit, right-drag pan, "
      "wheel zoom, F frame all, W frame the walk, C colour, G grid cells, space play, left/right "
      "frame, Home/End first/last frame, Esc or Q quit."};
  app.set_version_flag("--version", "footfall-view " FOOTFALL_VERSION,
                       "Print footfall-view's version and exit");
  std::string size, camera, up;
  double frame = 0;
  app.add_option("--terrain", o.terrain, "Terrain file (.pts/.xyz/.txt or any loader format)");
  const std::vector<CLI::Option*> load_flags = footfall::cli::AddLoadFlags(&app, &o.load);
  app.add_option("--query", o.queries,
                 "A query to draw, repeatable: \"next X Y Z DX DY DZ\", \"snap X Y Z\", "
                 "\"normal X Y Z\"");
  app.add_option("--tolerance", o.tolerance,
                 "next: candidate radius around the ideal point (default: the step length)")
      ->check(footfall::cli::FiniteAtLeast(0));
  app.add_option("--walk", o.walk, "Walk JSON file from the step generator");
  app.add_option("--server", o.server, "footfalld HOST:PORT, with --live");
  app.add_flag("--live", o.live, "Draw the queries the server answers, as they arrive");
  auto* live_wait_opt =
      app.add_option("--live-wait", o.live_wait,
                     "With --live and --screenshot: wait for this many live queries before "
                     "rendering")
          ->transform(footfall::cli::WholeUpTo(1000000));
  app.add_option("--timeout", o.timeout_s, "Bound on waits for the server (s)")
      ->check(footfall::cli::FiniteRange(0.001, 1e6));
  app.add_option("--screenshot", o.screenshot, "Render one frame off screen to this PNG and exit")
      ->check(footfall::cli::NotBlank("a PNG file path"));
  app.add_option("--size", size, "Window or image size WxH (default 1280x800)");
  // Any finite frame: a walk keeps the frames it was given (past 1e9 from --start-frame 1e9);
  // one outside the walk's shows its nearest end, with a note.
  auto* frame_opt =
      app.add_option("--frame", frame, "Walk frame to show")->check(footfall::cli::Finite());
  app.add_option("--dump-state", o.dump_state,
                 "Write what is drawn (pixel positions of chosen samples and feet, live "
                 "queries) as JSON");
  app.add_flag("--height-colors", o.height_colors, "Colour samples by height, not by normal");
  app.add_flag("--cells", o.show_cells, "Draw the occupied grid cells");
  auto* up_opt =
      app.add_option("--up", up,
                     "The world axis shown up: x, y, z, -x, -y, -z or a vector along one (0,0,1); "
                     "default --up-axis when given, else y");
  auto* foot_length_opt =
      app.add_option("--foot-length", o.sole_length,
                     "Draw each foot's sole this long (world units; 0: none), at its pose and "
                     "dimmed at its footholds, turned as --foot-rotations turns feet; default: "
                     "the walk's own foot_length (a character's), where it has one")
          ->check(footfall::cli::FiniteRange(0, 1e9));
  app.add_flag("--frame-walk", o.frame_walk,
               "Frame the walk at the start (as the W key does), not everything (F); a walk on "
               "a large terrain is otherwise small in the picture");
  app.add_option("--camera", camera,
                 "Camera \"EX EY EZ TX TY TZ\": eye and target in world space, within +-1e15 "
                 "(--up up, 45 degree vertical field of view); default frames everything");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    errno = 0;                       // what the write of the text sets, not an earlier call's
    if (app.exit(e) != 0) return 2;  // a refused flag: 2, as for --size and --camera
    // --help or --version: exit 0 only when its text was written.
    return footfall::FlushStandardOutput("footfall-view") ? 0 : 1;
  }
  // (Without --live it was ignored: the screenshot was taken at once.)
  if (live_wait_opt->count() > 0 && !o.live) {
    std::cerr << "footfall-view: --live-wait needs --live (it waits for queries the --server "
                 "answers)\n";
    return 2;
  }
  if (foot_length_opt->count() > 0 && o.walk.empty()) {
    std::cerr << "footfall-view: --foot-length needs --walk (it draws the walk's feet)\n";
    return 2;
  }
  if (o.frame_walk && o.walk.empty()) {
    std::cerr << "footfall-view: --frame-walk needs --walk (it frames the walk's keys)\n";
    return 2;
  }
  if (!size.empty()) {
    // Each side digits alone ("64,48x", "x64 40" and "3 2x" were read as sizes).
    const size_t x = size.find_first_of("xX");
    // (Leading zeros dropped first, as the whole-number flags drop them: "0064" is 64.)
    const std::string width = footfall::WithoutLeadingZeros(size.substr(0, x)),
                      height = x == std::string::npos
                                   ? ""
                                   : footfall::WithoutLeadingZeros(size.substr(x + 1));
    if (x == std::string::npos || !footfall::WholeNumberProblem(width, 1, 65536).empty() ||
        !footfall::WholeNumberProblem(height, 1, 65536).empty()) {
      std::cerr << "footfall-view: --size \"" << size
                << "\": expected WIDTHxHEIGHT in whole pixels from 1 to 65536 (and within what "
                   "the OpenGL draws), e.g. 1280x800\n";
      return 2;
    }
    o.width = std::stoi(width), o.height = std::stoi(height);
  }
  if (!camera.empty()) {
    std::vector<double> v;
    if (!ParseNumbers(camera, 6, &v) || (v[0] == v[3] && v[1] == v[4] && v[2] == v[5])) {
      std::cerr << "footfall-view: --camera \"" << camera
                << "\": expected 6 finite numbers EX EY EZ TX TY TZ, eye != target\n";
      return 2;
    }
    o.has_camera = true;
    o.eye = {v[0], v[1], v[2]}, o.target = {v[3], v[4], v[5]};
  }
  // A height map stood up along --up-axis is seen standing on it too.
  if (up_opt->count() > 0) {
    std::string problem;
    if (!footfall::viewer::ParseViewUp(up, &o.up, &problem)) {
      std::cerr << "footfall-view: " << problem << '\n';
      return 2;
    }
  } else if (o.load.up_axis == 'x' || o.load.up_axis == 'z') {
    o.up = {o.load.up_axis - 'x', 1};
  }
  if (frame_opt->count() > 0) o.has_frame = true, o.frame = frame;
  // Loading flags without a terrain to load were ignored.
  if (o.terrain.empty()) {
    for (const CLI::Option* flag : load_flags) {
      if (flag->count() > 0) {
        std::cerr << "footfall-view: " << flag->get_name()
                  << " is a loading flag of --terrain FILE, and no terrain is given\n";
        return 2;
      }
    }
  }
  std::string error;
  // (The height-map frame's flags, refused by the loader later, exited 1 where the others
  // exit 2.)
  if (!o.terrain.empty() &&
      (!footfall::cli::ResamplingFlagsApply(o.terrain, o.load, &error) ||
       footfall::CheckHeightMapOnly(o.terrain, footfall::FileExtension(o.terrain), o.load,
                                    &error) != footfall::Status::kOk)) {
    std::cerr << "footfall-view: " << error << '\n';  // (they were ignored)
    return 2;
  }
  try {
    return footfall::viewer::RunViewer(o);
  } catch (const std::bad_alloc&) {
    throw;  // said by main
  } catch (const std::exception& e) {
    // A last resort, as in `footfall`: every reader reports bad input itself; whatever escapes
    // still ends in a message and exit status 1, never an abort.
    std::cerr << "footfall-view: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return View(argc, argv);
  } catch (const std::bad_alloc&) {
    // Memory ran out (its command line, a file, what it draws): said, not an abort. Ended
    // without the libraries' exit handlers: memory running out within the OpenGL driver may
    // leave it holding a lock that its own handler then waits on for ever. (Within the driver,
    // llvmpipe's compiler may also end the process itself.)
    std::fputs("footfall-view: error: out of memory; stopped\n", stderr);
    std::fflush(nullptr);
    std::_Exit(1);
  }
}
