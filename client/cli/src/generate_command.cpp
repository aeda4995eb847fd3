// `footfall generate`: places the footsteps of a character (or a crowd) on a terrain and writes
// the keyed walk as JSON, glTF (.gltf, .glb) or a Maya MEL script.
#include <sys/stat.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <new>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "commands.h"
#include "footfall/cli/number_checks.h"
#include "footfall/client/query_text.h"
#include "footfall/export/gltf_writer.h"
#include "footfall/export/mel_writer.h"
#include "footfall/export/walk_writer.h"
#include "footfall/import/terrain_loader.h"
#include "footfall/steps/foot_rotations.h"
#include "footfall/steps/generator.h"
#include "footfall/steps/linear_units.h"
#include "footfall/steps/scene.h"
#include "footfall/steps/walk_json.h"
#include "footfall/steps/walk_terrain.h"
#include "footfall/terrain/file_extension.h"
#include "footfall/terrain/large_memory.h"
#include "footfall/terrain/output_file.h"
#include "footfall/terrain/point_file.h"
#include "footfall/terrain/shown_text.h"
#include "footfall/terrain/text_stream.h"
#include "standard_streams.h"
#include "terrain_flags.h"

namespace footfall::cli {
namespace {

struct GenerateFlags {
  TerrainFlags terrain;
  std::string character;
  std::string scene;
  std::string start, heading, path, up;
  int steps = -1;
  double start_frame = 1;
  double fps = 24;
  int crowd = 1;
  double crowd_spacing = 0;
  bool progress = false;
  bool foot_rotations = false;
  std::string unit;  // the walk's linear unit (Walk::unit; "": not said)
  double scale = 1;  // the character's lengths multiplied (ScaleCharacter)
  // The character file's walk settings replaced (negative: the file's own), in the terrain's
  // units (not scaled).
  double step_length = -1, step_height = -1, foot_length = -1, foot_width = -1;
  int frames_per_step = -1;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<std::string> out;
};

// "X,Y,Z" into *out; false with a message naming the flag.
bool ParseVec(const std::string& text, const std::string& flag, Vec3* out, std::string* error) {
  std::vector<double> v;
  std::string token;
  std::istringstream in(text);
  while (std::getline(in, token, ',')) {
    double x;
    if (!ParseFiniteNumber(token, &x)) {
      *error = flag + " '" + ShownText(text) + "': '" + ShownText(token) + "'" +
               HiddenBytesNote(token) + " is not a finite number (expected X,Y,Z)";
      return false;
    }
    v.push_back(x);
  }
  if (v.size() != 3 ||
      (!text.empty() && text.back() == ',')) {  // getline drops a last, empty field
    *error =
        flag + " '" + ShownText(text) + "': expected X,Y,Z (three numbers separated by commas)";
    return false;
  }
  *out = {v[0], v[1], v[2]};
  return true;
}

// "DX,DY,DZ" of non-zero length into *out; false with a message naming the flag (before any
// terrain is read).
bool ParseDirection(const std::string& text, const std::string& flag, Vec3* out,
                    std::string* error) {
  if (!ParseVec(text, flag, out, error)) return false;
  if (SafeNormalize(*out) == Vec3{}) {
    *error = flag + " '" + text + "': expected a direction DX,DY,DZ of non-zero length";
    return false;
  }
  return true;
}

// `--out -`: the walk JSON on standard output.
const std::string kStandardOutput = "-";

// Writes the walk JSON to standard output, as it is built. False with a message on failure
// (a closed pipe, a full disk).
bool WriteWalkJsonToStandardOutput(const Walk& walk, std::string* error) {
  const bool written = EmitWalkJson(walk, [](std::string_view piece) {
    std::cout.write(piece.data(), static_cast<std::streamsize>(piece.size()));
    return static_cast<bool>(std::cout);
  });
  std::cout.flush();
  if (written && std::cout) return true;
  const int why = StandardOutputError();
  *error = std::string("--out -: cannot write the walk JSON to standard output") +
           (why ? std::string(": ") + std::strerror(why) : std::string());
  return false;
}

// Writes one output, chosen by its extension.
Status WriteOutput(const Walk& walk, const std::string& path, const WalkExportOptions& options,
                   std::string* error) {
  const std::string ext = FileExtension(path);
  if (ext == "json") return WriteWalkJson(walk, path, error);
  if (IsWalkExportPath(path)) return WriteWalk(walk, path, options, error);
  *error = path + ": unsupported output extension (expected .json, .gltf, .glb or .mel)";
  return Status::kInvalidArgument;
}

// A one-line progress bar on stderr, redrawn at most 10 times a second.
class ProgressBar {
 public:
  void Update(int done, int total) {
    const auto now = std::chrono::steady_clock::now();
    if (done < total && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const int width = 40;
    const int filled =
        total > 0 ? static_cast<int>(static_cast<double>(done) * width / total) : width;
    const int percent = total > 0 ? static_cast<int>(100.0 * done / total) : 100;
    std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, '.') << "] "
              << std::setw(3) << percent << '%' << std::flush;
    open_ = true;
  }
  // Ends the bar's line, so that a message written now has a line of its own (the bar is drawn
  // again below it at its next update).
  void Break() {
    if (open_) std::cerr << '\n';
    open_ = false;
  }
  void Finish() { Break(); }

