#include "footfall/terrain/samples.h"

#include <cmath>

namespace footfall {

Status ValidateAndNormalize(RawSamples* samples, std::string* error) {
  if (samples->points.size() != samples->normals.size()) {
    if (error) *error = "points and normals differ in count";
    return Status::kInvalidArgument;
  }
  for (size_t i = 0; i < samples->size(); ++i) {
    const Vec3& p = samples->points[i];
    Vec3& n = samples->normals[i];
    if (!IsFinite(p) || !IsFinite(n)) {
      if (error) *error = "sample " + std::to_string(i) + ": value is NaN or infinite";
      return Status::kInvalidArgument;
    }
    const double len = Length(n);
    if (!(len > 0) || !std::isfinite(len)) {
      if (error) *error = "sample " + std::to_string(i) + ": normal has zero length";
      return Status::kInvalidArgument;
    }
    n = n / len;
  }
  return Status::kOk;
}

}  // namespace footfall
