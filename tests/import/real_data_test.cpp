// Real terrain from ../shared/data/terrain (see its README for sources and licences).
#include "footfall/import/mesh_reader.h"
#include "footfall/import/mesh_sampler.h"
#include "footfall/import/terrain_loader.h"
#include "footfall/terrain/grid.h"
#include "test_support.h"

namespace footfall {
namespace {

RawSamples Load(const std::string& path, const TerrainLoadOptions& options,
                TerrainLoadReport* report = nullptr) {
  RawSamples samples;
  std::string error;
  INFO(error);
  REQUIRE(LoadTerrain(path, options, &samples, &error, report) == Status::kOk);
  return samples;
}

TerrainGrid Grid(const RawSamples& samples) {
  TerrainGrid grid;
  std::string error;
  REQUIRE(TerrainGrid::Build(samples, GridOptions{}, &grid, &error) == Status::kOk);
  return grid;
}

// The largest distance from a sample of `a` to the nearest sample of `b`.
double Gap(const RawSamples& a, const TerrainGrid& b) {
  double gap = 0;
  for (const Vec3& p : a.points) gap = std::max(gap, Distance(p, b.Snap(p).point));
  return gap;
}

}  // namespace

TEST_CASE("Kootenai DEM: the ASC grid and the OBJ mesh give the same surface", "[import][real]") {
  const std::string dir = test::SharedTerrainDir();
  if (dir.empty()) return;
  TerrainLoadOptions options;
  options.separation = 0.5;
  TerrainLoadReport asc_report, obj_report;
  const RawSamples asc = Load(dir + "/terrain_kootenai_1m_50x37.asc", options, &asc_report);
  const RawSamples obj = Load(dir + "/terrain_kootenai_1m_50x37.obj", options, &obj_report);
  CHECK(asc_report.faces == 3528);
  CHECK(obj_report.faces == 3528);
  CHECK(obj_report.vertices == 1850);
  CHECK(asc_report.area == Approx(obj_report.area).epsilon(1e-3));
  // Each sample set lies within the separation of the other: the same surface.
  CHECK(Gap(asc, Grid(obj)) <= options.separation);
  CHECK(Gap(obj, Grid(asc)) <= options.separation);
  CHECK(asc_report.bounds_min.y > 537.3);
  CHECK(asc_report.bounds_max.y < 543.9);
}

TEST_CASE("SRTM tile: the ASC grid and the 16-bit PGM give the same samples", "[import][real]") {
  const std::string dir = test::SharedTerrainDir();
  if (dir.empty()) return;
  TerrainLoadOptions options;
  options.cell_size = 80;  // the tile's geographic cells are about 71 m x 93 m
  options.separation = 60;
  TerrainLoadReport asc_report, pgm_report;
  const RawSamples asc = Load(dir + "/terrain_srtm_boulder_144x144.asc", options, &asc_report);
  const RawSamples pgm = Load(dir + "/terrain_srtm_boulder_144x144_u16.pgm", options, &pgm_report);
  CHECK(asc_report.vertices == 144 * 144);
  CHECK(asc.points == pgm.points);
  CHECK(asc.normals == pgm.normals);
  CHECK(asc_report.bounds_min.y >= 2186);
  CHECK(asc_report.bounds_max.y <= 3345);
  SECTION("with Z up the same surface is rotated") {
    options.up_axis = 'z';
    RawSamples z_up = Load(dir + "/terrain_srtm_boulder_144x144.asc", options);
    for (size_t i = 0; i < z_up.size(); ++i) {
      CHECK(z_up.normals[i].z > 0);
      const Vec3 p = z_up.points[i];
      z_up.points[i] = {p.x, p.z, -p.y};  // back to Y up
    }
    CHECK(Gap(z_up, Grid(asc)) <= options.separation);
  }
}

TEST_CASE("Spot: a closed mesh with overhangs loads and answers queries", "[import][real]") {
  const std::string dir = test::SharedTerrainDir();
  if (dir.empty()) return;
  TerrainLoadOptions options;
  options.separation = 0.03;
  TerrainLoadReport report;
  const std::string path = dir + "/mesh_spot_triangulated.obj";
  const RawSamples samples = Load(path, options, &report);
  CHECK(report.vertices == 2930);
  CHECK(report.faces == 5856);
  CHECK(report.skipped_faces == 0);
  TriangleMesh mesh;
  std::string error;
  REQUIRE(ReadMesh(path, &mesh, &error) == Status::kOk);
  const TerrainGrid grid = Grid(samples);
  // Snap points around the cow: the answer lies on the surface, with an outward normal.
  RawSamples probes;
  SampleMeshUniform(mesh, 300, false, kDefaultCreaseAngleDeg, 3, &probes);
  for (size_t i = 0; i < probes.size(); ++i) {
    const Vec3 outside = probes.points[i] + probes.normals[i] * 0.01;
    const Foothold f = grid.Snap(outside);
    REQUIRE(f.status == Status::kOk);
    CHECK(Distance(f.point, probes.points[i]) <= options.separation + 0.01);
    size_t t = 0;
    CHECK(test::DistanceToMesh(mesh, f.point, &t) < 1e-5);
    CHECK(Dot(f.normal, Normalize(TriangleCross(mesh, t))) > 0);
  }
  // From below, the nearest sample is on an underside (a hoof or the belly) and faces down.
  const Foothold below = grid.Snap({0, report.bounds_min.y - 0.5, 0.4});
  REQUIRE(below.status == Status::kOk);
  CHECK(below.normal.y < 0);
  // A step along the back finds a foothold ahead.
  const Foothold top = grid.Snap({0, report.bounds_max.y + 1, 0.4});
  REQUIRE(top.status == Status::kOk);
  CHECK(top.normal.y > 0);
  const Foothold next = grid.Next({top.point, {0, 0, 0.05}}, 0.05);
  CHECK(next.status == Status::kOk);
  CHECK(Dot(next.point - top.point, Vec3{0, 0, 1}) > 0);
}

}  // namespace footfall
