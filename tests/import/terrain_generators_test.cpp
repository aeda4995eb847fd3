// The synthetic terrains of `footfall terrain make`: what they are documented to be like.
#include "footfall/import/terrain_generators.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <catch2/catch.hpp>

using namespace footfall;

TEST_CASE("terrain make hills is gentle ground like the bundled hills.pts",
          "[import][generators]") {
  // Laid at one noise unit every 0.25 m, its slopes were 27.5 degrees in the middle and up to
  // 61 (a walk across hills.pts stopped on them as too steep); hills.pts has 6.2 and 16.
  const RawSamples hills = MakeHills(161, 0.25, 0.6, 1);  // 40 m at 0.25 m, the defaults
  std::vector<double> slopes;
  for (const Vec3& n : hills.normals)
    slopes.push_back(std::acos(std::clamp(n.y, -1.0, 1.0)) * 180 / 3.14159265358979323846);
  std::sort(slopes.begin(), slopes.end());
  const double median = slopes[slopes.size() / 2];
  INFO("median " << median << ", steepest " << slopes.back());
  CHECK(median > 3);
  CHECK(median < 10);
  CHECK(slopes.back() < 30);
  // The same ground at any spacing: the sample at (10, 10) of a finer sampling is the same.
  const RawSamples fine = MakeHills(801, 0.05, 0.6, 1);
  CHECK(fine.points[200 * 801 + 200].y == Approx(hills.points[40 * 161 + 40].y).margin(1e-9));
}
