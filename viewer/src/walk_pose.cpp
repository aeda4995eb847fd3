#include "footfall/viewer/walk_pose.h"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace footfall::viewer {
namespace {

Quat Slerp(Quat a, const Quat& b, double t) {
  double d = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
  if (d < 0) a = {-a.x, -a.y, -a.z, -a.w}, d = -d;
  double wa = 1 - t, wb = t;
  if (d < 0.9995) {
    const double angle = std::acos(std::min(1.0, d));
    const double s = std::sin(angle);
    wa = std::sin((1 - t) * angle) / s;
    wb = std::sin(t * angle) / s;
  }
  Quat q{wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z, wa * a.w + wb * b.w};
  const double n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  return {q.x / n, q.y / n, q.z / n, q.w / n};
}

TrackPose FromKey(const WalkTrack& track, size_t i) {
  TrackPose p;
  p.position = track.keys[i].position;
  // At unit length, as between keys (a file's [0, 40, 0] was drawn 40 times as long).
  const Vec3& n = track.keys[i].normal;
  p.normal = Length2(n) > 0 ? Normalize(n) : n;
  p.rotation = track.Rotation(i);
  return p;
}

}  // namespace

Vec3 ArcPoint(const Vec3& start, const Vec3& mid, const Vec3& end, double t) {
  // Quadratic Bezier whose t = 0.5 point is `mid`.
  const Vec3 control = 2.0 * mid - 0.5 * (start + end);
  const double u = 1 - t;
  return u * u * start + 2 * u * t * control + t * t * end;
}

TrackPose PoseAt(const WalkTrack& track, double frame) {
  const auto& keys = track.keys;
  if (keys.empty()) return TrackPose{};
  if (frame <= keys.front().frame) return FromKey(track, 0);
  if (frame >= keys.back().frame) return FromKey(track, keys.size() - 1);
  // The last key at or before `frame`.
  size_t i =
      static_cast<size_t>(std::upper_bound(keys.begin(), keys.end(), frame,
                                           [](double f, const WalkKey& k) { return f < k.frame; }) -
                          keys.begin() - 1);
  const WalkKey& a = keys[i];
  const WalkKey& b = keys[i + 1];
  const double span = b.frame - a.frame;
  const double t = span > 0 ? (frame - a.frame) / span : 1.0;
  TrackPose pose;
  pose.rotation = Slerp(track.Rotation(i), track.Rotation(i + 1), t);
  if (track.kind == TrackKind::kFoot) {
    // A swing's lift-off, mid and touch-down keys around `frame` make its arc.
    size_t s = keys.size();
    if (SwingStartsAt(keys, i)) {
      s = i;
    } else if (i >= 1 && SwingStartsAt(keys, i - 1)) {
      s = i - 1;
    }
    if (s < keys.size()) {
      const WalkKey& k0 = keys[s];
      const WalkKey& km = keys[s + 1];
      const WalkKey& k1 = keys[s + 2];
      const double swing = k1.frame - k0.frame;
      const double u = swing > 0 ? (frame - k0.frame) / swing : 1.0;
      pose.position = ArcPoint(k0.position, km.position, k1.position, u);
      const Vec3 n = Lerp(k0.normal, k1.normal, u);
      pose.normal = Length2(n) > 0 ? Normalize(n) : k0.normal;
      pose.swinging = true;
      return pose;
    }
  }
  pose.position = Lerp(a.position, b.position, t);
  const Vec3 n = Lerp(a.normal, b.normal, t);
  pose.normal = Length2(n) > 0 ? Normalize(n) : a.normal;
  pose.swinging = a.phase == KeyPhase::kMid;  // (a lift-off with its mid key is an arc above)
  return pose;
}

void FrameRange(const Walk& walk, double* first, double* last) {
  bool any = false;
  *first = *last = 0;
  for (const WalkTrack& t : walk.tracks) {
    if (t.keys.empty()) continue;
    if (!any || t.keys.front().frame < *first) *first = t.keys.front().frame;
    if (!any || t.keys.back().frame > *last) *last = t.keys.back().frame;
    any = true;
  }
}

namespace {

// `frame` in plain digits with `decimals` decimals, trailing zeros dropped ("-0" as "0"); false
// when that text does not read back as `frame` and `exact` asks it to.
bool FixedText(double frame, int decimals, bool exact, std::string* out) {
  char text[64];
  // (std::to_chars ignores the C locale: a decimal point whatever LC_NUMERIC says.)
  const std::to_chars_result r =
      std::to_chars(text, text + sizeof text, frame, std::chars_format::fixed, decimals);
  if (exact) {
    double back = 0;
    std::from_chars(text, r.ptr, back);
    if (back != frame) return false;
  }
  std::string s(text, r.ptr);
  s.erase(s.find_last_not_of('0') + 1);
  if (s.back() == '.') s.pop_back();
  *out = s == "-0" ? "0" : s;
  return true;
}

// `frame` with an exponent, in the shortest form that reads back as it.
std::string ScientificText(double frame) {
  char text[64];
  const std::to_chars_result r =
      std::to_chars(text, text + sizeof text, frame, std::chars_format::scientific);
  return std::string(text, r.ptr);
}

}  // namespace

std::string FrameText(double frame) {
  // From 1e15 on always with an exponent: the shortest form wrote 1e15 so and 1e15 + 1 in digits.
  if (!(std::fabs(frame) < 1e15)) return ScientificText(frame);
  std::string s;
  FixedText(frame, 3, false, &s);
  return s;
}

std::string ExactFrameText(double frame) {
  std::string s;
  if (std::fabs(frame) < 1e15)
    for (int decimals = 3; decimals <= 20; ++decimals)
      if (FixedText(frame, decimals, true, &s)) return s;
  return ScientificText(frame);
}

}  // namespace footfall::viewer
