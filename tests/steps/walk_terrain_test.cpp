// Terrain set-up for a walk (walk_terrain.h): a height map whose cells are coarser than a
// character's steps is resampled finely enough for it, only around where the walk goes, and the
// walk then goes where the file's own spacing stops it.
#include "footfall/steps/walk_terrain.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include <catch2/catch.hpp>

#include "footfall/steps/character.h"
#include "generator_fixtures.h"
#include "walk_checks.h"

using namespace footfall;
using namespace footfall::test;

namespace {

// A temporary ESRI ASCII grid of n x n cells of `cell` with gentle bumps (heights within a
// fifth of a cell), removed by the destructor.
struct BumpyAsc {
  std::string path;
  BumpyAsc(int n, double cell, const std::string& name) {
    path = std::string(std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp") + "/footfall_" +
           name + "_" + std::to_string(::getpid()) + ".asc";
    std::ofstream out(path);
    out << "ncols " << n << "\nnrows " << n << "\nxllcorner 0\nyllcorner 0\ncellsize " << cell
        << "\n";
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c)
        out << 0.1 * cell * (std::sin(0.7 * r) + std::cos(0.5 * c)) << ' ';
      out << '\n';
    }
  }
  ~BumpyAsc() { std::remove(path.c_str()); }
};

bool Inside(const Vec3& p, const WalkTerrain& t) {
  return p.x >= t.region_min.x && p.y >= t.region_min.y && p.z >= t.region_min.z &&
         p.x <= t.region_max.x && p.y <= t.region_max.y && p.z <= t.region_max.z;
}

// PrepareWalkTerrain on `asc` with the default load options; REQUIREs success.
WalkTerrain Prepared(const BumpyAsc& asc, const Character& c, const GenerateOptions& o) {
  WalkTerrain prepared;
  std::string error;
  const Status status = PrepareWalkTerrain(asc.path, TerrainLoadOptions{}, c, o, &prepared, &error);
  INFO(error);
  REQUIRE(status == Status::kOk);
  return prepared;
}

// `o` walking from the start `prepared` found for it.
GenerateOptions FromPreparedStart(GenerateOptions o, const WalkTerrain& prepared) {
  o.start = prepared.start;
  return o;
}

size_t BodyKeys(const Walk& w) {
  for (const WalkTrack& t : w.tracks)
    if (t.kind == TrackKind::kBody) return t.keys.size();
  return 0;
}

}  // namespace

