#include "footfall/steps/foot_rotations.h"

#include <algorithm>
#include <cmath>

namespace footfall {
namespace {

// The rotation a then b: b * a.
Quat Then(const Quat& a, const Quat& b) {
  return {b.w * a.x + a.w * b.x + (b.y * a.z - b.z * a.y),
          b.w * a.y + a.w * b.y + (b.z * a.x - b.x * a.z),
          b.w * a.z + a.w * b.z + (b.x * a.y - b.y * a.x),
          b.w * a.w - (b.x * a.x + b.y * a.y + b.z * a.z)};
}

}  // namespace

FootOrientation::FootOrientation(const Walk& walk) : walk_(walk) {
  for (size_t t = 0; t < walk.tracks.size(); ++t)
    if (walk.tracks[t].kind == TrackKind::kBody) body_of_.emplace(walk.tracks[t].character, t);
}

Quat FootOrientation::BodyAt(size_t body, double frame) {
  const WalkTrack& track = walk_.tracks[body];
  auto found = order_.find(body);
  if (found == order_.end()) found = order_.emplace(body, KeyOrder(track)).first;
  const std::vector<size_t>& order = found->second;
  if (order.empty()) return Quat{};
  const auto at = std::lower_bound(order.begin(), order.end(), frame,
                                   [&](size_t k, double f) { return track.keys[k].frame < f; });
  if (at == order.begin()) return Normalized(track.Rotation(order.front()));
  if (at == order.end()) return Normalized(track.Rotation(order.back()));
  const Quat b = Normalized(track.Rotation(*at));
  if (track.keys[*at].frame == frame) return b;
  const Quat a = Normalized(track.Rotation(*(at - 1)));
  const double fa = track.keys[*(at - 1)].frame, fb = track.keys[*at].frame;
  const double t = (frame - fa) / (fb - fa);
  const double sign = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w < 0 ? -1.0 : 1.0;
  const double u = 1 - t, v = sign * t;
  return Normalized({a.x * u + b.x * v, a.y * u + b.y * v, a.z * u + b.z * v, a.w * u + b.w * v});
}

std::vector<Quat> FootOrientation::Rotations(size_t track) {
  const WalkTrack& foot = walk_.tracks[track];
  std::vector<Quat> out(foot.keys.size());
  if (foot.rotations.size() == foot.keys.size()) {
    for (size_t k = 0; k < out.size(); ++k) out[k] = Normalized(foot.rotations[k]);
    return out;
  }
  const auto body = body_of_.find(foot.character);
  for (size_t k = 0; k < foot.keys.size(); ++k) {
    const WalkKey& key = foot.keys[k];
    const Quat q = body == body_of_.end() ? Quat{} : BodyAt(body->second, key.frame);
    // (Scaled by its largest component first: no square overflows or underflows.)
    const double m =
        std::max({std::fabs(key.normal.x), std::fabs(key.normal.y), std::fabs(key.normal.z)});
    if (!std::isfinite(m) || !(m > 0)) {
      out[k] = q;
      continue;
    }
    const Vec3 n = Normalize(key.normal / m);
    const Vec3 up = Rotate(q, Vec3{0, 1, 0});
    const double d = Dot(up, n);
    // The shortest rotation taking up onto n; half a turn about the body's left when n is
    // opposite (no shortest one).
    Quat tilt;
    if (d < -1 + 1e-12) {
      const Vec3 left = Rotate(q, Vec3{1, 0, 0});
      tilt = {left.x, left.y, left.z, 0};
    } else {
      const Vec3 c = Cross(up, n);
      tilt = Normalized({c.x, c.y, c.z, 1 + d});
    }
    out[k] = Normalized(Then(q, tilt));
  }
  return out;
}

void AddFootRotations(Walk* walk) {
  FootOrientation orientation(*walk);
  for (size_t t = 0; t < walk->tracks.size(); ++t) {
    WalkTrack& track = walk->tracks[t];
    if (track.kind != TrackKind::kFoot) continue;
    const std::vector<Quat> rotations = orientation.Rotations(t);
    track.rotations.assign(rotations.begin(), rotations.end());
  }
}

}  // namespace footfall
