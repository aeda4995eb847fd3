// TerrainGrid against its brute-force oracle on many terrain shapes: every answer must be
// identical (status, index, point, normal) for queries inside, on and far outside the bounds,
// along every axis both ways.
#include <algorithm>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/import/terrain_generators.h"
#include "footfall/terrain/batch_pool.h"
#include "footfall/terrain/brute_force.h"
#include "footfall/terrain/grid.h"

using namespace footfall;

namespace {

TerrainGrid Build(RawSamples s, const GridOptions& options = GridOptions{}) {
  std::string error;
  REQUIRE(ValidateAndNormalize(&s, &error) == Status::kOk);
  TerrainGrid g;
  REQUIRE(TerrainGrid::Build(s, options, &g, &error) == Status::kOk);
  return g;
}

void RequireSame(const Foothold& a, const Foothold& b, const std::string& what) {
  INFO(what);
  REQUIRE(StatusName(a.status) == std::string(StatusName(b.status)));
  if (a.status != Status::kOk) return;
  REQUIRE(a.index == b.index);
  REQUIRE(a.point == b.point);
  REQUIRE(a.normal == b.normal);
}

std::string Describe(const Vec3& v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

// Query points: samples themselves, jittered samples, uniform in the bounds, on the bounds'
// faces and corners, and far outside in every direction.
std::vector<Vec3> QueryPoints(const TerrainGrid& g, std::mt19937_64& rng, int count) {
  const GridStats& st = g.stats();
  const Vec3 lo = st.bounds_min, hi = st.bounds_max;
  const Vec3 size = hi - lo;
  const double scale = std::max({size.x, size.y, size.z, 1e-3});
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> samples;
  g.ForEachSample([&](uint32_t, const Vec3& p, const Vec3&) { samples.push_back(p); });
  std::vector<Vec3> q;
  for (int i = 0; i < count; ++i) {
    const Vec3& s = samples[rng() % samples.size()];
    switch (i % 6) {
      case 0:
        q.push_back(s);
        break;
      case 1:
        q.push_back(s + Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5} * (0.05 * scale));
        break;
      case 2:
        q.push_back(lo + Vec3{u(rng) * size.x, u(rng) * size.y, u(rng) * size.z});
        break;
      case 3: {  // on a face or corner of the bounds
        Vec3 p = lo + Vec3{u(rng) * size.x, u(rng) * size.y, u(rng) * size.z};
        const int axis = static_cast<int>(rng() % 3);
        const bool top = rng() % 2;
        (axis == 0   ? p.x
         : axis == 1 ? p.y
                     : p.z) = axis == 0   ? (top ? hi.x : lo.x)
                              : axis == 1 ? (top ? hi.y : lo.y)
                                          : (top ? hi.z : lo.z);
        if (rng() % 4 == 0)
          p = Vec3{rng() % 2 ? hi.x : lo.x, rng() % 2 ? hi.y : lo.y, rng() % 2 ? hi.z : lo.z};
        q.push_back(p);
        break;
      }
      case 4: {  // far outside along one axis, both ways
        Vec3 p = s;
        const int axis = (i / 6) % 3;
        const double far = (i / 18) % 2 ? 50 * scale : -50 * scale;
        (axis == 0 ? p.x : axis == 1 ? p.y : p.z) += far;
        q.push_back(p);
        break;
      }
      default: {  // far outside in a random direction
        const Vec3 d = Normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5 + 1e-9});
        q.push_back(lo + size * 0.5 + d * (scale * (2 + 1000 * u(rng))));
      }
    }
  }
  return q;
}

