#include "footfall/import/mesh_sampler.h"

#include <cmath>

#include "footfall/import/mesh_generators.h"
#include "footfall/import/terrain_loader.h"
#include "footfall/terrain/grid.h"
#include "test_support.h"

namespace footfall {
namespace {

double Diagonal(const TriangleMesh& mesh) {
  Vec3 lo, hi;
  MeshBounds(mesh, &lo, &hi);
  return Distance(lo, hi);
}

RawSamples Sample(const TriangleMesh& mesh, double s, bool smooth = true, uint64_t seed = 1) {
  MeshSampleOptions o;
  o.separation = s, o.smooth_normals = smooth, o.seed = seed;
  RawSamples out;
  std::string error;
  REQUIRE(SampleMesh(mesh, o, &out, &error) == Status::kOk);
  REQUIRE(out.size() > 0);
  return out;
}

// Largest distance from `probes` to their nearest sample (brute force via the exact grid).
double LargestGap(const RawSamples& samples, const RawSamples& probes) {
  TerrainGrid grid;
  std::string error;
  REQUIRE(TerrainGrid::Build(samples, GridOptions{}, &grid, &error) == Status::kOk);
  double gap = 0;
  for (const Vec3& p : probes.points) gap = std::max(gap, Distance(p, grid.Snap(p).point));
  return gap;
}

TriangleMesh Square(double size) {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {size, 0, 0}, {size, 0, size}, {0, 0, size}};
  m.triangles = {{0, 2, 1}, {0, 3, 2}};
  return m;
}

}  // namespace

TEST_CASE("SampleMesh: samples lie on the mesh", "[import][sampler]") {
  const TriangleMesh meshes[] = {MakeSphereMesh({1, 2, 3}, 2.0, 3), MakeRocksMesh(20, 0.5, 1.5, 3),
                                 MakeBlocksMesh(6, 6, 3, 5)};
  for (const TriangleMesh& mesh : meshes) {
    const RawSamples s = Sample(mesh, 0.3);
    const double limit = 1e-5 * Diagonal(mesh);
    double worst = 0;
    for (const Vec3& p : s.points) worst = std::max(worst, test::DistanceToMesh(mesh, p));
    CHECK(worst < limit);
  }
}

TEST_CASE("SampleMesh: no surface point is farther than the separation from a sample",
          "[import][sampler]") {
  const TriangleMesh meshes[] = {MakeSphereMesh({0, 0, 0}, 2.0, 3), MakeRocksMesh(30, 0.3, 1.0, 9),
                                 MakeBlocksMesh(5, 5, 3, 2), MakeRampsMesh({15, -30, 45}, 2, 1.5)};
  for (const TriangleMesh& mesh : meshes) {
    for (double s : {0.2, 0.45}) {
      const RawSamples samples = Sample(mesh, s);
      RawSamples probes;
      SampleMeshUniform(mesh, 20000, true, kDefaultCreaseAngleDeg, 77, &probes);
      // The vertices are the hardest points to reach (corners of the surface).
      for (const Vec3& v : mesh.vertices) probes.push_back(v, {0, 1, 0});
      CHECK(LargestGap(samples, probes) <= s * (1 + 1e-5));
    }
  }
}