TEST_CASE("PrepareWalkTerrain: a height map coarser than the steps is walked after resampling",
          "[steps][terrain]") {
  for (const std::string& name : ShippedCharacters()) {
    const Character c = LoadShipped(name);
    INFO(name);
    // Cells twice the step: the file's own samples lie farther apart than the foothold radius.
    const double cell = 2 * c.step_length;
    const BumpyAsc asc(80, cell, name);
    GenerateOptions o;
    o.steps = 12;
    o.has_start = true;
    o.start = {40 * cell, 5 * cell, 40 * cell};
    o.heading = {1, 0, 1};

    const WalkTerrain prepared = Prepared(asc, c, o);
    std::string error;
    CHECK(prepared.report.separation == Approx(kSeparationPerStep * c.step_length));
    CHECK(prepared.report.file_separation == Approx(cell));
    // The start is the surface point nearest the point asked for: below it, give or take the
    // bumps' slope.
    CHECK(std::hypot(prepared.start.x - o.start.x, prepared.start.z - o.start.z) < cell);
    CHECK(std::fabs(prepared.start.y) < 0.25 * cell);
    // Cropped to the box of 12 steps: far less than the 160 steps of the file.
    REQUIRE(prepared.cropped);
    CHECK(prepared.region_is_bound);
    CHECK(prepared.region_max.x - prepared.region_min.x < 0.75 * 80 * cell);

    Terrain t = LoadTerrain(prepared.samples, prepared.report.separation);
    const GenerateOptions walk = FromPreparedStart(o, prepared);
    const Walk w = Generate(t, c, walk);
    INFO(w.stopped);
    CHECK(w.stopped.empty());
    CHECK(BodyKeys(w) == 13);
    CheckWalk(t, c, walk, w);
    // Every key inside the box, and no foot moving farther in a step than MaxStepTravel.
    for (const WalkTrack& track : w.tracks) {
      for (const WalkKey& k : track.keys) CHECK(Inside(k.position, prepared));
      if (track.kind != TrackKind::kFoot) continue;
      const WalkKey* last_end = nullptr;
      for (const WalkKey& k : track.keys) {
        if (k.phase != KeyPhase::kEnd) continue;
        if (last_end) CHECK(Distance(last_end->position, k.position) <= MaxStepTravel(c));
        last_end = &k;
      }
    }

    // The file's own samples: the same walk stops at once.
    RawSamples own;
    REQUIRE(footfall::LoadTerrain(asc.path, TerrainLoadOptions{}, &own, &error) == Status::kOk);
    Terrain coarse = LoadTerrain(own, cell);
    const Walk stopped = Generate(coarse, c, walk);
    CHECK_FALSE(stopped.stopped.empty());
    CHECK(BodyKeys(stopped) < 13);
    // ... and says that the samples are too far apart, and at what to resample.
    CHECK_THAT(stopped.stopped,
               Catch::Contains("too far for this character: resample it at a separation of"));
  }
}

TEST_CASE("PrepareWalkTerrain: without a start, the surface under the top centre",
          "[steps][terrain]") {
  const Character c = LoadShipped("biped");
  const BumpyAsc asc(20, 1.0, "centre");
  GenerateOptions o;  // no start, default up +Y
  const WalkTerrain prepared = Prepared(asc, c, o);
  // The grid's points span 0 .. 19 in x and z: the start lies near 9.5, 9.5, on the surface.
  CHECK(prepared.start.x == Approx(9.5).margin(0.5));
  CHECK(prepared.start.z == Approx(9.5).margin(0.5));
  CHECK(std::fabs(prepared.start.y) < 0.25);
  // Eight steps of a biped reach beyond this 20 m field: nothing cropped.
  CHECK_FALSE(prepared.cropped);
  CHECK(prepared.report.separation == Approx(0.175));
}

TEST_CASE("PrepareWalkTerrain: a path walked to its end widens the box along it",
          "[steps][terrain]") {
  const Character c = LoadShipped("hexapod");
  const BumpyAsc asc(100, 0.5, "path");
  const GenerateOptions o = PathOptions({5, 1, 5}, {{30, 0, 5}, {30, 0, 40}}, -1);
  WalkTerrain prepared = Prepared(asc, c, o);
  std::string error;
  CHECK_FALSE(prepared.region_is_bound);
  REQUIRE(prepared.cropped);
  for (const Vec3& p : {prepared.start, o.path[0], o.path[1]}) CHECK(Inside(p, prepared));
  CHECK(prepared.region_max.x < 45);  // the terrain reaches 50
  // A separation set by the caller is refused: the set-up chooses it.
  TerrainLoadOptions set;
  set.separation = 0.1;
  CHECK(PrepareWalkTerrain(asc.path, set, c, o, &prepared, &error) == Status::kInvalidArgument);
  // Point files are not resampled.
  CHECK(PrepareWalkTerrain(FOOTFALL_SOURCE_DIR "/data/terrain/stairs.pts", TerrainLoadOptions{}, c,
                           o, &prepared, &error) == Status::kInvalidArgument);
}