// Checks snap and next against brute force; next with step directions along +-X, +-Y, +-Z and
// random directions, at step lengths relative to the terrain's spacing and size.
void CheckAgainstBruteForce(const TerrainGrid& g, int count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  const BruteForce oracle(g);
  const std::vector<Vec3> points = QueryPoints(g, rng, count);
  const GridStats& st = g.stats();
  const Vec3 size = st.bounds_max - st.bounds_min;
  const double scale = std::max({size.x, size.y, size.z, 1e-3});
  const Vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::uniform_real_distribution<double> u(0, 1);
  size_t found = 0;
  std::vector<StepQuery> steps;  // the next queries, for the batch check
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    RequireSame(g.Snap(p), oracle.Snap(p), "snap at " + Describe(p));
    const double length = scale * (i % 3 == 0 ? 0.01 : i % 3 == 1 ? 0.1 : 0.5) * (0.5 + u(rng));
    Vec3 dir = i % 2 ? axes[(i / 2) % 6]
                     : Normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5 + 1e-9});
    dir = dir * length;
    const double tolerance = i % 5 == 0 ? length * 0.3 : 0;
    const StepQuery q{p, dir};
    steps.push_back(q);
    if (i % 5 == 0) {  // a traced query (the viewer's) takes the general search: same answers
      QueryTrace trace;
      RequireSame(g.Snap(p, &trace), g.Snap(p), "traced snap at " + Describe(p));
      RequireSame(g.Next(q, tolerance, &trace), g.Next(q, tolerance),
                  "traced next from " + Describe(p));
    }
    const Foothold a = g.Next(q, tolerance);
    found += a.status == Status::kOk;
    RequireSame(a, oracle.Next(q, tolerance),
                "next from " + Describe(p) + " along " + Describe(dir) + " tol " +
                    std::to_string(tolerance));
  }
  // The query mix must exercise both outcomes of next.
  CHECK(found > 0);
  // Batches give the same answers, in the given order and in a spatially sorted order, on one
  // and two threads, with invalid queries among valid ones.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (size_t i = 0; i < steps.size(); i += 97) steps[i].direction = {0, 0, 0};
  for (size_t i = 50; i < steps.size(); i += 89) steps[i].foot.y = nan;
  for (int threads : {1, 2}) {
    BatchPool pool(threads);
    std::vector<Foothold> answers(steps.size());
    g.NextBatch(steps.data(), steps.size(), 0, answers.data(), threads > 1 ? &pool : nullptr);
    for (size_t i = 0; i < steps.size(); ++i)
      RequireSame(
          answers[i], oracle.Next(steps[i], 0),
          "batch next from " + Describe(steps[i].foot) + " along " + Describe(steps[i].direction));
  }
  const std::vector<Vec3> points_with_invalid = [&] {
    std::vector<Vec3> v = points;
    for (size_t i = 30; i < v.size(); i += 83) v[i].z = nan;
    return v;
  }();
  std::vector<Vec3> sorted = points;
  std::sort(sorted.begin(), sorted.end(), [](const Vec3& a, const Vec3& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  });
  for (const std::vector<Vec3>* batch :
       {&points_with_invalid, static_cast<const std::vector<Vec3>*>(&sorted)}) {
    for (int threads : {1, 2}) {
      BatchPool pool(threads);
      std::vector<Foothold> answers(batch->size());
      g.SnapBatch(batch->data(), batch->size(), answers.data(), threads > 1 ? &pool : nullptr);
      for (size_t i = 0; i < batch->size(); ++i)
        RequireSame(answers[i], oracle.Snap((*batch)[i]), "batch snap at " + Describe((*batch)[i]));
    }
  }
}

}  // namespace