TEST_CASE("SampleMesh: both faces of a slab thinner than the separation are covered",
          "[import][sampler]") {
  // A floor modelled as a closed box 2 x 2, s / 4 thick (outward winding). Pieces of the top
  // and the bottom lie closer than the minimum distance: they thinned each other out, leaving
  // each face with gaps of 1.5-2.3 s, so that a foot on the top snapped to the underside.
  const double s = 0.1, t = s / 4, l = 2;
  TriangleMesh box;
  for (int i = 0; i < 8; ++i)
    box.vertices.push_back({i & 1 ? l : 0, i & 2 ? 0.0 : -t, i & 4 ? l : 0});
  // Faces as quads (outward), each split in two.
  const int quads[6][4] = {{2, 6, 7, 3}, {0, 1, 5, 4}, {0, 2, 3, 1},
                           {4, 5, 7, 6}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    box.triangles.push_back(
        {static_cast<uint32_t>(q[0]), static_cast<uint32_t>(q[1]), static_cast<uint32_t>(q[2])});
    box.triangles.push_back(
        {static_cast<uint32_t>(q[0]), static_cast<uint32_t>(q[2]), static_cast<uint32_t>(q[3])});
  }
  const RawSamples samples = Sample(box, s, false);
  for (double side : {1.0, -1.0}) {
    INFO((side > 0 ? "top" : "bottom"));
    RawSamples own, probes;
    for (size_t i = 0; i < samples.size(); ++i)
      if (samples.normals[i].y * side > 0.5) own.push_back(samples.points[i], samples.normals[i]);
    for (int i = 0; i <= 80; ++i)
      for (int k = 0; k <= 80; ++k)
        probes.push_back({l * i / 80, side > 0 ? 0 : -t, l * k / 80}, {0, side, 0});
    REQUIRE(own.size() > 0);
    CHECK(LargestGap(own, probes) <= s * (1 + 1e-5));
  }
}

TEST_CASE("SampleMesh: a vertex no face uses does not widen the mesh", "[import][sampler]") {
  // A 1 m square and a stray vertex 1e7 away: a separation of 0.001 was refused as too small
  // for the mesh's extent.
  TriangleMesh m = Square(1);
  m.vertices.push_back({1e7, 0, 1e7});
  Vec3 lo, hi;
  MeshBounds(m, &lo, &hi);
  CHECK(hi == Vec3{1, 0, 1});
  CHECK(Sample(m, 0.01).size() > 10000);
}

TEST_CASE("SampleMesh: samples do not clump", "[import][sampler]") {
  const TriangleMesh mesh = MakeRocksMesh(10, 0.4, 0.8, 4);
  const double s = 0.25;
  const RawSamples samples = Sample(mesh, s);
  double closest = 1e9;
  for (size_t i = 0; i < samples.size(); ++i) {
    for (size_t j = i + 1; j < samples.size(); ++j) {
      closest = std::min(closest, Distance(samples.points[i], samples.points[j]));
    }
  }
  CHECK(closest >= 2 * s / 3 * (1 - 1e-5));
}

TEST_CASE("SampleMesh: counts scale with area / s^2", "[import][sampler]") {
  SECTION("halving the separation about quadruples the count") {
    const TriangleMesh mesh = Square(10);
    const size_t coarse = Sample(mesh, 0.4).size(), fine = Sample(mesh, 0.2).size();
    const double ratio = static_cast<double>(fine) / coarse;
    CHECK(ratio > 3.6);
    CHECK(ratio < 4.4);
  }
  SECTION("doubling the area doubles the count; density is about 1.6 / s^2") {
    const double s = 0.3;
    const size_t one = Sample(Square(10), s).size();
    const size_t two = Sample(Square(10 * std::sqrt(2.0)), s).size();
    CHECK(static_cast<double>(two) / one == Approx(2).epsilon(0.08));
    const double density = one * s * s / 100.0;
    CHECK(density > 1.3);
    CHECK(density < 1.9);
  }
  SECTION("a mesh of many tiny triangles gets as many samples as a coarse one") {
    const size_t coarse = Sample(Square(8), 0.5).size();
    TriangleMesh fine = MakeRocksMesh(200, 8.0 / 200, 0.0, 1);  // flat, 80,000 triangles
    const size_t many = Sample(fine, 0.5).size();
    CHECK(static_cast<double>(many) / coarse == Approx(1).epsilon(0.1));
  }
}

TEST_CASE("SampleMesh: normals are unit and agree with the faces", "[import][sampler]") {
  const TriangleMesh sphere = MakeSphereMesh({0, 0, 0}, 2.0, 2);
  for (bool smooth : {true, false}) {
    const RawSamples s = Sample(sphere, 0.25, smooth);
    for (size_t i = 0; i < s.size(); ++i) {
      CHECK(Length(s.normals[i]) == Approx(1).epsilon(1e-9));
      size_t t = 0;
      test::DistanceToMesh(sphere, s.points[i], &t);
      const Vec3 face = Normalize(TriangleCross(sphere, t));
      CHECK(Dot(s.normals[i], face) > 0.9);
      if (!smooth) CHECK(Distance(s.normals[i], face) < 1e-12);
    }
  }
}

