#include "footfall/terrain/samples.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "footfall/terrain/shown_text.h"

namespace footfall {
namespace {

// Every digit it takes to read back: a point just past the range was shown rounded onto it
// ("(5e+14, 0, 0) is out of range ... within +-5e+14").
std::string Format(double x) { return NumberText(x); }

std::string Format(const Vec3& v) {
  return "(" + Format(v.x) + ", " + Format(v.y) + ", " + Format(v.z) + ")";
}

}  // namespace

Status CheckSample(const Vec3& point, const Vec3& normal, std::string* what) {
  std::string why;
  if (!IsFinite(point)) {
    why = "point " + Format(point) + " is not finite (expected finite x y z)";
  } else if (std::fabs(point.x) > terrain::kMaxCoordinate ||
             std::fabs(point.y) > terrain::kMaxCoordinate ||
             std::fabs(point.z) > terrain::kMaxCoordinate) {
    why = "point " + Format(point) + " is out of range (expected coordinates within +-" +
          Format(terrain::kMaxCoordinate) + ")";
  } else if (!IsFinite(normal)) {
    why = "normal " + Format(normal) + " is not finite (expected finite nx ny nz)";
  } else if (Length2(SafeNormalize(normal)) == 0) {
    why = "normal " + Format(normal) + " has zero length (expected a non-zero nx ny nz)";
  } else {
    return Status::kOk;
  }
  if (what) *what = why;
  return Status::kInvalidArgument;
}

Status ValidateAndNormalize(RawSamples* samples, std::string* error) {
  if (samples->points.size() != samples->normals.size()) {
    if (error) *error = "points and normals differ in count";
    return Status::kInvalidArgument;
  }
  for (size_t i = 0; i < samples->size(); ++i) {
    std::string what;
    if (CheckSample(samples->points[i], samples->normals[i], &what) != Status::kOk) {
      if (error) *error = "sample " + std::to_string(i) + ": " + what;
      return Status::kInvalidArgument;
    }
    samples->normals[i] = UnitNormal(samples->normals[i]);
  }
  return Status::kOk;
}

}  // namespace footfall