TEST_CASE("PrepareWalkTerrain: a path spans the whole surface along up, whatever its heights",
          "[steps][terrain]") {
  // Waypoints given at y = 0 over ground 500 m up that climbs between them: the box ran from
  // the waypoints' heights to the start's, and the walk stopped at its top as at a cliff where
  // the bank rose above it.
  const Character c = LoadShipped("hexapod");
  const std::string path = std::string(std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp") +
                           "/footfall_bank_" + std::to_string(::getpid()) + ".asc";
  {
    std::ofstream out(path);
    out << "ncols 40\nnrows 20\nxllcorner 0\nyllcorner 0\ncellsize 0.5\n";
    for (int r = 0; r < 20; ++r) {
      for (int col = 0; col < 40; ++col) out << 500 + 0.15 * col << ' ';  // up 6 m along x
      out << '\n';
    }
  }
  const GenerateOptions o = PathOptions({2, 0, 5}, {{18, 0, 5}}, -1);
  WalkTerrain prepared;
  std::string error;
  const Status status = PrepareWalkTerrain(path, TerrainLoadOptions{}, c, o, &prepared, &error);
  std::remove(path.c_str());
  INFO(error);
  REQUIRE(status == Status::kOk);
  REQUIRE(prepared.cropped);  // across up: the path's box
  CHECK(prepared.region_min.y <= 500);
  CHECK(prepared.region_max.y >= 500 + 0.15 * 39);
  Terrain t = LoadTerrain(prepared.samples, prepared.report.separation);
  const Walk w = Generate(t, c, FromPreparedStart(o, prepared));
  INFO(w.stopped);
  CHECK(w.stopped.empty());
  CHECK(BodyKeys(w) > 20);
}

TEST_CASE("PrepareWalkTerrain: a start that may move keeps its search area in the box",
          "[steps][terrain]") {
  const Character c = LoadShipped("hexapod");
  const BumpyAsc asc(60, 0.5, "search");
  GenerateOptions o;
  o.has_start = true;
  o.start = {15, 0, 15};
  o.steps = 4;
  const WalkTerrain fixed = Prepared(asc, c, o);
  o.start_may_move = true;
  const WalkTerrain moving = Prepared(asc, c, o);
  REQUIRE(fixed.cropped);
  REQUIRE(moving.cropped);
  // Wider by the search radius on every side.
  const double r = StartSearchRadius(c);
  CHECK(r == Approx(kStartSearchSteps * c.step_length));
  CHECK(fixed.region_min.x - moving.region_min.x == Approx(r));
  CHECK(moving.region_max.z - fixed.region_max.z == Approx(r));
  // Every candidate the generator may stand on lies inside (in the plane across up).
  for (const Vec3& d : {Vec3{r, 0, 0}, Vec3{-r, 0, 0}, Vec3{0, 0, r}, Vec3{0, 0, -r}})
    CHECK(Inside(moving.start + d, moving));
}

TEST_CASE("A multiped crossing a block's corner keeps its body out of the block",
          "[steps][walk_terrain]") {
  // A ten-legged multiped walking diagonally over the corner of a 1 m cube (an OBJ of six faces,
  // resampled for it as footfall generate does): a body key whose nearest sample lay on a side
  // face, which its most raise would not take it out of, was not raised (as under a roof) and
  // stayed 3.8 cm inside.
  const std::string path = std::string(std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp") +
                           "/footfall_cube_" + std::to_string(::getpid()) + ".obj";
  {
    std::ofstream out(path);
    for (int i = 0; i < 8; ++i)
      out << "v " << (i & 4 ? 0.5 : -0.5) << ' ' << (i & 2 ? 1 : 0) << ' ' << (i & 1 ? 0.5 : -0.5)
          << '\n';
    out << "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n";
  }
  // Ten legs in five pairs, 3 cm body, reach 40 cm.
  std::string feet;
  for (int i = 0; i < 5; ++i) {
    const std::string z = std::to_string(0.24 - 0.12 * i);
    feet += std::string(i ? "," : "") + "{\"name\": \"L" + std::to_string(i + 1) +
            "\", \"rest\": [0.08, 0, " + z + "]}, {\"name\": \"R" + std::to_string(i + 1) +
            "\", \"rest\": [-0.08, 0, " + z + "]}";
  }
  Character c;
  std::string parse_error;
  REQUIRE(ParseCharacter(
              R"({"format": "footfall-character", "version": 1, "name": "centipede", "feet": [)" +
                  feet +
                  R"(], "gait": [["L1", "R2", "L3", "R4", "L5"], ["R1", "L2", "R3", "L4", "R5"]],
                 "pairs": [["L1", "R1"], ["L2", "R2"], ["L3", "R3"], ["L4", "R4"], ["L5", "R5"]],
                 "step_length": 0.08, "step_height": 0.03, "body_height": 0.03,
                 "frames_per_step": 6, "align_to_normal": true, "slope_threshold_deg": 25,
                 "slope_step_scale": 0.7, "max_slope_deg": 100, "max_rise": 0.06, "reach": 0.4,
                 "max_turn_deg": 30})",
              "centipede.json", &c, &parse_error) == Status::kOk);
  for (const Vec3& heading : {Vec3{1, 0, 1}, Vec3{-1, 0, 1}}) {
    GenerateOptions o;
    o.has_start = true;
    o.start = {0, 1, 0};
    o.heading = heading;
    o.steps = 60;
    WalkTerrain prepared;
    std::string error;
    REQUIRE(PrepareWalkTerrain(path, TerrainLoadOptions{}, c, o, &prepared, &error) == Status::kOk);
    Terrain t = LoadTerrain(prepared.samples, prepared.report.separation * 2 / 3);
    const Walk w = Generate(t, c, o);
    INFO(heading.x << ": " << w.stopped);
    CheckWalk(t, c, o, w);
    double deepest = 0;
    for (const WalkTrack& track : w.tracks) {
      if (track.kind != TrackKind::kBody) continue;
      for (const WalkKey& k : track.keys) {
        const Vec3& p = k.position;
        deepest =
            std::max(deepest, std::min({p.x + 0.5, 0.5 - p.x, p.y, 1 - p.y, p.z + 0.5, 0.5 - p.z}));
      }
    }
    CHECK(deepest <= 0);
  }
  std::remove(path.c_str());
}

