// `footfall terrain`: convert meshes and height maps to point files, describe terrain files, and
// make synthetic test terrain.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "commands.h"
#include "footfall/cli/number_checks.h"
#include "footfall/import/terrain_generators.h"
#include "footfall/import/terrain_loader.h"
#include "footfall/steps/character.h"
#include "footfall/steps/walk_terrain.h"
#include "footfall/terrain/file_extension.h"
#include "footfall/terrain/grid.h"
#include "footfall/terrain/large_memory.h"
#include "footfall/terrain/output_file.h"
#include "footfall/terrain/point_file.h"
#include "footfall/terrain/text_stream.h"
#include "standard_streams.h"
#include "terrain_flags.h"

namespace footfall::cli {
namespace {

// "1 sample", "2 samples".
std::string SampleCount(size_t n) { return std::to_string(n) + (n == 1 ? " sample" : " samples"); }

struct ConvertFlags {
  std::string input, output;
  std::string character;  // resample for this character's steps (walk_terrain.h)
  double scale = 1;       // the character's lengths multiplied (generate's --scale)
  TerrainLoadOptions load;
};

struct InfoFlags {
  std::string input;
  TerrainLoadOptions load;
};

struct MakeFlags {
  std::string kind, output;
  double spacing = 0.05;
  uint64_t seed = 1;
  // stairs
  int steps = 8;
  double rise = 0.18, run = 0.3, width = 1.5;
  // blocks, rocks
  int size = 12;
  int max_height = 3;
  double amplitude = 0.6;
  // ramp
  std::vector<double> slopes{10, 20, 30};
  double length = 2;
  // sphere
  double radius = 3;
};

// Enough digits to tell apart samples a millimetre apart a thousand kilometres out.
std::string Format(const Vec3& v) {
  TextStream out;
  out << std::setprecision(12) << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return out.str();
}

int RunConvert(const ConvertFlags& flags) {
  RawSamples samples;
  std::string error;
  TerrainLoadReport report;
  TerrainLoadOptions load = flags.load;
  if (!flags.character.empty()) {
    // The whole file, as fine as generate resamples it for the character's walk.
    Character character;
    if (load.separation > 0) {
      error = "give --separation or --character, not both";
    } else if (IsPointFileExtension(FileExtension(flags.input))) {
      // (It was accepted and changed nothing.)
      error = flags.input +
              ": --character applies to meshes and height maps, which are resampled for it; a "
              "point file is used as it is (leave --character out)";
    } else if (LoadCharacter(flags.character, &character, &error) == Status::kOk) {
      if (flags.scale != 1 && ScaleCharacter(flags.scale, &character, &error) != Status::kOk) {
        error = "--scale: " + flags.character + ": " + error;
      } else {
        load.finest_default = kSeparationPerStep * character.step_length;
        load.max_samples = std::min(load.max_samples, kMaxWalkSamples);
      }
    }
    if (!error.empty()) {
      std::cerr << "footfall terrain convert: " << error << '\n';
      return 1;
    }
  }
  if (error.empty() && SameFile(flags.input, flags.output))
    error = flags.output + ": the output is the input file (write the points to another file)";
  if (error.empty() && !flags.character.empty() && SameFile(flags.character, flags.output)) {
    error = flags.output +
            ": the output is the character file --character reads (write the points to another "
            "file)";
  }
  if (error.empty()) ResamplingFlagsApply(flags.input, load, &error);
  if (!error.empty() || LoadTerrain(flags.input, load, &samples, &error, &report) != Status::kOk) {
    std::cerr << "footfall terrain convert: " << error << '\n';
    return 1;
  }
  if (WritePointFile(flags.output, samples, &error) != Status::kOk) {
    std::cerr << "footfall terrain convert: " << error << '\n';
    return 1;
  }
  std::cout << "wrote " << SampleCount(samples.size()) << " to " << flags.output;
  if (report.separation > 0) std::cout << " (separation " << report.separation << ")";
  std::cout << '\n';
  // What the resampling changed of the surface, as generate says it.
  for (const std::string& note :
       {DescribeSkippedFaces(report), DescribeTurnover(report), DescribeSteepHeightMap(report)})
    if (!note.empty())
      std::cerr << "footfall terrain convert: " << flags.input << ": " << note << '\n';
  // Coarser than the character's steps want, to stay within a walk's samples: said, as
  // generate says it.
  const std::string coarser = flags.character.empty() || report.format == "points"
                                  ? std::string()
                                  : CoarserThanStepsNote(report, load.finest_default);
  if (!coarser.empty())
    std::cerr << "footfall terrain convert: " << coarser << "; set --separation for a finer file\n";
  return 0;
}

int RunInfo(const InfoFlags& flags) {
  RawSamples samples;
  std::string error;
  TerrainLoadReport report;
  if (!ResamplingFlagsApply(flags.input, flags.load, &error) ||
      LoadTerrain(flags.input, flags.load, &samples, &error, &report) != Status::kOk) {
    std::cerr << "footfall terrain info: " << error << '\n';
    return 1;
  }
  TerrainGrid grid;
  if (TerrainGrid::Build(samples, GridOptions{}, &grid, &error) != Status::kOk) {
    std::cerr << "footfall terrain info: " << flags.input << ": " << error << '\n';
    return 1;
  }
  const GridStats& g = grid.stats();
  std::cout << std::setprecision(8);
  std::cout << "file: " << flags.input << '\n' << "format: " << report.format << '\n';
  if (report.format == "mesh") {
    std::cout << "vertices: " << report.vertices << '\n'
              << "faces: " << report.faces << " (polygons in the file)\n"
              << "skipped faces: " << report.skipped_faces << " (of those, left out)\n"
              << "faces turned over: "
              << (DescribeTurnover(report).empty() ? "none" : DescribeTurnover(report)) << '\n';
  } else if (report.format == "heightmap") {
    std::cout << "cells with data: " << report.vertices << '\n'
              << "nodata cells: " << report.nodata_cells << '\n'
              << "triangles: " << report.faces << '\n'
              << "surface over area covered: " << report.surface_ratio << " (1 when flat)\n";
    if (!DescribeSteepHeightMap(report).empty())
      std::cerr << "footfall terrain info: " << flags.input << ": "
                << DescribeSteepHeightMap(report) << '\n';
  }
  if (report.format != "points") {
    std::cout << "area: " << report.area << '\n' << "separation: " << report.separation << '\n';
  }
  std::cout << "samples: " << report.samples << '\n'
            << "bounds: " << Format(report.bounds_min) << " to " << Format(report.bounds_max)
            << " (of the samples)\n"
            << "grid: " << g.cells[0] << " x " << g.cells[1] << " x " << g.cells[2] << " cells of "
            << g.cell_size << ", " << g.occupied_cells << " occupied, " << g.bytes << " bytes\n"
            << "sample spacing: ";
  // Samples all at one point have no neighbours to be apart from (it read "about 1").
  if (report.bounds_min == report.bounds_max)
    std::cout << "none (" << (report.samples == 1 ? "a single sample" : "every sample at one point")
              << ")\n";
  else
    std::cout << "about " << g.spacing
              << (report.samples < kDirectSpacingSamples
                      ? " (the median distance from a sample to its nearest)\n"
                      : " (between neighbouring samples, taking them as a surface)\n");
  std::cout << "stored within: " << g.max_rounding
            << " of the given coordinates (float offsets from the centre of the bulk)\n";
  // (A full disk lost the description with exit 0.)
  if (!std::cout.flush()) {
    const int why = StandardOutputError();
    std::cerr << "footfall terrain info: cannot write to stdout: " << std::strerror(why ? why : EIO)
              << '\n';
    return 1;
  }
  return 0;
}

// The most samples `terrain make` writes (about 1 GB of point file).
constexpr double kMaxMadeSamples = 20000000;
// [Units: bytes] Peak memory per sample made: laid out directly (stairs, sphere, flat, hills;
// measured 49 to 62 resident, and more address space while an array doubles: 19.4 million
// flat samples fail under a 1.5 GB limit and pass under 2 GB), and sampled from a mesh
// (blocks, ramp, rocks; measured 400 to 460 resident).
constexpr double kBytesPerSample = 96;
constexpr double kMeshBytesPerSample = 500;

// Lattice points along a side `size` long at `spacing`: both ends. A ratio a rounding below a
// whole number counts as it (7 / 0.07 is 99.99999999999999: the last row and column went).
int SamplesAlong(double size, double spacing) {
  const double steps = size / spacing;
  const double whole = std::round(steps);
  return static_cast<int>(
             std::fabs(steps - whole) <= 1e-9 * std::max(1.0, whole) ? whole : std::floor(steps)) +
         1;
}

// About how many samples `make` would write, in double so that no flag can overflow it (areas
// in units of spacing^2, measured per side: a 1e300 sphere at --spacing 1e300 was inf * 0,
// "about -nan samples").
double EstimateSamples(const MakeFlags& f) {
  const std::string& k = f.kind;
  if (k == "stairs") {
    // As MakeStairs counts them: a tread and a riser take at least one sample each way, however
    // coarse the spacing (2 billion treads at --spacing 1e12 were "about 0" samples).
    auto count = [&f](double length) { return std::max(1.0, std::round(length / f.spacing)); };
    return f.steps * (count(f.width) + 1) * (count(f.run) + count(std::fabs(f.rise)) - 1);
  }
  if (k == "blocks") return f.size / f.spacing * (f.size / f.spacing) * (1 + 4.0 * f.max_height);
  if (k == "ramp") {
    double run = f.length;  // the landing
    for (double slope : f.slopes) run += f.length / std::cos(slope * 3.14159265358979323846 / 180);
    return run / f.spacing * (f.width / f.spacing);
  }
  if (k == "sphere")
    return 4 * 3.14159265358979323846 * (f.radius / f.spacing) * (f.radius / f.spacing);
  const double side = f.size / f.spacing + 1;  // rocks, flat, hills
  return side * side;
}

// About how many cells the mesh that `make` samples has (blocks: a face per exposed side of a
// unit cube; rocks: cells 0.25 wide, or --spacing if finer), which a coarse --spacing does not
// make smaller; 0 for the kinds whose work the sample count bounds.
double EstimateMeshCells(const MakeFlags& f) {
  if (f.kind == "blocks") return static_cast<double>(f.size) * f.size * (1 + 4.0 * f.max_height);
  if (f.kind == "rocks") {
    const double n = std::ceil(f.size / std::min(f.spacing, 0.25));
    return n * n;
  }
  return 0;
}

// [Units: wu] The largest coordinate, in size, of the mesh that `make` samples, checked before
// the mesh is built where the sampler cannot take it: a ramp's profile, as MakeRampsMesh lays
// it (a ramp 1e300 long failed allocating), and rocks whose relief is beyond what the sampler
// can measure (squared lengths overflow: rocks 1e300 high asked for "a separation of at least
// -nan"; lower ones it refuses itself, or their samples are checked as made); 0 otherwise.
double MeshReach(const MakeFlags& f) {
  if (f.kind == "rocks") return std::fabs(f.amplitude) > 1e150 ? std::fabs(f.amplitude) : 0;
  if (f.kind != "ramp") return 0;
  double y = 0, reach = std::max(f.width, f.length * (static_cast<double>(f.slopes.size()) + 2));
  for (double slope : f.slopes) {
    y += f.length * std::tan(slope * 3.14159265358979323846 / 180);
    reach = std::max(reach, std::fabs(y));
  }
  return reach;
}

// The refusal of a terrain whose coordinates (of size `m`) pass the grid's range.
int OutOfRange(const std::string& kind, double m) {
  std::cerr << "footfall terrain make: " << kind << ": the parameters give coordinates beyond "
            << terrain::kMaxCoordinate << " (" << m << "), out of the grid's range\n";
  return 1;
}

// `x` with 3 significant digits ("4e+24"), for counts far beyond any limit.
std::string Format3(double x) {
  TextStream o;
  o << std::setprecision(3) << x;
  return o.str();
}

int RunMake(const MakeFlags& f) {
  RawSamples samples;
  const std::string& k = f.kind;
  const double estimate = EstimateSamples(f);
  if (!(estimate <= kMaxMadeSamples)) {
    TextStream m;
    m << "footfall terrain make: " << k << ": these sizes at --spacing " << f.spacing << " give "
      << (estimate < 1e15           ? "about " + std::to_string(std::llround(estimate))
          : std::isfinite(estimate) ? "about " + Format3(estimate)
                                    : std::string("too many"))
      << " samples, more than the " << std::setprecision(10) << kMaxMadeSamples
      << " allowed (raise --spacing or give smaller sizes)";
    std::cerr << m.str() << '\n';
    return 1;
  }
  const double cells = EstimateMeshCells(f);
  if (!(cells <= kMaxMadeSamples)) {
    TextStream m;
    m << "footfall terrain make: " << k << ": these sizes give a mesh of about "
      << (cells < 1e15 ? std::to_string(std::llround(cells)) : Format3(cells))
      << " cells to sample ("
      << (k == "rocks" ? "rocks are modelled 0.25 apart, whatever --spacing"
                       : "a face per side of a unit cube")
      << "), more than the " << std::setprecision(10) << kMaxMadeSamples
      << " allowed (give smaller sizes)";
    std::cerr << m.str() << '\n';
    return 1;
  }
  if (const double reach = MeshReach(f); !(reach <= terrain::kMaxCoordinate))
    return OutOfRange(k, reach);
  // Sizes this machine cannot hold are refused now, not after minutes of sampling ended in
  // "out of memory" (rocks of 9 million samples under a 2 GB limit).
  const bool meshed = k == "blocks" || k == "ramp" || k == "rocks";
  const double bytes = estimate * (meshed ? kMeshBytesPerSample : kBytesPerSample);
  if (const double memory = UsableMemoryBytes(); memory > 0 && bytes > memory) {
    std::cerr << std::setprecision(3) << "footfall terrain make: " << k
              << ": these sizes at --spacing " << f.spacing << " give about "
              << std::llround(estimate) << " samples: making them needs about " << bytes / 1e9
              << " GB, more than the " << memory / 1e9
              << " GB of memory this process may use (raise --spacing or give smaller sizes)\n";
    return 1;
  }
  std::string why;  // the mesh sampler's, for blocks, ramp and rocks
  // The estimate above is the ground's plan area: relief adds surface (rocks 5 high: 3.7 times
  // the samples), which the mesh sampler counts from the mesh itself before sampling. It is
  // held to what memory holds too, not only to kMaxMadeSamples (it ended in a bare "out of
  // memory").
  size_t most = static_cast<size_t>(kMaxMadeSamples);
  const double memory = UsableMemoryBytes();
  const bool memory_binds = memory > 0 && memory / kMeshBytesPerSample < kMaxMadeSamples;
  if (memory_binds) most = std::max<size_t>(1, static_cast<size_t>(memory / kMeshBytesPerSample));
  if (k == "stairs") {
    samples = MakeStairs(f.steps, f.rise, f.run, f.width, f.spacing);
  } else if (k == "blocks") {
    samples = MakeBlocks(f.size, f.size, f.max_height, f.spacing, f.seed, &why, most);
  } else if (k == "ramp") {
    samples = MakeRamps(f.slopes, f.length, f.width, f.spacing, &why, most);
  } else if (k == "rocks") {
    samples = MakeRocks(f.size, f.amplitude, f.spacing, f.seed, &why, most);
  } else if (k == "sphere") {
    // Fibonacci lattice with about one sample per spacing^2 of surface (the estimate: no inf /
    // inf cast to int for a sphere as large as its spacing).
    samples = MakeSphere(static_cast<int>(estimate) + 1, {0, f.radius, 0}, f.radius);
  } else if (k == "flat") {
    samples = MakeFlat(SamplesAlong(f.size, f.spacing), f.spacing, 0);
  } else if (k == "hills") {
    const int n = SamplesAlong(f.size, f.spacing);
    samples = MakeHills(n, f.spacing, f.amplitude, f.seed);
  }
  std::string error;
  if (samples.size() == 0) {
    // The sampler's reason, when it refused (rocks 10 km high: "no samples" said nothing).
    std::cerr << "footfall terrain make: " << k << ": "
              << (why.empty() ? "the parameters give no samples" : why);
    if (memory_binds && why.find("limit") != std::string::npos)
      std::cerr << std::setprecision(3) << " (the limit is what the " << memory / 1e9
                << " GB of memory this process may use holds, at about " << kMeshBytesPerSample
                << " bytes a sample)";
    std::cerr << '\n';
    return 1;
  }
  for (const Vec3& p : samples.points) {
    const double m = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
    if (!(m <= terrain::kMaxCoordinate)) return OutOfRange(k, m);
  }
  if (WritePointFile(f.output, samples, &error) != Status::kOk) {
    std::cerr << "footfall terrain make: " << error << '\n';
    return 1;
  }
  std::cout << "wrote " << SampleCount(samples.size()) << " to " << f.output << '\n';
  return 0;
}

// -o of convert and make: terrain is written as a point file only, so its name must say so
// (.pts .xyz .txt), or `-o walls.obj` would write points into a file that every reader takes
// for a mesh.
const CLI::Validator kPointFileOutput(
    [](std::string& path) {
      if (IsPointFileExtension(FileExtension(path))) return std::string();
      return "'" + path +
             "': expected a point file name (.pts .xyz .txt): terrain is written as "
             "points";
    },
    "FILE.pts");

}  // namespace

void AddTerrainCommand(CLI::App& app, int* exit_code) {
  CLI::App* terrain = app.add_subcommand(
      "terrain", "Convert, describe and make terrain files (points, meshes, height maps)");
  terrain->require_subcommand(1);

  auto convert = std::make_shared<ConvertFlags>();
  CLI::App* c = terrain->add_subcommand(
      "convert", "Resample a mesh or height map (or copy a point file) into a point file");
  c->add_option("input", convert->input, "Terrain file (.obj .ply .off .stl .asc .pgm .pts)")
      ->required();
  c->add_option("-o,--output,--out", convert->output, "Point file to write (.pts .xyz .txt)")
      ->required()
      ->check(kPointFileOutput);
  AddLoadFlags(c, &convert->load);
  CLI::Option* character =
      c->add_option("--character", convert->character,
                    "Meshes and height maps: resample as finely as footfall generate does for this "
                    "character (a quarter of its step, at most 2,000,000 samples); not with "
                    "--separation");
  c->add_option("--scale", convert->scale,
                "The character's lengths multiplied, as footfall generate --scale takes them "
                "(with --character)")
      ->check(FiniteRange(kMinCharacterScale, kMaxCharacterScale))
      ->needs(character);  // (by name, CLI11 looks it up in a noexcept function)
  c->callback([convert, exit_code] { *exit_code = RunConvert(*convert); });

  auto info = std::make_shared<InfoFlags>();
  CLI::App* i = terrain->add_subcommand(
      "info", "Print a terrain file's counts, bounds, area and the grid it would build");
  i->add_option("input", info->input, "Terrain file")->required();
  AddLoadFlags(i, &info->load);
  i->callback([info, exit_code] { *exit_code = RunInfo(*info); });

  auto make = std::make_shared<MakeFlags>();
  CLI::App* m = terrain->add_subcommand(
      "make", "Write a synthetic terrain of known geometry (Y up, world units) as a point file");
  m->add_option("kind", make->kind, "stairs, blocks, ramp, rocks, sphere, flat or hills")
      ->required()
      ->check(CLI::IsMember({"stairs", "blocks", "ramp", "rocks", "sphere", "flat", "hills"}));
  m->add_option("-o,--output,--out", make->output, "Point file to write (.pts .xyz .txt)")
      ->required()
      ->check(kPointFileOutput);
  m->add_option("--spacing", make->spacing, "Distance between samples")
      ->check(FiniteAbove(0))
      ->capture_default_str();
  m->add_option("--seed", make->seed,
                "Seed (blocks, rocks, hills), a whole number from 0 to 2^64 - 1")
      ->transform(Seed())
      ->capture_default_str();
  m->add_option("--steps", make->steps,
                "stairs: number of treads, the first on the ground (one riser fewer)")
      ->transform(WholeRange(1, 2147483647))
      ->capture_default_str();
  m->add_option("--rise", make->rise, "stairs: step height (negative: stairs going down along +z)")
      ->check(Finite())
      ->capture_default_str();
  m->add_option("--run", make->run, "stairs: step depth")
      ->check(FiniteAbove(0))
      ->capture_default_str();
  m->add_option("--width", make->width, "stairs, ramp: width across")
      ->check(FiniteAbove(0))
      ->capture_default_str();
  m->add_option("--size", make->size, "blocks: columns per side; rocks, flat, hills: side length")
      ->transform(WholeRange(1, 2147483647))
      ->capture_default_str();
  m->add_option("--max-height", make->max_height, "blocks: tallest pile in unit cubes")
      ->transform(WholeRange(0, 2147483647))
      ->capture_default_str();
  m->add_option("--amplitude", make->amplitude,
                "rocks, hills: height of the relief (hills: the same hills at any --spacing)")
      ->check(Finite())
      ->capture_default_str();
  m->add_option("--slope", make->slopes, "ramp: slope of each segment in degrees (repeatable)")
      ->check(FiniteRange(-80, 80))
      ->capture_default_str();
  m->add_option("--length", make->length, "ramp: horizontal run of each segment and landing")
      ->check(FiniteAbove(0))
      ->capture_default_str();
  m->add_option("--radius", make->radius, "sphere: radius (it rests on y = 0)")
      ->check(FiniteAbove(0))
      ->capture_default_str();
  // A flag of another kind's shape (--steps for flat) is refused, not ignored. The options are
  // found here by their long names, not with CLI11's get_option, which may not throw: memory
  // running out within it ended the process.
  const std::pair<const char*, const char*> kinds_of[] = {{"--seed", "blocks rocks hills"},
                                                          {"--steps", "stairs"},
                                                          {"--rise", "stairs"},
                                                          {"--run", "stairs"},
                                                          {"--width", "stairs ramp"},
                                                          {"--size", "blocks rocks flat hills"},
                                                          {"--max-height", "blocks"},
                                                          {"--amplitude", "rocks hills"},
                                                          {"--slope", "ramp"},
                                                          {"--length", "ramp"},
                                                          {"--radius", "sphere"}};
  std::vector<std::tuple<const CLI::Option*, std::string, std::string>> shaped;
  for (const CLI::Option* option : m->get_options())
    for (const auto& [flag, kinds] : kinds_of)
      for (const std::string& name : option->get_lnames())
        if (name == flag + 2) shaped.emplace_back(option, flag, kinds);
  m->callback([shaped, make, exit_code] {
    for (const auto& [option, flag, kinds] : shaped) {
      if (option->count() == 0) continue;
      if (std::istringstream words(kinds);
          std::find(std::istream_iterator<std::string>(words), std::istream_iterator<std::string>(),
                    make->kind) == std::istream_iterator<std::string>()) {
        std::cerr << "footfall terrain make: " << flag << " is for " << kinds << ", not "
                  << make->kind << '\n';
        *exit_code = 1;
        return;
      }
    }
    *exit_code = RunMake(*make);
  });
}

}  // namespace footfall::cli