TEST_CASE("TerrainGrid answers exactly as brute force", "[terrain][grid]") {
  SECTION("on a height field") {
    CheckAgainstBruteForce(Build(MakeHeightField(80, 60, 0.5, 3, 7)), 3000, 1);
  }
  SECTION("on a sphere") {
    CheckAgainstBruteForce(Build(MakeSphere(5000, {1, 2, 3}, 10)), 3000, 2);
  }
  SECTION("in a room with walls and a ceiling") {
    CheckAgainstBruteForce(Build(MakeRoom({20, 8, 12}, 0.5)), 3000, 3);
  }
  SECTION("on stairs") {
    CheckAgainstBruteForce(Build(MakeStairs(12, 0.2, 0.3, 2, 0.05)), 3000, 4);
  }
  SECTION("on a perfectly flat square") {
    CheckAgainstBruteForce(Build(MakeFlat(60, 0.25, 1.5)), 3000, 5);
  }
  SECTION("on a ramp") { CheckAgainstBruteForce(Build(MakeRamp(40, 40, 0.25, 35)), 2000, 6); }
  SECTION("on a line of samples") {
    RawSamples s;
    for (int i = 0; i < 2000; ++i) s.push_back({0.01 * i, 0, 0}, {0, 1, 0});
    CheckAgainstBruteForce(Build(s), 2000, 7);
  }
  SECTION("in a cloud of random points (sparse cells: nearest samples one to three cells away)") {
    std::mt19937_64 rng(10);
    std::uniform_real_distribution<double> u(-5, 5);
    RawSamples s;
    for (int i = 0; i < 3000; ++i) s.push_back({u(rng), 0.3 * u(rng), u(rng)}, {0, 1, 0});
    CheckAgainstBruteForce(Build(s), 3000, 11);
  }
  SECTION("through the volume around a height field (nearest samples cells away)") {
    // Points well above and below the surface: the ball of the query's own cell often reaches
    // two or more cells away, and sometimes the answer lies there. The field is turned to face
    // each axis in turn, so that those cells lie along every axis.
    const RawSamples field = MakeHeightField(80, 60, 0.5, 3, 7);
    for (int up = 0; up < 3; ++up) {
      RawSamples s;
      auto turn = [up](const Vec3& v) {
        return up == 0 ? Vec3{v.y, v.z, v.x} : up == 1 ? v : Vec3{v.x, v.z, v.y};
      };
      for (size_t i = 0; i < field.size(); ++i)
        s.push_back(turn(field.points[i]), turn(field.normals[i]));
      const TerrainGrid g = Build(s);
      const BruteForce oracle(g);
      const GridStats& st = g.stats();
      std::mt19937_64 rng(12 + up);
      std::uniform_real_distribution<double> u(-0.1, 1.1);
      for (int i = 0; i < 30000; ++i) {
        const Vec3& lo = st.bounds_min;
        const Vec3 size = st.bounds_max - st.bounds_min;
        const Vec3 p{lo.x + size.x * u(rng), lo.y + size.y * u(rng), lo.z + size.z * u(rng)};
        RequireSame(g.Snap(p), oracle.Snap(p), "snap at " + Describe(p));
      }
    }
  }
  SECTION("on a single sample") {
    RawSamples s;
    s.push_back({3, -2, 5}, {0, 0, 2});
    CheckAgainstBruteForce(Build(s), 500, 8);
  }
  SECTION("with duplicated samples (ties go to the lowest index)") {
    RawSamples s = MakeFlat(20, 1, 0);
    const size_t n = s.size();
    for (size_t i = 0; i < n; ++i) s.push_back(s.points[i], {0, 1, 1});  // same points, new normals
    const TerrainGrid g = Build(s);
    CheckAgainstBruteForce(g, 2000, 9);
    for (size_t i = 0; i < n; i += 37) REQUIRE(g.Snap(s.points[i]).index == i);
  }
  SECTION("with a few far outliers") {
    RawSamples s = MakeHeightField(60, 60, 0.5, 2, 11);
    s.push_back({1e6, 0, 0}, {0, 1, 0});
    s.push_back({0, -5e5, 0}, {0, 1, 0});
    s.push_back({0, 0, 3e5}, {1, 1, 0});
    const TerrainGrid g = Build(s);
    CheckAgainstBruteForce(g, 3000, 10);
    // The outliers do not stretch the cells: the bulk still gets a fine grid.
    CHECK(g.stats().cell_size < 5);
    // Stored as float offsets from the bulk's centre: the outlier 1e6 away moves by up to
    // 2^-5 (float spacing there), and the grid says so.
    CHECK(g.stats().max_rounding > 0);
    CHECK(g.stats().max_rounding <= 0.04);
    const Foothold far = g.Snap({1e6, 0, 0});
    REQUIRE(far.status == Status::kOk);
    CHECK(far.index == s.size() - 3);
    CHECK(Distance(far.point, {1e6, 0, 0}) <= g.stats().max_rounding);
    // Samples on a float grid near the centre are kept exactly.
    RawSamples exact;
    for (int i = 0; i < 8; ++i) exact.push_back({i * 0.5, 0, (i % 3) * 0.25}, {0, 1, 0});
    CHECK(Build(exact).stats().max_rounding == 0);
    // Offsets too small for a float (1e-300 apart) are stored as the centre: said, not hidden.
    RawSamples tiny;
    for (int i = 0; i < 4; ++i) tiny.push_back({i * 1e-300, 0, (i % 2) * 1e-300}, {0, 1, 0});
    const double rounding = Build(tiny).stats().max_rounding;
    CHECK(rounding >= 1e-300);
    CHECK(rounding <= 3e-300);
  }
  SECTION("with an outlier a trillion units away, queries stay local") {
    // The cells' pad was sized by every sample's bounds: one outlier 1e12 away padded each
    // cell by a thousand units, and every query scanned every cell (slower than brute force).
    RawSamples s = MakeHeightField(60, 60, 0.5, 2, 11);
    s.push_back({1e12, 1e12, 1e12}, {0, 1, 0});
    const TerrainGrid g = Build(s);
    CheckAgainstBruteForce(g, 2000, 14);
    QueryTrace trace;
    const Foothold near = g.Snap({15, 1, 15}, &trace);
    REQUIRE(near.status == Status::kOk);
    INFO("cells scanned " << trace.cells.size() << " of " << g.stats().occupied_cells);
    CHECK(trace.cells.size() <= 27);
    QueryTrace next_trace;
    g.Next({{15, 1, 15}, {1, 0, 0}}, 0, &next_trace);
    CHECK(next_trace.cells.size() <= 64);
  }
  SECTION("with a few far outliers where a fixed-stride subsample would pick them all") {
    // A 1e-4 lattice near 1e5 with strays at the origin: kept in the grid's box, they moved
    // its centre 5e4 away, whose float offsets (spacing 0.004) merged the lattice. Strays one
    // every n / 4096 samples (0.15%) were all in the subsample the box was chosen from, and a
    // terrain of up to 100 samples kept any outlier.
    for (const int side : {200, 10, 8, 4, 3, 2}) {
      INFO(side * side << " lattice samples");
      RawSamples s;
      for (int k = 0; k < side; ++k)
        for (int i = 0; i < side; ++i)
          s.push_back({1e5 + i * 1e-4, 1e5, 1e5 + k * 1e-4}, {0, 1, 0});
      if (side == 2) s.push_back({1e5 + 2e-4, 1e5, 1e5}, {0, 1, 0});  // 5 samples, 4 kept
      std::vector<bool> stray(s.size(), false);
      if (side == 200) {
        for (size_t i = 0; i < 60; ++i) stray[i * s.size() / 4096] = true;
      } else {
        stray[s.size() / 2] = true;
      }
      for (size_t i = 0; i < s.size(); ++i)
        if (stray[i]) s.points[i] = {0, 0, 0};
      const TerrainGrid g = Build(s);
      CHECK(g.stats().cell_size < 1e-2);
      size_t own = 0, kept = 0;
      for (size_t i = 0; i < s.size(); ++i) {
        if (stray[i]) continue;
        ++kept;
        own += g.Snap(s.points[i]).index == i;  // each lattice sample stays apart
      }
      CHECK(own == kept);
      CheckAgainstBruteForce(g, 500, 18);
    }
  }
  SECTION("with a few samples far apart, none of them an outlier") {
    // Three in a line or a cross of five: trimmed as if all but the middle one were outliers,
    // they had a box of no size, cells of 1 and a spacing made up, whatever their scale.
    for (const double scale : {0.001, 100.0, 1000.0}) {
      INFO("samples " << scale << " apart");
      RawSamples line, cross;
      for (int i = 0; i < 3; ++i) line.push_back({i * scale, 0, 0}, {0, 1, 0});
      for (const auto& [x, z] : {std::pair{0, 0}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}})
        cross.push_back({x * scale, 0, z * scale}, {0, 1, 0});
      for (const RawSamples* s : {&line, &cross}) {
        const TerrainGrid g = Build(*s);
        CHECK(g.stats().cell_size > 0.05 * scale);
        CHECK(g.stats().cell_size < 2 * scale);
        CHECK(g.stats().grid_max.x - g.stats().grid_min.x >= 1.999 * scale);  // all of them
        CheckAgainstBruteForce(g, 200, 19);
      }
    }
  }
  SECTION("with huge coordinates (near 1e5)") {
    RawSamples s = MakeHeightField(60, 60, 0.5, 2, 12);
    for (auto& p : s.points) p = p + Vec3{1e5, 1e5, -1e5};
    CheckAgainstBruteForce(Build(s), 3000, 13);
  }
  SECTION("with tiny spacing (1e-4)") {
    CheckAgainstBruteForce(Build(MakeHeightField(60, 60, 1e-4, 2e-4, 14)), 3000, 15);
  }
  SECTION("with tiny spacing at huge coordinates") {
    RawSamples s = MakeHeightField(40, 40, 1e-3, 1e-3, 16);
    for (auto& p : s.points) p = p + Vec3{1e5, 0, 1e5};
    CheckAgainstBruteForce(Build(s), 2000, 17);
  }
}