TEST_CASE("SampleMesh: smooth and flat normals differ where they should", "[import][sampler]") {
  SECTION("on a sphere smooth normals follow the radius more closely than face normals") {
    const TriangleMesh sphere = MakeSphereMesh({0, 0, 0}, 2.0, 2);
    const RawSamples smooth = Sample(sphere, 0.2, true), flat = Sample(sphere, 0.2, false);
    REQUIRE(smooth.points == flat.points);  // the normal rule does not move samples
    double smooth_error = 0, flat_error = 0, largest_difference = 0;
    for (size_t i = 0; i < smooth.size(); ++i) {
      const Vec3 radial = Normalize(smooth.points[i]);
      smooth_error += std::acos(std::min(1.0, Dot(smooth.normals[i], radial)));
      flat_error += std::acos(std::min(1.0, Dot(flat.normals[i], radial)));
      largest_difference =
          std::max(largest_difference, Distance(smooth.normals[i], flat.normals[i]));
    }
    CHECK(smooth_error < 0.5 * flat_error);
    CHECK(largest_difference > 0.05);
  }
  SECTION("on a plane they are equal") {
    const RawSamples smooth = Sample(Square(4), 0.3, true), flat = Sample(Square(4), 0.3, false);
    for (size_t i = 0; i < smooth.size(); ++i) {
      CHECK(Distance(smooth.normals[i], {0, 1, 0}) < 1e-12);
      CHECK(Distance(flat.normals[i], {0, 1, 0}) < 1e-12);
    }
  }
}

TEST_CASE("SampleMesh: deterministic for a seed", "[import][sampler]") {
  const TriangleMesh mesh = MakeRocksMesh(12, 0.5, 1.0, 2);
  const RawSamples a = Sample(mesh, 0.3, true, 5), b = Sample(mesh, 0.3, true, 5);
  const RawSamples c = Sample(mesh, 0.3, true, 6);
  CHECK(a.points == b.points);
  CHECK(a.normals == b.normals);
  CHECK(a.points != c.points);
}

TEST_CASE("SampleMesh: the same samples on any number of threads", "[import][sampler]") {
  // Steps 1 and 4 cut runs of triangles on threads of their own, joined in triangle order: about
  // 1.3 million pieces and 140,000 samples, enough for several threads in both.
  const TriangleMesh mesh = MakeRocksMesh(60, 0.5, 1.0, 3);
  auto sample = [&mesh](int threads, MeshSampleStats* stats) {
    MeshSampleOptions o;
    o.separation = 0.1, o.seed = 9, o.threads = threads;
    RawSamples out;
    std::string error;
    REQUIRE(SampleMesh(mesh, o, &out, &error, stats) == Status::kOk);
    return out;
  };
  MeshSampleStats one_stats;
  const RawSamples one = sample(1, &one_stats);
  REQUIRE(one_stats.candidates > 1000000);
  REQUIRE(one.size() > 100000);
  for (const int threads : {2, 3, 5}) {
    INFO(threads << " threads");
    MeshSampleStats stats;
    const RawSamples many = sample(threads, &stats);
    CHECK(stats.candidates == one_stats.candidates);
    CHECK(stats.samples == one_stats.samples);
    CHECK(many.points == one.points);
    CHECK(many.normals == one.normals);
  }
}