TEST_CASE("A crowd whose grid runs off a slab's edge stands no two characters on one place",
          "[steps][walk_terrain]") {
  // 49 hexapods 0.3 apart around a corner of a closed rough slab (4 x 4 m, 20 cm thick; an OBJ
  // resampled as footfall generate does): two places on the edge snapped apart, but their feet
  // snapped alike, and both characters were kept, every first key identical.
  const std::string path = std::string(std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp") +
                           "/footfall_slab_" + std::to_string(::getpid()) + ".obj";
  {
    constexpr int n = 48;
    constexpr double half = 2.0, amp = 0.06;
    auto coordinate = [](int i) { return -half + 2 * half * i / n; };
    auto height = [](double x, double z) {
      return amp * std::sin(3 * x) * std::cos(3 * z) +
             0.5 * amp * std::sin(7 * x + 1) * std::sin(5 * z);
    };
    std::ofstream out(path);
    out.precision(17);
    // Vertices: the top (n + 1)^2, then the bottom (n + 1)^2; 1-based ids in the file.
    for (int bottom = 0; bottom < 2; ++bottom)
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
          const double x = coordinate(i), z = coordinate(j);
          out << "v " << x << ' ' << (bottom ? -0.2 : height(x, z)) << ' ' << z << '\n';
        }
    auto top = [](int i, int j) { return 1 + i * (n + 1) + j; };
    auto low = [&](int i, int j) { return top(i, j) + (n + 1) * (n + 1); };
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        out << "f " << top(i, j) << ' ' << top(i, j + 1) << ' ' << top(i + 1, j + 1) << ' '
            << top(i + 1, j) << '\n';
    std::vector<std::pair<int, int>> ring;
    for (int i = 0; i < n; ++i) ring.push_back({i, 0});
    for (int j = 0; j < n; ++j) ring.push_back({n, j});
    for (int i = n; i > 0; --i) ring.push_back({i, n});
    for (int j = n; j > 0; --j) ring.push_back({0, j});
    for (size_t k = 0; k < ring.size(); ++k) {
      const auto [ai, aj] = ring[k];
      const auto [bi, bj] = ring[(k + 1) % ring.size()];
      out << "f " << top(ai, aj) << ' ' << top(bi, bj) << ' ' << low(bi, bj) << ' ' << low(ai, aj)
          << '\n';
    }
    out << 'f';
    for (const auto& [i, j] : ring) out << ' ' << low(i, j);
    out << '\n';
  }
  const Character c = LoadShipped("hexapod");
  GenerateOptions o;
  o.has_start = true;
  o.start = {1.7, 0, 1.7};
  o.heading = {1, 0, 0};
  o.steps = 4;
  o.crowd = 49;
  o.crowd_spacing = 0.3;
  WalkTerrain prepared;
  std::string error;
  REQUIRE(PrepareWalkTerrain(path, TerrainLoadOptions{}, c, o, &prepared, &error) == Status::kOk);
  std::remove(path.c_str());
  Terrain t = LoadTerrain(prepared.samples, prepared.report.separation * 2 / 3);
  const Walk w = Generate(t, c, o);
  std::vector<Vec3> bodies;
  for (const WalkTrack& track : w.tracks)
    if (track.kind == TrackKind::kBody) bodies.push_back(track.keys.front().position);
  CHECK(bodies.size() > 20);
  size_t stacked = 0;
  for (size_t i = 0; i < bodies.size(); ++i)
    for (size_t j = i + 1; j < bodies.size(); ++j) stacked += Distance(bodies[i], bodies[j]) < 0.15;
  CHECK(stacked == 0);
}