TEST_CASE("The portable cell scan answers as the AVX2 one and as brute force", "[terrain][grid]") {
  // Grids scan with AVX2 when the CPU has it; the portable path serves every other CPU.
  if (!CpuHasAvx2()) WARN("this CPU has no AVX2: both grids below take the portable path");
  GridOptions portable;
  portable.use_avx2 = false;
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(-5, 5);
  RawSamples cloud;
  for (int i = 0; i < 3000; ++i) cloud.push_back({u(rng), 0.3 * u(rng), u(rng)}, {0, 1, 0});
  int seed = 30;
  for (const RawSamples& s : {MakeHeightField(80, 60, 0.5, 3, 7), MakeSphere(5000, {1, 2, 3}, 10),
                              MakeStairs(12, 0.2, 0.3, 2, 0.05), cloud}) {
    const TerrainGrid g = Build(s, portable), fast = Build(s);
    CheckAgainstBruteForce(g, 2000, ++seed);
    const GridStats& st = g.stats();
    const Vec3 size = st.bounds_max - st.bounds_min;
    std::uniform_real_distribution<double> t(-0.2, 1.2);
    for (int i = 0; i < 20000; ++i) {
      const Vec3 p{st.bounds_min.x + size.x * t(rng), st.bounds_min.y + size.y * t(rng),
                   st.bounds_min.z + size.z * t(rng)};
      RequireSame(g.Snap(p), fast.Snap(p), "snap at " + Describe(p));
      const StepQuery q{p, Vec3{t(rng) - 0.5, t(rng) - 0.5, t(rng) - 0.5} * size.x};
      RequireSame(g.Next(q, 0), fast.Next(q, 0), "next from " + Describe(p));
    }
  }
}