TEST_CASE("SampleMesh: bad options are refused", "[import][sampler]") {
  const TriangleMesh mesh = Square(10);
  MeshSampleOptions o;
  RawSamples out;
  std::string error;
  o.separation = 0;
  CHECK(SampleMesh(mesh, o, &out, &error) == Status::kInvalidArgument);
  CHECK(error.find("separation") != std::string::npos);
  o.separation = NAN;
  CHECK(SampleMesh(mesh, o, &out, &error) == Status::kInvalidArgument);
  o.separation = 1e-4;
  CHECK(SampleMesh(mesh, o, &out, &error) == Status::kLimitExceeded);
  CHECK(error ==
        "separation 0.0001 would give about 16000000000 samples (limit 20000000); choose a "
        "separation of at least 0.00283");
  // The separation suggested fits: sqrt(1.6 * 100 / 2000) = 0.28284 rounds up to 0.283.
  o.max_samples = 2000;
  o.separation = 0.05;
  CHECK(SampleMesh(mesh, o, &out, &error) == Status::kLimitExceeded);
  CHECK(error.find("about 64000 samples (limit 2000); choose a separation of at least 0.283") !=
        std::string::npos);
  o.separation = 0.283;
  CHECK(SampleMesh(mesh, o, &out, &error) == Status::kOk);
  // No room at all (footfalld's --max-samples 0): no separation is offered.
  o.max_samples = 0;
  CHECK(SampleMesh(mesh, o, &out, &error) == Status::kLimitExceeded);
  CHECK(error == "separation 0.283 would give about 1998 samples (limit 0): no separation fits");
  o.max_samples = 20000000;
  TriangleMesh bad = mesh;
  bad.vertices[1].y = NAN;
  o.separation = 1;
  CHECK(SampleMesh(bad, o, &out, &error) == Status::kInvalidArgument);
  CHECK(error.find("vertex 1") != std::string::npos);
}

}  // namespace footfall

namespace footfall {

TEST_CASE("SampleMesh: a separation far too small for the area says how many samples it means",
          "[import][sampler]") {
  TriangleMesh huge;  // 8e28 square units
  huge.vertices = {{0, 0, 0}, {4e14, 0, 0}, {0, 0, 4e14}};
  huge.triangles = {{0, 2, 1}};
  MeshSampleOptions o;
  o.separation = 1;
  RawSamples out;
  std::string error;
  CHECK(SampleMesh(huge, o, &out, &error) == Status::kLimitExceeded);
  CHECK(error.find("would give about 1.28e+29 samples") != std::string::npos);
}

TEST_CASE("SampleMesh: long thin triangles are refused before they are cut", "[import][sampler]") {
  // Two slivers 10000 long and 1e-4 wide: 16000 samples by area at s = 0.01, but millions of
  // pieces along their length.
  TriangleMesh sliver;
  sliver.vertices = {{0, 0, 0}, {1e-4, 0, 0}, {1e-4, 1e4, 0}, {0, 1e4, 0}};
  sliver.triangles = {{0, 1, 2}, {0, 2, 3}};
  MeshSampleOptions o;
  o.separation = 0.01;
  o.max_samples = 20000;
  RawSamples out;
  std::string error;
  CHECK(SampleMesh(sliver, o, &out, &error) == Status::kLimitExceeded);
  CHECK(error.find("long and thin") != std::string::npos);
  CHECK(out.size() == 0);
  // Both refusals suggest a separation that is then taken (by area alone, the first suggested
  // one the second refused).
  for (const double tried : {0.01, 1e-5}) {
    o.separation = tried;
    CHECK(SampleMesh(sliver, o, &out, &error) == Status::kLimitExceeded);
    const size_t at = error.find("choose a separation of at least ");
    REQUIRE(at != std::string::npos);
    MeshSampleOptions suggested = o;
    suggested.separation = std::stod(error.substr(at + 32));
    INFO(error);
    CHECK(SampleMesh(sliver, suggested, &out, &error) == Status::kOk);
  }
  // Two unit triangles 1e6 apart: the sampler's cells cannot span that at small separations,
  // and the refusal for it suggests one too (it suggested none, and the sample budget's
  // suggestion was then refused for it).
  TriangleMesh far;
  far.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {1e6, 0, 0}, {1e6 + 1, 0, 0}, {1e6, 0, 1}};
  far.triangles = {{0, 2, 1}, {3, 5, 4}};
  for (const double tried : {0.1, 1e-4}) {
    MeshSampleOptions fo;
    fo.separation = tried;
    CHECK(SampleMesh(far, fo, &out, &error) == Status::kLimitExceeded);
    const size_t at = error.find("choose a separation of at least ");
    REQUIRE(at != std::string::npos);
    fo.separation = std::stod(error.substr(at + 32));
    INFO(error);
    CHECK(SampleMesh(far, fo, &out, &error) == Status::kOk);
  }
  // With room for its pieces (about 1.1 million at s = 5), the same mesh samples, every sample
  // on it.
  o.separation = 5;
  o.max_samples = 100000;
  const Status status = SampleMesh(sliver, o, &out, &error);
  INFO(error);
  REQUIRE(status == Status::kOk);
  CHECK(out.size() > 1000);
  for (const Vec3& p : out.points) CHECK(test::DistanceToMesh(sliver, p) < 1e-5 * 1e4);
}