TEST_CASE("PrepareWalkTerrain: a surface too large to resample finely enough is refused at once",
          "[steps][walk_terrain]") {
  // A hexapod of 3 cm steps (a separation of 0.0075) along a path across a 100 m height map:
  // about 190 million samples, past the 2,000,000 cap. The surface was resampled at 0.072, 10
  // times a quarter step, after a minute of sampling, and the walk then stopped at its first
  // step for want of footholds, advising a separation it could not have.
  Character c = LoadShipped("hexapod");
  c.step_length = 0.03;
  const BumpyAsc asc(100, 1, "large");
  GenerateOptions o = PathOptions({10, 0, 10}, {{90, 0, 90}}, -1);
  WalkTerrain prepared;
  std::string error;
  CHECK(PrepareWalkTerrain(asc.path, TerrainLoadOptions{}, c, o, &prepared, &error) ==
        Status::kLimitExceeded);
  CHECK_THAT(error, Catch::StartsWith(asc.path + ": resampled for hexapod at a quarter of its "
                                                 "step (0.0075) within the box its walk can "
                                                 "reach, its "));
  CHECK_THAT(error, Catch::Contains(" samples, more than the 2000000 a walk's terrain may have; "
                                    "at the separation that fits, 0.07"));
  CHECK_THAT(error, Catch::Contains("(more than its step), samples lie farther apart than the "
                                    "half step (0.015) within which the character looks for a "
                                    "foothold, and the walk would stop within its first steps; "
                                    "give --steps, or waypoints nearer the start (the box holds "
                                    "them and eight steps around them), or --separation S to "
                                    "resample the whole file at S"));
  // Its steps given, the box is theirs: as many as cover the map are refused the same way.
  o.path.clear();
  o.steps = 1000;
  CHECK(PrepareWalkTerrain(asc.path, TerrainLoadOptions{}, c, o, &prepared, &error) ==
        Status::kLimitExceeded);
  CHECK_THAT(error, Catch::Contains("; give fewer --steps, or --separation S"));
}