TEST_CASE("TerrainGrid answers very far queries exactly, and refuses absurd ones",
          "[terrain][grid]") {
  const TerrainGrid g = Build(MakeHeightField(120, 120, 0.1, 0.3, 21));
  const BruteForce oracle(g);
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double distance : {1e4, 1e6, 1e9, 1e12, 1e14}) {
    for (int i = 0; i < 40; ++i) {
      const Vec3 q = Normalize(Vec3{u(rng), u(rng), u(rng)}) * distance;
      RequireSame(g.Snap(q), oracle.Snap(q), "snap at " + Describe(q));
      const StepQuery step{q, Vec3{u(rng), u(rng), u(rng)} * distance};
      RequireSame(g.Next(step, 0), oracle.Next(step, 0), "next from " + Describe(q));
    }
  }
  for (const Vec3& q : {Vec3{2e15, 0, 0}, Vec3{0, -1e300, 0}, Vec3{1e308, 1e308, 1e308}}) {
    CHECK(g.Snap(q).status == Status::kInvalidArgument);
    CHECK(oracle.Snap(q).status == Status::kInvalidArgument);
    CHECK(g.Next({Vec3{}, q}, 0).status == Status::kInvalidArgument);
  }
}

TEST_CASE("TerrainGrid next follows the candidate rules", "[terrain][grid]") {
  const TerrainGrid g = Build(MakeFlat(21, 1, 0));  // samples at integer x, z in [0, 20]
  SECTION("the ideal point's sample is chosen") {
    const Foothold f = g.Next({{5, 0, 5}, {0, 0, 3}}, 0);
    REQUIRE(f.status == Status::kOk);
    CHECK(f.point == Vec3{5, 0, 8});
    CHECK(f.normal == Vec3{0, 1, 0});
  }
  SECTION("samples behind or beside the foot are never candidates") {
    // From the +Z edge walking on: the only samples within one step are behind or level.
    const Foothold f = g.Next({{5, 0, 20}, {0, 0, 3}}, 0);
    CHECK(f.status == Status::kNoFoothold);
  }
  SECTION("the tolerance bounds the candidate radius") {
    // Ideal point (5, 0, 23.5) is 3.5 beyond the edge: no sample within 1, one within 4.
    CHECK(g.Next({{5, 0, 20.5}, {0, 0, 3}}, 1).status == Status::kNoFoothold);
    CHECK(g.Next({{5, 0, 19.5}, {0, 0, 4}}, 4).status == Status::kOk);
  }
  SECTION("a zero or non-finite direction is an error") {
    CHECK(g.Next({{5, 0, 5}, {0, 0, 0}}, 0).status == Status::kInvalidArgument);
    CHECK(g.Next({{5, 0, 5}, {0, NAN, 1}}, 0).status == Status::kInvalidArgument);
    CHECK(g.Next({{5, 0, INFINITY}, {0, 0, 1}}, 0).status == Status::kInvalidArgument);
    CHECK(g.Snap({NAN, 0, 0}).status == Status::kInvalidArgument);
  }
  SECTION("a direction too small to square is not zero") {
    // |d|^2 underflows to 0: it was refused as a zero direction. With a tolerance the nearest
    // sample ahead within it is the answer; without, only a sample at the ideal point would be.
    const Foothold f = g.Next({{5, 0, 5}, {1e-170, 0, 0}}, 2);
    REQUIRE(f.status == Status::kOk);
    CHECK(f.point == Vec3{6, 0, 5});
    CHECK(g.Next({{5, 0, 5}, {1e-170, 0, 0}}, 0).status == Status::kNoFoothold);
    CHECK(g.Next({{5, 0, 5}, {0, -1e-300, 0}}, 0).status == Status::kNoFoothold);
  }
}