TEST_CASE("ResampleTerrainMesh: finest_default refines the file's spacing within the budget",
          "[import][sampler]") {
  test::TempDir dir;
  // A 40 x 40 height field of 1-unit cells: the file's own spacing is 1.
  std::string asc = "ncols 40\nnrows 40\nxllcorner 0\nyllcorner 0\ncellsize 1\n";
  for (int r = 0; r < 40; ++r) {
    for (int c = 0; c < 40; ++c) asc += std::to_string(0.1 * ((r * 7 + c * 3) % 5)) + " ";
    asc += "\n";
  }
  const std::string path = dir.Write("field.asc", asc);
  TerrainLoadOptions options;
  TriangleMesh mesh;
  TerrainLoadReport report;
  std::string error;
  REQUIRE(ReadTerrainMesh(path, options, &mesh, &error, &report) == Status::kOk);
  CHECK(report.format == "heightmap");
  CHECK(report.file_separation == 1);
  RawSamples samples;

  SECTION("no finest_default: the file's spacing, as LoadTerrain") {
    REQUIRE(ResampleTerrainMesh(path, mesh, options, &samples, &error, &report) == Status::kOk);
    CHECK(report.separation == 1);
    RawSamples loaded;
    REQUIRE(LoadTerrain(path, options, &loaded, &error) == Status::kOk);
    CHECK(loaded.points == samples.points);
  }
  SECTION("finer than the file: taken") {
    options.finest_default = 0.25;
    REQUIRE(ResampleTerrainMesh(path, mesh, options, &samples, &error, &report) == Status::kOk);
    CHECK(report.separation == 0.25);
    CHECK(report.samples == samples.size());
    CHECK(LargestGap(samples, Sample(mesh, 0.05)) <= 0.25);
  }
  SECTION("coarser than the file: the file's spacing") {
    options.finest_default = 3;
    REQUIRE(ResampleTerrainMesh(path, mesh, options, &samples, &error, &report) == Status::kOk);
    CHECK(report.separation == 1);
  }
  SECTION("beyond the sample budget: as fine as the budget allows") {
    options.finest_default = 0.01;
    options.max_samples = 20000;
    REQUIRE(ResampleTerrainMesh(path, mesh, options, &samples, &error, &report) == Status::kOk);
    CHECK(report.separation > 0.01);
    CHECK(report.separation < 0.5);
    CHECK(samples.size() <= 20000);
    CHECK(samples.size() > 10000);
  }
  SECTION("an explicit separation wins") {
    options.finest_default = 0.25;
    options.separation = 0.5;
    REQUIRE(ResampleTerrainMesh(path, mesh, options, &samples, &error, &report) == Status::kOk);
    CHECK(report.separation == 0.5);
  }
}

TEST_CASE("ReadTerrainMesh: point files and unknown extensions are not meshes",
          "[import][sampler]") {
  test::TempDir dir;
  TriangleMesh mesh;
  TerrainLoadReport report;
  std::string error;
  const std::string points = dir.Write("a.pts", "0 0 0 0 1 0\n");
  CHECK(ReadTerrainMesh(points, TerrainLoadOptions{}, &mesh, &error, &report) ==
        Status::kInvalidArgument);
  CHECK(error.find("unknown terrain file extension 'pts'") == std::string::npos);
  CHECK(error.find("a.pts") != std::string::npos);
}

}  // namespace footfall