 private:
  std::chrono::steady_clock::time_point last_{};
  bool open_ = false;  // the bar is drawn and its line not ended
};

// One bar for a scene's characters, walked one after the other or at once: the mean of their
// shares done. Update may be called from several threads.
class SceneProgress {
 public:
  explicit SceneProgress(size_t characters) : shares_(characters, 0.0) {}
  void Update(size_t character, int done, int total) {
    std::lock_guard<std::mutex> lock(mutex_);
    shares_[character] = total > 0 ? static_cast<double>(done) / total : 1.0;
    double sum = 0;
    for (double s : shares_) sum += s;
    constexpr int kScale = 1000;
    bar_.Update(static_cast<int>(sum / static_cast<double>(shares_.size()) * kScale), kScale);
  }
  void Break() {
    std::lock_guard<std::mutex> lock(mutex_);
    bar_.Break();
  }
  void Finish() { bar_.Finish(); }

 private:
  std::mutex mutex_;
  std::vector<double> shares_;
  ProgressBar bar_;
};

// Draws `bar` as the walk advances when asked (--progress), or for a long run on a terminal.
void ShowProgress(const GenerateFlags& flags, ProgressBar* bar, GenerateOptions* options) {
  const long long steps = options->steps < 0 ? kDefaultSteps : options->steps;
  const bool long_run = static_cast<long long>(options->crowd) * steps >= 20000;
  if (flags.progress || (long_run && isatty(STDERR_FILENO)))
    options->progress = [bar](int done, int total) { bar->Update(done, total); };
}

// True when the terrain is read here, not as a point file, with no --separation: it is then
// resampled for the character (walk_terrain.h; an unknown extension fails there).
bool ResamplesForCharacter(const TerrainFlags& flags) {
  return !flags.terrain.empty() && !(flags.load.separation > 0) &&
         !IsPointFileExtension(FileExtension(flags.terrain));
}

std::string Box(const Vec3& lo, const Vec3& hi) {
  TextStream o;
  o.precision(4);
  o << "(" << lo.x << ", " << lo.y << ", " << lo.z << ") to (" << hi.x << ", " << hi.y << ", "
    << hi.z << ")";
  return o.str();
}

// Says on stderr how the terrain was resampled for the character, when not at its own spacing.
void ReportResampling(const std::string& path, const Character& character, const WalkTerrain& t) {
  const TerrainLoadReport& r = t.report;
  for (const std::string& note :
       {DescribeSkippedFaces(r), DescribeTurnover(r), DescribeSteepHeightMap(r)})
    if (!note.empty()) std::cerr << "footfall generate: " << path << ": " << note << '\n';
  if (!t.cropped && r.separation == r.file_separation) return;
  TextStream o;
  o.precision(4);
  o << "footfall generate: " << path << " resampled for " << character.name
    << " at a separation of " << r.separation << " (its own spacing " << r.file_separation
    << ", a quarter of the step " << t.wanted_separation << ")";
  if (t.cropped) o << " within " << Box(t.region_min, t.region_max);
  o << ": " << r.samples << " samples; --separation S resamples "
    << (t.cropped ? "all of it" : "it") << " at S\n";
  const std::string coarser = CoarserThanStepsNote(r, t.wanted_separation);
  if (!coarser.empty()) {
    o << "footfall generate: " << coarser << " and stop; "
      << (t.region_is_bound ? "give fewer --steps" : "give --steps, or waypoints nearer the start,")
      << " or set --separation\n";
  }
  std::cerr << o.str();
}

// Writes the samples the walk was placed on as a point file at `out`: `resampled` when the
// terrain was resampled for the character, else the --terrain file read again with its flags
// (its samples are then exactly those the session loaded).
Status WriteWalkTerrain(const TerrainFlags& flags, const RawSamples* resampled,
                        const std::string& out, std::string* error) {
  if (resampled) return WritePointFile(out, *resampled, error);
  RawSamples samples;
  const Status read = LoadTerrain(flags.terrain, flags.load, &samples, error);
  if (read != Status::kOk) return read;
  return WritePointFile(out, samples, error);
}

// Reads the flags that shape the walk into *options; false with a message naming the flag.
bool ReadOptions(const GenerateFlags& flags, GenerateOptions* options, std::string* error) {
  if (!flags.start.empty()) {
    if (!ParseVec(flags.start, "--start", &options->start, error)) return false;
    options->has_start = true;
    // Before the terrain is resampled around it (a start of 1e155 was "no samples").
    if (!WithinQueryReach(options->start)) {
      *error =
          "the start (--start) is too far from the terrain to snap (queries reach 1e15 from "
          "it)";
      return false;
    }
  }
  if (!flags.heading.empty() &&
      !ParseDirection(flags.heading, "--heading", &options->heading, error))
    return false;
  if (!flags.up.empty() && !ParseDirection(flags.up, "--up", &options->up, error)) return false;
  std::istringstream in(flags.path);
  for (std::string point; in >> point;) {
    Vec3 p;
    if (!ParseVec(point, "--path", &p, error)) {
      // "20, 0, 25" splits into three waypoints at its spaces: say so, not only that '20,' is
      // not X,Y,Z.
      if (flags.path.find(", ") != std::string::npos || flags.path.find(" ,") != std::string::npos)
        *error += "; write each waypoint X,Y,Z without spaces (spaces separate the waypoints)";
      return false;
    }
    options->path.push_back(p);
  }
  options->steps = flags.steps;
  options->start_frame = flags.start_frame;
  options->fps = flags.fps;
  options->crowd = flags.crowd;
  options->crowd_spacing = flags.crowd_spacing;
  options->threads = flags.threads;
  return true;
}

// Checks every --out before anything is generated: its extension, that it can be written, and
// that it is neither another output nor an input. False with a message naming the output.
bool CheckOutputs(const GenerateFlags& flags, const std::vector<std::string>& inputs,
                  std::string* error) {
  if (std::count(flags.out.begin(), flags.out.end(), kStandardOutput) > 1) {
    *error = "--out - is given twice; standard output takes the walk JSON once";
    return false;
  }
  for (const std::string& out : flags.out) {
    if (out == kStandardOutput) continue;
    const std::string ext = FileExtension(out);
    if (ext != "json" && ext != "gltf" && ext != "glb" && ext != "mel" &&
        !IsPointFileExtension(ext)) {
      *error = "--out " + out +
               ": unsupported output extension (expected .json, .gltf, .glb, .mel, or .pts for "
               "the terrain's samples)";
      return false;
    }
    // The samples of a --server-terrain are footfalld's: this side never has them.
    if (IsPointFileExtension(ext) && !flags.terrain.server_terrain.empty()) {
      *error = "--out " + out +
               ": the terrain is read by footfalld (--server-terrain), so its samples are not "
               "here to write; give the file with --terrain, or convert it with footfall "
               "terrain convert";
      return false;
    }
    // Refused before anything is generated or written (glTF times are >= 0). A scene's
    // characters are checked each (RunScene): --start-frame is only the default of those that
    // give none.
    if ((ext == "gltf" || ext == "glb") && flags.start_frame < 0 && flags.scene.empty()) {
      TextStream m;
      m << "--out " << out << ": glTF animation times must be >= 0, and --start-frame is "
        << flags.start_frame << "; start at frame 0 or later, or write .json or .mel only";
      *error = m.str();
      return false;
    }
    // Two outputs naming one file (the same path, or links to one file) would overwrite each
    // other: the last written would win, silently.
    for (const std::string& other : flags.out) {
      if (&other == &out) break;
      if (other != kStandardOutput && SameFile(out, other)) {
        *error = "--out " + other + " and --out " + out +
                 " are the same file; give each output its own file";
        return false;
      }
    }
    // An output that cannot be written is said now, not after a long walk.
    std::string unwritable;
    if (CheckWritable(out, &unwritable) != Status::kOk) {
      *error = "--out " + out + ": " + unwritable;
      return false;
    }
    // Never write over what the walk is made from.
    for (const std::string& input : inputs) {
      if (!input.empty() && SameFile(out, input)) {
        *error = "--out " + out + " is the " +
                 (&input == &inputs.front() ? "terrain"
                  : &input == &inputs[1]    ? (flags.scene.empty() ? "character" : "scene")
                                            : "character") +
                 " file this walk reads; choose another output name";
        return false;
      }
    }
  }
  return true;
}

// Loads --character, with the walk settings given as flags (--step-length, --step-height,
// --frames-per-step, --foot-length, --foot-width, each checked against the character file's range
// as it was read) in place of the file's. False with the loader's message.
bool LoadCharacterWithFlags(const GenerateFlags& flags, Character* c, std::string* error) {
  if (LoadCharacter(flags.character, c, error) != Status::kOk) return false;
  if (flags.scale != 1 && ScaleCharacter(flags.scale, c, error) != Status::kOk) {
    *error = "--scale: " + flags.character + ": " + *error;
    return false;
  }
  if (flags.step_length > 0) c->step_length = flags.step_length;
  if (flags.step_height > 0) c->step_height = flags.step_height;
  if (flags.frames_per_step > 0) c->frames_per_step = flags.frames_per_step;
  if (flags.foot_length >= 0) c->foot_length = flags.foot_length;
  if (flags.foot_width >= 0) c->foot_width = flags.foot_width;
  // Point feet have no width: --foot-length 0 takes the file's width away too.
  if (flags.foot_length == 0 && flags.foot_width < 0) c->foot_width = 0;
  if (c->foot_width > 0 && !(c->foot_length > 0)) {
    *error = "--foot-width: " + NumberText(c->foot_width) +
             " needs a foot length above 0 (--foot-length, or the character file's "
             "'foot_length')";
    return false;
  }
  return true;
}

// The terrain a walk is generated on, loaded in its session.
struct LoadedTerrain {
  TerrainFlags flags;  // the command's, with its thread count
  std::unique_ptr<TerrainSession> session;
  TerrainHandle handle = 0;
  bool resampled = false;  // resampled here for the character: `prepared` holds it
  WalkTerrain prepared;
};

// Opens the session and loads the terrain for `character`: a mesh or height map without
// --separation resampled here for it (and, without --start, the start found on its surface),
// else the file as the flags say (footfalld resampling a --server-terrain as fine as the
// character needs). On failure returns false with a message.
bool LoadWalkTerrain(const GenerateFlags& flags, const Character& character,
                     GenerateOptions* options, LoadedTerrain* t, std::string* error) {
  t->flags = flags.terrain;
  t->flags.threads = flags.threads;
  TerrainFlags& terrain_flags = t->flags;
  // Before a mesh is resampled for the character (--server-terrain beside a mesh --terrain was
  // ignored, and a bad --server said only after the resampling).
  if (CheckTerrainFlags(terrain_flags, error) != Status::kOk) return false;
  t->resampled = ResamplesForCharacter(terrain_flags);
  if (t->resampled) {
    if (PrepareWalkTerrain(terrain_flags.terrain, terrain_flags.load, character, *options,
                           &t->prepared, error) != Status::kOk)
      return false;
    ReportResampling(terrain_flags.terrain, character, t->prepared);
    // The default start, found on the surface before cropping (a --start is snapped as given);
    // it may still move to where the character can stand, within the crop.
    if (!options->has_start) {
      options->start = t->prepared.start, options->has_start = true;
      options->start_may_move = true;
    }
    if (OpenSession(terrain_flags, &t->session, error) != Status::kOk) return false;
    if (t->session->LoadSamples(t->prepared.samples, terrain_flags.terrain, &t->handle) !=
        Status::kOk) {
      *error = t->session->last_error();
      return false;
    }
    return true;
  }
  // A file footfalld reads: the whole of it, as fine as the character needs within the samples
  // a walk's terrain may have (and the server's budget), when no separation is given.
  if (!terrain_flags.server_terrain.empty() && !(terrain_flags.load.separation > 0)) {
    terrain_flags.load.finest_default = kSeparationPerStep * character.step_length;
    terrain_flags.load.max_samples = std::min(terrain_flags.load.max_samples, kMaxWalkSamples);
  }
  if (OpenTerrain(terrain_flags, &t->session, &t->handle, error) != Status::kOk) return false;
  // A mesh read here at --separation: faces left out or turned over are said, as when it is
  // resampled for the character.
  if (!terrain_flags.terrain.empty()) {
    const TerrainLoadReport& r = t->session->last_file_report();
    for (const std::string& note :
         {DescribeSkippedFaces(r), DescribeTurnover(r), DescribeSteepHeightMap(r)})
      if (!note.empty())
        std::cerr << "footfall generate: " << terrain_flags.terrain << ": " << note << '\n';
  }
  // footfalld resampled a mesh or height map itself: say how, as a local file's resampling is
  // reported.
  if (!terrain_flags.server_terrain.empty() &&
      !IsPointFileExtension(FileExtension(terrain_flags.server_terrain)) &&
      !t->session->last_load_report().empty())
    std::cerr << "footfall generate: footfalld " << t->session->last_load_report() << "\n";
  return true;
}

// [Units: bytes] About what one key of a walk takes: its frame, phase, position and normal, and a
// body key's rotation shared out over the keys.
constexpr double kBytesPerKey = 68;

// About how many keys `crowd` characters walking `steps` steps make: per character and step,
// the start, mid and end keys of a gait group's feet, and a body key.
double EstimateKeys(double crowd, double steps, const Character& character) {
  return crowd * steps *
         (3.0 * static_cast<double>(character.feet.size()) /
              static_cast<double>(character.gait.size()) +
          1);
}

// Refuses, before the terrain is loaded, a walk whose keys alone need more memory than this
// process may use (`what` names it): without an address-space limit, a crowd of a million
// characters x a million steps grew for minutes until the system stopped it.
bool CheckKeyMemory(double keys, const std::string& what, std::string* error) {
  const double memory = UsableMemoryBytes();
  if (!(memory > 0) || keys * kBytesPerKey <= memory) return true;
  TextStream m;
  m.precision(3);
  m << what << " make about " << keys << " keys, " << keys * kBytesPerKey / 1e9
    << " GB, more than the " << memory / 1e9
    << " GB of memory this process may use; nothing was generated (give fewer "
    << "characters, crowds or steps)";
  *error = m.str();
  return false;
}

// What running out of memory while generating says: about how many keys the walk needed.
std::string OutOfMemoryMessage(const GenerateFlags& flags, const GenerateOptions& options,
                               const Character& character) {
  const double steps = flags.steps < 0 ? kMaxPathSteps : flags.steps;
  const double keys = EstimateKeys(flags.crowd, steps, character);
  TextStream m;
  m.precision(3);
  const bool capped = flags.steps < 0 && !options.path.empty();
  m << "out of memory generating " << flags.crowd
    << (flags.crowd == 1 ? " character" : " characters") << " x " << (capped ? "up to " : "")
    << steps << " steps: " << (capped ? "up to " : "") << "about " << keys << " keys, "
    << keys * kBytesPerKey / 1e9 << " GB; nothing was written (give fewer --crowd or --steps)";
  return m.str();
}

// --foot-rotations: gives the walk's feet their orientations, which the walk JSON then carries
// (the glTF and MEL writers key the same ones). Memory running out keeps the walk as it was,
// its JSON without them, and says so.
void AddFootRotationsIfAsked(const GenerateFlags& flags, Walk* walk) {
  if (!flags.foot_rotations) return;
  try {
    AddFootRotations(walk);
  } catch (const std::bad_alloc&) {
    for (WalkTrack& t : walk->tracks)
      if (t.kind == TrackKind::kFoot)
        t.rotations = std::pmr::vector<Quat>(t.rotations.get_allocator());
    std::cerr << "footfall generate: warning: out of memory giving the feet their rotations: the "
                 "walk JSON is written without them (glTF and MEL still key them)\n";
  }
}

// Writes every --out, each on its own: one that fails is said (and an older file of its name
// said to be left as it was) and the others are still written. They replace older files of
// their names together, once all are written (OutputFileSet): Ctrl-C while they are written
// leaves the older files, never a mix. The walk is given its unit (--unit) first. Returns 1 if
// any failed, else 0.
int WriteOutputs(const GenerateFlags& flags, const LoadedTerrain& terrain, Walk& walk) {
  walk.unit = flags.unit;
  WalkExportOptions exports;
  exports.foot_rotations = flags.foot_rotations;
  int code = 0;
  std::string error;
  OutputFileSet outputs;
  // glTF first: its model is built whole, checked against the memory free then, and writing
  // JSON or MEL on several threads leaves the allocator's per-thread pools counted as used
  // (a glTF given after a .json was refused where one given before it was written).
  std::vector<std::string> order;
  for (const bool gltf : {true, false}) {
    for (const std::string& out : flags.out) {
      const std::string ext = FileExtension(out);
      if ((ext == "gltf" || ext == "glb") == gltf) order.push_back(out);
    }
  }
  for (const std::string& out : order) {
    if (out == kStandardOutput) continue;  // after the files (below)
    const std::string ext = FileExtension(out);
    Status written;
    try {
      written = IsPointFileExtension(ext)
                    ? WriteWalkTerrain(terrain.flags,
                                       terrain.resampled ? &terrain.prepared.samples : nullptr, out,
                                       &error)
                    : WriteOutput(walk, out, exports, &error);
    } catch (const std::bad_alloc&) {
      error =
          "out of memory writing it (the outputs before it are written; the walk JSON "
          "takes least)";
      written = Status::kLimitExceeded;
    }
    if (written == Status::kOk && (ext == "gltf" || ext == "glb")) {
      // Said of a glTF written (one refused says why it is). Keys are stored relative to the
      // walk's origin (GltfOrigin): only a walk spanning kilometres moves visibly.
      const double rounding = MaxFloatRounding(walk);
      if (rounding > 1e-4) {
        std::cerr << "footfall generate: warning: " << out
                  << ": glTF stores positions as floats, and at these coordinates keys move by "
                     "up to "
                  << rounding << " (JSON and MEL keep full precision)\n";
      }
      const double late = MaxTimeRounding(walk);
      if (late > 0.01) {
        std::cerr << "footfall generate: warning: " << out
                  << ": glTF stores times as float seconds, and at these frames keys move by up "
                     "to "
                  << late << " frames (JSON and MEL keep the frames exact)\n";
      }
    }
    if (written != Status::kOk) {
      // Named by its output (the other outputs are still written).
      const bool named = error.compare(0, out.size(), out) == 0;
      std::cerr << "footfall generate: " << (named ? "" : "--out " + out + ": ") << error << '\n';
      // A file of that name from before stays as it was: say so, as it no longer matches the
      // other outputs, if there are any.
      struct stat st;
      if (::stat(out.c_str(), &st) == 0 && S_ISREG(st.st_mode)) {
        std::cerr << "footfall generate: " << out << " is left as it was, from before this walk"
                  << (flags.out.size() > 1 ? " (it does not match the other outputs)" : "") << '\n';
      }
      code = 1;
    }
  }
  for (const std::string& failure : outputs.Commit()) {
    std::cerr << "footfall generate: " << failure << " (the other outputs are written)\n";
    code = 1;
  }
  // Standard output last: a reader that stops early (`| head`) costs no file.
  if (std::count(flags.out.begin(), flags.out.end(), kStandardOutput) > 0 &&
      !WriteWalkJsonToStandardOutput(walk, &error)) {
    std::cerr << "footfall generate: " << error << '\n';
    code = 1;
  }
  return code;
}

// Says on stderr what is worth knowing of a finished walk: path walks short of their goals, and
// why the walk stopped early (every character's reason, up to a screenful; of a scene, with
// `scene_names` its characters' names, the first reason of each of them beyond that too: a
// biped stopped after a crowd of 25 went unnamed). True if it stopped.
bool ReportWalkEnd(const Walk& walk, const LoadedTerrain& terrain,
                   const std::vector<std::string>& scene_names = {}) {
  constexpr size_t kMaxNotes = 20;
  for (size_t i = 0; i < walk.notes.size() && i < kMaxNotes; ++i)
    std::cerr << "footfall generate: note: " << walk.notes[i] << '\n';
  if (walk.notes.size() > kMaxNotes)
    std::cerr << "footfall generate: note: ... and " << walk.notes.size() - kMaxNotes
              << " more notes\n";
  if (walk.stopped.empty()) return false;
  std::cerr << "footfall generate: stopped early: " << walk.stopped << '\n';
  if (walk.session_failed)
    std::cerr << "footfall generate: footfalld failed mid-walk (not the terrain): the keys up to "
                 "its failure are written; exit status 1\n";
  constexpr size_t kMaxListed = 20;
  if (walk.stops.size() > 1) {
    std::vector<bool> listed(walk.stops.size());
    for (size_t i = 0; i < walk.stops.size() && i < kMaxListed; ++i) listed[i] = true;
    for (const std::string& name : scene_names) {
      const std::string prefix = name + ": ";
      for (size_t i = 0; i < walk.stops.size(); ++i) {
        if (walk.stops[i].compare(0, prefix.size(), prefix) != 0) continue;
        listed[i] = true;
        break;
      }
    }
    size_t more = 0;
    for (size_t i = 0; i < walk.stops.size(); ++i) {
      if (listed[i])
        std::cerr << "  " << walk.stops[i] << '\n';
      else
        ++more;
    }
    if (more > 0) std::cerr << "  ... and " << more << " more\n";
  }
  const WalkTerrain& prepared = terrain.prepared;
  if (terrain.resampled && prepared.cropped && !prepared.region_is_bound) {
    std::cerr << "footfall generate: the terrain was resampled only within "
              << Box(prepared.region_min, prepared.region_max)
              << ", around the path; a stop at its edge is that edge: give --steps or "
                 "--separation\n";
  }
  return true;
}

// `footfall generate --scene`: every character of the scene file walked on the terrain
// (loaded once, or resampled for each character that needs it), their walks written as one.
int RunScene(const GenerateFlags& flags) {
  std::string error;
  GenerateOptions base;
  std::vector<SceneCharacter> scene;
  if (!ReadOptions(flags, &base, &error) || LoadScene(flags.scene, &scene, &error) != Status::kOk) {
    std::cerr << "footfall generate: " << error << '\n';
    return 1;
  }
  std::vector<std::string> inputs = {flags.terrain.terrain, flags.scene};
  for (const SceneCharacter& c : scene) inputs.push_back(c.character_file);
  const bool per_character = ResamplesForCharacter(flags.terrain);
  for (const std::string& out : flags.out) {
    const std::string ext = FileExtension(out);
    if (IsPointFileExtension(ext) && per_character) {
      error = "--out " + out +
              ": with --scene, a mesh or height map is resampled for each character; give "
              "--separation (or a point file) to write the terrain's samples";
      break;
    }
    for (const SceneCharacter& c : scene) {
      const double start = c.has_start_frame ? c.options.start_frame : flags.start_frame;
      if ((ext == "gltf" || ext == "glb") && start < 0 && error.empty())
        error = "--out " + out + ": glTF animation times must be >= 0, and " + c.name +
                " starts at frame " + NumberText(start) +
                (c.has_start_frame ? "" : " (--start-frame)") + "; write .json or .mel";
    }
  }
  double keys = 0;  // of the characters whose steps are given (the others' are only a bound)
  for (const SceneCharacter& c : scene)
    if (c.options.steps >= 0) keys += EstimateKeys(c.options.crowd, c.options.steps, c.character);
  if (!error.empty() || !CheckOutputs(flags, inputs, &error) ||
      !CheckKeyMemory(keys, "the scene's characters", &error)) {
    std::cerr << "footfall generate: " << error << '\n';
    return 1;
  }
  // A terrain read as it is (a point file, a --separation, footfalld's file) is loaded once, as
  // fine as the character with the shortest step needs.
  LoadedTerrain shared;
  if (!per_character) {
    const SceneCharacter* finest = &scene.front();
    for (const SceneCharacter& c : scene)
      if (c.character.step_length < finest->character.step_length) finest = &c;
    GenerateOptions options = base;
    if (!LoadWalkTerrain(flags, finest->character, &options, &shared, &error)) {
      std::cerr << "footfall generate: " << error << '\n';
      return 1;
    }
  }
  std::vector<const Character*> characters;
  std::vector<GenerateOptions> options;
  long long work = 0;  // characters times steps, for the progress bar
  for (const SceneCharacter& c : scene) {
    characters.push_back(&c.character);
    GenerateOptions o = c.options;
    o.fps = flags.fps;
    o.threads = flags.threads;
    if (!c.has_up) o.up = base.up, o.names.up = base.names.up;
    if (!c.has_start_frame) o.start_frame = flags.start_frame;
    work += static_cast<long long>(o.crowd) * (o.steps < 0 ? kDefaultSteps : o.steps);
    options.push_back(std::move(o));
  }
  SceneProgress progress(scene.size());
  if (flags.progress || (work >= 20000 && isatty(STDERR_FILENO))) {
    for (size_t i = 0; i < options.size(); ++i)
      options[i].progress = [&progress, i](int done, int total) {
        progress.Update(i, done, total);
      };
  }
  // The characters walk on the shared terrain together (over footfalld, their queries joined
  // into one call per round), or one after the other, each on the terrain resampled for it.
  // A character that fails leaves the others walking: their walks are written.
  std::vector<SceneWalk> walks;
  try {
    if (!per_character) {
      GenerateSceneWalks(*shared.session, shared.handle, characters, options, &walks);
    } else {
      walks.resize(scene.size());
      for (size_t i = 0; i < scene.size(); ++i) {
        LoadedTerrain own;
        progress.Break();  // (the resampling's message was written after the bar's "25%")
        if (!LoadWalkTerrain(flags, scene[i].character, &options[i], &own, &error)) {
          walks[i].walked = true, walks[i].status = Status::kInvalidArgument;
          walks[i].error = error;
          continue;
        }
        std::vector<SceneWalk> one;
        GenerateSceneWalks(*own.session, own.handle, {characters[i]}, {options[i]}, &one);
        walks[i] = std::move(one.front());
        if (walks[i].out_of_memory) break;
      }
    }
  } catch (const std::bad_alloc&) {
    walks.clear();
  }
  progress.Finish();
  // Characters started on top of each other, said (read before the walks move into the scene's).
  std::vector<std::string> names;
  std::vector<const Walk*> walked_walks;
  std::vector<double> reaches;
  for (size_t i = 0; i < walks.size(); ++i) {
    names.push_back(scene[i].name);
    const bool ok = walks[i].walked && walks[i].status == Status::kOk;
    walked_walks.push_back(ok ? &walks[i].walk : nullptr);
    reaches.push_back(scene[i].character.reach);
  }
  const std::vector<std::string> overlapping = OverlappingStartNotes(names, walked_walks, reaches);
  Walk walk;
  walk.fps = flags.fps;
  size_t walked = 0;
  std::vector<std::pair<std::string, std::string>> failures;  // (character, reason)
  for (size_t i = 0; i < walks.size(); ++i) {
    SceneWalk& w = walks[i];
    if (w.out_of_memory) {
      std::cerr << "footfall generate: " << scene[i].name << ": out of memory generating its walk; "
                << "nothing was written (give fewer characters, crowds or steps)\n";
      return 1;
    }
    if (!w.walked) continue;
    if (w.status != Status::kOk) {
      failures.emplace_back(scene[i].name, w.error);
      continue;
    }
    try {
      AddToSceneWalk(scene[i].name, std::move(w.walk), &walk);
    } catch (const std::bad_alloc&) {
      std::cerr << "footfall generate: " << scene[i].name << ": out of memory generating its walk; "
                << "nothing was written (give fewer characters, crowds or steps)\n";
      return 1;
    }
    ++walked;
  }
  walk.notes.insert(walk.notes.end(), overlapping.begin(), overlapping.end());
  AddFootRotationsIfAsked(flags, &walk);
  if (walks.empty() && failures.empty()) {
    std::cerr << "footfall generate: out of memory setting out the scene's walks; nothing was "
                 "written (give fewer characters, crowds or steps)\n";
    return 1;
  }
  if (!failures.empty()) {
    // The characters that walked are kept: written, with who did not walk among the stops,
    // then the failures said.
    // The first 20 (footfalld dying mid-scene failed each character not yet walked: 5,584
    // lines of one reason in a scene of 10,000).
    constexpr size_t kMaxFailuresListed = 20;
    for (size_t i = 0; i < failures.size() && i < kMaxFailuresListed; ++i)
      std::cerr << "footfall generate: " << failures[i].first << ": " << failures[i].second << '\n';
    if (failures.size() > kMaxFailuresListed)
      std::cerr << "footfall generate: ... and " << failures.size() - kMaxFailuresListed
                << " more characters did not walk\n";
    if (!walk.tracks.empty()) {
      ReportWalkEnd(walk, LoadedTerrain{}, names);  // the others' notes and stops
      std::cerr << "footfall generate: the walks of the " << walked
                << (walked == 1 ? " character that walked are" : " characters that walked are")
                << " written\n";
      AddFailuresToSceneWalk(failures, &walk);
      WriteOutputs(flags, shared, walk);
    }
    return 1;
  }
  const int written = WriteOutputs(flags, shared, walk);
  const bool stopped = ReportWalkEnd(walk, LoadedTerrain{}, names);
  return written != 0 ? written : walk.session_failed ? 1 : stopped ? 2 : 0;
}

int RunGenerate(const GenerateFlags& flags) {
  if (!flags.scene.empty()) return RunScene(flags);
  if (flags.character.empty()) {
    std::cerr << "footfall generate: give --character FILE (one character, or a crowd of it) or "
                 "--scene FILE (several)\n";
    return 1;
  }
  std::string error;
  GenerateOptions options;
  Character character;
  LoadedTerrain terrain;
  // Flags first, so a typo fails before the terrain loads.
  if (!ReadOptions(flags, &options, &error) ||
      !CheckOutputs(flags, {flags.terrain.terrain, flags.character}, &error) ||
      !LoadCharacterWithFlags(flags, &character, &error) ||
      (flags.steps >= 0 &&
       !CheckKeyMemory(EstimateKeys(flags.crowd, flags.steps, character),
                       std::to_string(flags.crowd) +
                           (flags.crowd == 1 ? " character x " : " characters x ") +
                           std::to_string(flags.steps) + " steps",
                       &error)) ||
      !LoadWalkTerrain(flags, character, &options, &terrain, &error)) {
    std::cerr << "footfall generate: " << error << '\n';
    return 1;
  }
  // (A heading given with a path was dropped without a word; a crowd's grid still turns by it.)
  if (!flags.heading.empty() && !options.path.empty() && options.crowd <= 1)
    std::cerr << "footfall generate: note: --heading is not used with --path: the character "
                 "starts facing its first waypoint\n";
  ProgressBar bar;
  ShowProgress(flags, &bar, &options);
  Walk walk;
  Status status;
  try {
    status = GenerateWalk(*terrain.session, terrain.handle, character, options, &walk, &error);
  } catch (const std::bad_alloc&) {
    bar.Finish();
    // The message is made before anything is written: memory may run out making it too.
    std::string message = "out of memory generating the walk; nothing was written";
    try {
      message = OutOfMemoryMessage(flags, options, character);
    } catch (const std::bad_alloc&) {
    }
    std::cerr << "footfall generate: " << message << '\n';
    return 1;
  }
  bar.Finish();
  if (status != Status::kOk) {
    std::cerr << "footfall generate: " << error << '\n';
    return 1;
  }
  if (!options.path.empty() && options.steps != 0 && walk.stopped.empty() && !walk.tracks.empty() &&
      std::all_of(walk.tracks.begin(), walk.tracks.end(),
                  [](const WalkTrack& t) { return t.keys.size() <= 1; })) {
    std::cerr << "footfall generate: note: no steps: the path's goal is already reached where "
                 "the character starts (a waypoint counts as reached within half a step along "
                 "the ground, whatever its height above it)\n";
  }
  AddFootRotationsIfAsked(flags, &walk);
  const int code = WriteOutputs(flags, terrain, walk);
  const bool stopped = ReportWalkEnd(walk, terrain);
  // An output not written, or footfalld failing mid-walk, is an error before a stop.
  return code != 0 ? code : walk.session_failed ? 1 : stopped ? 2 : 0;
}

}  // namespace

void AddGenerateCommand(CLI::App& app, int* exit_code) {
  auto flags = std::make_shared<GenerateFlags>();
  CLI::App* cmd = app.add_subcommand(
      "generate",
      "Place every footstep of a character on a terrain and key the walk (foot IK targets and "
      "body) into JSON, glTF or MEL files");
  AddTerrainFlags(cmd, &flags->terrain);
  CLI::Option* character =
      cmd->add_option("--character", flags->character, "Character file (JSON, see the README)");
  CLI::Option* scene = cmd->add_option(
      "--scene", flags->scene,
      "Scene file (JSON, see the README): several characters, each with its own character "
      "file, start, heading, path, steps and crowd, walked on the terrain into one walk");
  scene->excludes(character);
  CLI::Option* start =
      cmd->add_option("--start", flags->start,
                      "X,Y,Z where the character starts (default: the sample nearest the centre of "
                      "the top of the terrain's bounds, or the nearest place within 12 steps where "
                      "the character can stand)")
          ->check(NotBlank("X,Y,Z"));
  CLI::Option* heading =
      cmd->add_option("--heading", flags->heading,
                      "DX,DY,DZ facing direction, projected onto the ground (default 0,0,1)")
          ->check(NotBlank("DX,DY,DZ"));
  CLI::Option* path_opt =
      cmd->add_option("--path", flags->path,
                      "Waypoints \"X,Y,Z X,Y,Z ...\" to follow (one point: a goal); the walk ends "
                      "at the last one")
          ->check(NotBlank("at least one waypoint X,Y,Z"));
  CLI::Option* steps =
      cmd->add_option("--steps", flags->steps,
                      "Steps per character, one gait group each (default 8; with --path, until "
                      "the goal)")
          ->transform(WholeUpTo(1000000));
  CLI::Option* scale =
      cmd->add_option("--scale", flags->scale,
                      "Multiply the character's lengths (its feet's rests, step length and "
                      "height, body height, max_rise, reach, foot length and width) by this: 100 "
                      "walks a "
                      "character file in metres on a terrain in centimetres (default 1)")
          ->check(FiniteRange(kMinCharacterScale, kMaxCharacterScale));
  // The character file's walk settings, as the plugins' panels override them (the ranges are
  // the character file's): --step-length replaces step_length, and so on, in the terrain's
  // units (after --scale).
  auto setting = [cmd](const std::string& flag, auto* value, const std::string& what) {
    std::string field = flag.substr(2);
    std::replace(field.begin(), field.end(), '-', '_');
    return cmd->add_option(flag, *value, what + ", in place of the character file's " + field);
  };
  CLI::Option* step_length =
      setting("--step-length", &flags->step_length, "Distance a foot travels in a step")
          ->check(FiniteAboveUpTo(0, 1e9));
  CLI::Option* step_height = setting("--step-height", &flags->step_height, "Swing arc height")
                                 ->check(FiniteAboveUpTo(0, 1e9));
  CLI::Option* frames_per_step =
      setting("--frames-per-step", &flags->frames_per_step, "Frames from lift-off to touch-down")
          ->transform(WholeRange(2, 1000000));
  CLI::Option* foot_length =
      setting("--foot-length", &flags->foot_length, "Length of each foot's sole (0: point feet)")
          ->check(FiniteRange(0, 1e9));
  CLI::Option* foot_width = setting("--foot-width", &flags->foot_width,
                                    "Width of each foot's sole (0: none; needs a foot length)")
                                ->check(FiniteRange(0, 1e9));
  cmd->add_option("--start-frame", flags->start_frame, "Frame of the first keys (default 1)")
      ->check(FiniteRange(-kMaxStartFrame, kMaxStartFrame));
  cmd->add_option("--fps", flags->fps, "Frames per second of the walk (default 24)")
      ->check(FiniteRange(0.001, kMaxFps));
  cmd->add_option("--up", flags->up, "X,Y,Z world up of bipeds (default 0,1,0, as in Maya)")
      ->check(NotBlank("X,Y,Z"));
  CLI::Option* crowd =
      cmd->add_option("--crowd", flags->crowd,
                      "Generate this many characters at once on a grid around --start")
          ->transform(WholeRange(1, 1000000));
  CLI::Option* crowd_spacing =
      cmd->add_option("--crowd-spacing", flags->crowd_spacing,
                      "Distance between crowd characters (default: twice the character's reach)")
          ->check(FiniteAboveUpTo(0, 1e6));
  cmd->add_option("--threads", flags->threads,
                  "Threads for the embedded engine's queries and the generator's own work "
                  "(default: the hardware's; the walk is the same whatever the count)")
      ->transform(WholeRange(1, 256));
  cmd->add_flag("--progress", flags->progress,
                "Show a progress bar on stderr (shown anyway for long runs on a terminal)");
  cmd->add_flag("--foot-rotations", flags->foot_rotations,
                "Key the feet's rotations too: each foot on its ground, facing its body's "
                "heading (.gltf, .glb and .mel outputs key them; the .json gives each foot key a "
                "rotation)");
  cmd->add_option("--unit", flags->unit,
                  "The linear unit of the terrain, and so of the walk (cm for a terrain in "
                  "centimetres): the walk JSON says it, .gltf and .glb outputs convert the walk "
                  "to metres, glTF's unit, and .mel outputs key it with Maya's unit set to it "
                  "(the user's put back after), so the walk keeps its size wherever it goes; "
                  "default: not said, one walk unit to one unit of the scene it goes to")
      ->check(CLI::Validator(
          [](const std::string& unit) {
            return MetresPerLinearUnit(unit) > 0 ? std::string()
                                                 : std::string("expected ") + LinearUnitNames();
          },
          "UNIT"));
  cmd->add_option("-o,--out,--output", flags->out,
                  "Output file: .json, .gltf, .glb or .mel (repeatable); .pts: the terrain's "
                  "samples the walk was placed on (as resampled for the character), for "
                  "footfall-view or a plugin; -: the walk JSON on standard output")
      ->required();
  for (CLI::Option* o : {start, heading, path_opt, steps, crowd, crowd_spacing, scale, step_length,
                         step_height, frames_per_step, foot_length, foot_width})
    scene->excludes(o);
  cmd->footer(
      "Exit status: 0 when every step was generated, 2 when the walk stopped early (at a cliff, "
      "a gap, a wall too steep; the outputs then hold every key up to that step), 1 on errors "
      "(footfalld failing mid-walk among them: the keys up to its failure are written).");
  cmd->callback([flags, exit_code] { *exit_code = RunGenerate(*flags); });
}

}  // namespace footfall::cli