TEST_CASE("TerrainGrid next never answers a point level with the foot by the caller's arithmetic",
          "[terrain][grid]") {
  // Far from the world origin (here across x = 2^17, where doubles change their step), a stored
  // point's world position, origin + its float offset, rounds. From a foot placed exactly on
  // such a reported point the sample itself lies level with the foot (dot 0), but its local
  // offset and the foot's differed by that rounding: it was answered as ahead of itself.
  RawSamples s;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.9, 0.9);
  for (int i = 0; i < 40; ++i) {
    for (int k = 0; k < 40; ++k) {
      s.points.push_back({131072.0 + 3 * i - 60.1 + u(rng), 50.3 + u(rng), -65536.7 + 3 * k});
      s.normals.push_back({0, 1, 0});
    }
  }
  const TerrainGrid g = Build(s);
  const BruteForce oracle(g);
  int answered = 0, checked = 0;
  g.ForEachSample([&](uint32_t index, const Vec3& w, const Vec3&) {
    for (const Vec3& d : {Vec3{0.5, 0, 0}, Vec3{-0.5, 0, 0}, Vec3{0, 0.5, 0}, Vec3{0, -0.5, 0},
                          Vec3{0, 0, 0.5}, Vec3{0, 0, -0.5}, Vec3{0.3, 0.2, -0.3}}) {
      const StepQuery q{w, d};
      const Foothold f = g.Next(q, 1.0);
      RequireSame(f, oracle.Next(q, 1.0), "brute force");
      ++checked;
      if (f.status != Status::kOk) continue;
      ++answered;
      INFO("foot on sample " << index << " at " << Describe(w) << " along " << Describe(d)
                             << ": answer " << f.index);
      REQUIRE(Dot(f.point - w, d) > 0);
    }
  });
  CHECK(checked == 1600 * 7);
  CHECK(answered > 0);  // some neighbours come within reach
}

TEST_CASE("TerrainGrid next with a tolerance as large as the terrain", "[terrain][grid]") {
  // 200 x 200 samples, 0.1 apart: steps from every edge outward and inward, from inside and
  // from beyond the bounds, with tolerances from a step to far beyond the terrain.
  const TerrainGrid g = Build(MakeHeightField(200, 200, 0.1, 0.3, 31));
  const BruteForce oracle(g);
  const GridStats& st = g.stats();
  const Vec3 lo = st.bounds_min, hi = st.bounds_max, mid = (lo + hi) * 0.5;
  std::vector<StepQuery> steps;
  for (double along : {-0.5, 0.0, 0.5}) {
    for (double t : {-1.0, -0.2, 0.0, 0.3, 1.0, 2.0}) {
      const Vec3 x_edge{hi.x + t, mid.y, mid.z + along * (hi.z - lo.z)};
      const Vec3 z_edge{mid.x + along * (hi.x - lo.x), mid.y, lo.z - t};
      for (double sign : {1.0, -1.0}) {
        steps.push_back({x_edge, {0.6 * sign, 0, 0}});
        steps.push_back({z_edge, {0, 0.1 * sign, -0.6 * sign}});
      }
    }
  }
  for (const StepQuery& q : steps) {
    for (double tolerance : {0.0, 1.0, 10.0, 1e3, 1e6}) {
      RequireSame(g.Next(q, tolerance), oracle.Next(q, tolerance),
                  "next from " + Describe(q.foot) + " along " + Describe(q.direction) +
                      " tolerance " + std::to_string(tolerance));
    }
    // Tolerances whose square overflows are as unbounded as 1e6 is here (they were invalid).
    for (double tolerance : {1e155, 1e300, std::numeric_limits<double>::max()}) {
      RequireSame(g.Next(q, tolerance), g.Next(q, 1e6), "tolerance " + std::to_string(tolerance));
      RequireSame(oracle.Next(q, tolerance), g.Next(q, 1e6), "brute force");
    }
  }
  // Walking off the +X edge with a huge tolerance: every sample is behind the foot, and only the
  // cells the foot's plane crosses are scanned. (How long the search takes is measured by
  // bench/terrain_bench, BM_GridNextNoCandidate.)
  QueryTrace trace;
  const Foothold f = g.Next({{hi.x, mid.y, mid.z}, {0.6, 0, 0}}, 1e6, &trace);
  CHECK(f.status == Status::kNoFoothold);
  const size_t cells = size_t{st.cells[0]} * st.cells[1] * st.cells[2];
  INFO("cells scanned " << trace.cells.size() << " of " << cells);
  CHECK(trace.cells.size() * 10 < cells);
  CHECK(trace.candidates.empty());
}

TEST_CASE("TerrainGrid next from flat ground straight up skips blocks level with the foot",
          "[terrain][grid]") {
  // Flat ground at y = 0 (and a tilted plane): a foot on it stepping up, or up and a little
  // along, with tolerances up to beyond the terrain. Straight up from the flat ground no
  // sample is ahead (level with the foot is not ahead): every block is skipped from its tight
  // bounds (the padded ones kept them all, and each query scanned every sample).
  const TerrainGrid flat = Build(MakeFlat(200, 0.1, 0));
  RawSamples plane;  // rising 0.3 along x
  for (int i = 0; i < 200; ++i)
    for (int k = 0; k < 200; ++k) {
      plane.points.push_back({0.1 * i, 0.03 * i, 0.1 * k});
      plane.normals.push_back({-0.3, 1, 0});
    }
  const TerrainGrid tilted = Build(plane);
  for (const TerrainGrid* g : {&flat, &tilted}) {
    const BruteForce oracle(*g);
    const GridStats& st = g->stats();
    const Vec3 mid = (st.bounds_min + st.bounds_max) * 0.5;
    for (const Vec3& dir : {Vec3{0, 0.5, 0}, Vec3{0, -0.5, 0}, Vec3{1e-9, 0.5, 0},
                            Vec3{0.001, 0.5, -0.002}, Vec3{0.5, 0.5, 0}}) {
      for (const Vec3& foot : {Vec3{mid.x, 0, mid.z}, Vec3{st.bounds_min.x, 0, mid.z},
                               Vec3{mid.x + 0.05, 0, mid.z + 0.05}}) {
        const Vec3 on = g->Snap(foot).point;
        for (double tolerance : {0.0, 10.0, 1e4}) {
          RequireSame(g->Next({on, dir}, tolerance), oracle.Next({on, dir}, tolerance),
                      "next from " + Describe(on) + " along " + Describe(dir) + " tolerance " +
                          std::to_string(tolerance));
        }
      }
    }
  }
  const GridStats& st = flat.stats();
  QueryTrace trace;
  const Vec3 mid = (st.bounds_min + st.bounds_max) * 0.5;
  const Foothold f = flat.Next({flat.Snap({mid.x, 0, mid.z}).point, {0, 0.5, 0}}, 1e4, &trace);
  CHECK(f.status == Status::kNoFoothold);
  INFO("samples examined " << trace.examined_samples.size() << " of " << st.samples);
  CHECK(trace.examined_samples.size() * 10 < st.samples);
}

TEST_CASE("TerrainGrid reports its samples' spacing whatever its cells hold", "[terrain][grid]") {
  struct Case {
    RawSamples samples;
    double spacing;  // as generated
  };
  const Case cases[] = {{MakeFlat(200, 0.25, 3), 0.25},
                        {MakeHills(300, 0.02, 0.5, 7), 0.02},
                        {MakeRamp(150, 120, 0.5, 30), 0.5}};
  for (const Case& c : cases) {
    double first = 0;
    for (const double per_cell : {4.0, 12.0, 24.0, 60.0}) {
      GridOptions options;
      options.samples_per_cell = per_cell;
      const TerrainGrid g = Build(c.samples, options);
      INFO("generated every " << c.spacing << ", " << per_cell << " samples per cell");
      // Along the ground: slopes and hills spread it a little; a leaning surface reads a little
      // small (slivers of cells it barely crosses often hold no sample).
      CHECK(g.stats().spacing > 0.9 * c.spacing);
      CHECK(g.stats().spacing < 1.3 * c.spacing);
      if (first == 0) first = g.stats().spacing;
      CHECK(g.stats().spacing == first);
    }
  }
  CHECK(Build(RawSamples{}).stats().spacing == 0);
}

TEST_CASE("TerrainGrid reports the spacing of a few samples sample to sample", "[terrain][grid]") {
  // Too few samples to fill the cells the spacing is measured on: two samples 1 m apart read
  // 0.07, the size of the cells that stopped growing.
  auto lattice = [](int nx, int nz, double step, const Vec3& at) {
    RawSamples s;
    for (int i = 0; i < nx; ++i)
      for (int k = 0; k < nz; ++k) s.push_back(at + Vec3{i * step, 0, k * step}, {0, 1, 0});
    return s;
  };
  CHECK(Build(lattice(2, 1, 1.0, {})).stats().spacing == Approx(1.0));
  CHECK(Build(lattice(3, 3, 0.5, {})).stats().spacing == Approx(0.5));
  CHECK(Build(lattice(3, 13, 0.25, {1e5, -3, 1e5})).stats().spacing == Approx(0.25));  // 39
  // A sample given twice is measured to its nearest other place, not to its copy.
  RawSamples twice = lattice(4, 1, 2.0, {});
  twice.push_back({0, 0, 0}, {0, 1, 0});
  CHECK(Build(twice).stats().spacing == Approx(2.0));
  // One place holds them all: no distance to measure; a spacing all the same (callers size
  // their checks by it).
  RawSamples one_place = lattice(1, 1, 1.0, {3, 4, 5});
  one_place.push_back({3, 4, 5}, {0, 1, 0});
  CHECK(Build(one_place).stats().spacing > 0);
  // From kDirectSpacingSamples on, as a surface (the lattice of 40 within 10% of its step).
  const double forty = Build(lattice(4, 10, 0.25, {})).stats().spacing;
  CHECK(forty > 0.225);
  CHECK(forty < 0.275);
}

TEST_CASE("TerrainGrid reports the same spacing however its terrain is turned", "[terrain][grid]") {
  // Occupied cells alone counted a leaning surface as sparser: the same hills turned 37 degrees
  // read 8 to 15% wider apart, and walks (whose swing arcs are checked by the spacing) differed.
  const Vec3 axis = Normalize(Vec3{1, 2, 3});
  for (const double degrees : {20.0, 37.0, 45.0, 90.0}) {
    const double a = degrees * 3.14159265358979323846 / 180;
    auto turn = [&](const Vec3& v) {  // Rodrigues' rotation about `axis`
      return v * std::cos(a) + Cross(axis, v) * std::sin(a) +
             axis * (Dot(axis, v) * (1 - std::cos(a)));
    };
    for (const RawSamples& samples :
         {MakeHills(300, 0.02, 0.5, 7), MakeRamp(150, 120, 0.5, 30), MakeFlat(200, 0.25, 3)}) {
      RawSamples turned;
      for (size_t i = 0; i < samples.size(); ++i)
        turned.push_back(turn(samples.points[i]), turn(samples.normals[i]));
      const double spacing = Build(samples).stats().spacing;
      const double turned_spacing = Build(turned).stats().spacing;
      INFO(degrees << " degrees: " << spacing << " and turned " << turned_spacing);
      CHECK(std::fabs(turned_spacing / spacing - 1) < 0.03);
    }
  }
}

TEST_CASE("TerrainGrid keeps memory bounded", "[terrain][grid]") {
  SECTION("an empty grid answers no foothold") {
    TerrainGrid g;
    std::string error;
    REQUIRE(TerrainGrid::Build(RawSamples{}, GridOptions{}, &g, &error) == Status::kOk);
    CHECK(g.Snap({0, 0, 0}).status == Status::kNoFoothold);
  }
  SECTION("cells and bytes stay within 0.95 cells and 32 bytes per sample whatever the shape") {
    // A plane across the diagonal of a cube: a surface whose cells hit the cap.
    RawSamples diagonal;
    std::mt19937_64 rng(41);
    std::uniform_real_distribution<double> u(0, 10);
    while (diagonal.size() < 20000) {
      const double x = u(rng), y = u(rng), z = 15 - x - y;
      if (z < 0 || z > 10) continue;
      diagonal.points.push_back({x, y, z});
      diagonal.normals.push_back({1, 1, 1});
    }
    const RawSamples shapes[] = {MakeSphere(20000, {0, 0, 0}, 100),
                                 MakeHeightField(150, 150, 0.1, 40, 3),
                                 MakeRoom({100, 1, 100}, 0.5), diagonal};
    for (const RawSamples& s : shapes) {
      const TerrainGrid g = Build(s);
      const GridStats& st = g.stats();
      const double cells = double(st.cells[0]) * st.cells[1] * st.cells[2];
      CHECK(cells <= std::max(64.0, 0.95 * s.size()));
      CHECK(st.bytes <= 32 * s.size());
      if (&s == &shapes[3]) CHECK(cells > 0.85 * s.size());  // the cap binds here
    }
  }
  SECTION("grids move but do not copy") {
    STATIC_REQUIRE(!std::is_copy_constructible<TerrainGrid>::value);
    STATIC_REQUIRE(std::is_nothrow_move_constructible<TerrainGrid>::value);
    TerrainGrid a = Build(MakeFlat(10, 1, 0));
    TerrainGrid b = std::move(a);
    CHECK(b.size() == 100);
    CHECK(b.Snap({3.2, 0, 4.9}).point == Vec3{3, 0, 5});
  }
}
