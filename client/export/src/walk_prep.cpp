#include "walk_prep.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

namespace footfall {
namespace walk_export {
namespace {

bool Finite(const Quat& q) {
  return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w);
}

double Norm2(const Quat& q) { return q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w; }

double MaxAbs(const Quat& q) {
  return std::max({std::fabs(q.x), std::fabs(q.y), std::fabs(q.z), std::fabs(q.w)});
}

// The rotation a then b: b * a.
Quat Then(const Quat& a, const Quat& b) {
  return {b.w * a.x + a.w * b.x + (b.y * a.z - b.z * a.y),
          b.w * a.y + a.w * b.y + (b.z * a.x - b.x * a.z),
          b.w * a.z + a.w * b.z + (b.x * a.y - b.y * a.x),
          b.w * a.w - (b.x * a.x + b.y * a.y + b.z * a.z)};
}

}  // namespace

void SetError(std::string* error, const std::string& message) {
  if (error != nullptr) *error = message;
}

Status CheckWalk(const Walk& walk, std::string* error) {
  if (!std::isfinite(walk.fps) || walk.fps <= 0) {
    std::ostringstream message;
    message << "walk fps must be finite and > 0, got " << walk.fps;
    SetError(error, message.str());
    return Status::kInvalidArgument;
  }
  for (size_t t = 0; t < walk.tracks.size(); ++t) {
    const WalkTrack& track = walk.tracks[t];
    if (track.kind == TrackKind::kBody && track.rotations.size() != track.keys.size()) {
      std::ostringstream message;
      message << "track " << t << " '" << QualifiedTrackName(track, t) << "' has "
              << track.rotations.size() << " rotations for " << track.keys.size()
              << " keys (expected one per key)";
      SetError(error, message.str());
      return Status::kInvalidArgument;
    }
    for (size_t k = 0; k < track.keys.size(); ++k) {
      const WalkKey& key = track.keys[k];
      const char* what = nullptr;
      if (!std::isfinite(key.frame)) {
        what = "a non-finite frame";
      } else if (!IsFinite(key.position)) {
        what = "a non-finite position";
      } else if (track.kind == TrackKind::kBody && !Finite(track.rotations[k])) {
        what = "a non-finite rotation";
      } else if (track.kind == TrackKind::kBody && MaxAbs(track.rotations[k]) == 0) {
        what = "a zero rotation quaternion";
      }
      if (what != nullptr) {
        std::ostringstream message;
        message << "track " << t << " '" << QualifiedTrackName(track, t) << "' key " << k << " has "
                << what;
        SetError(error, message.str());
        return Status::kInvalidArgument;
      }
    }
  }
  return Status::kOk;
}

std::vector<size_t> KeyOrder(const WalkTrack& track) {
  std::vector<size_t> order(track.keys.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&track](size_t a, size_t b) {
    return track.keys[a].frame < track.keys[b].frame;
  });
  std::vector<size_t> kept;
  kept.reserve(order.size());
  for (size_t index : order) {
    if (!kept.empty() && track.keys[kept.back()].frame == track.keys[index].frame) {
      kept.back() = index;  // same frame: the later key wins
    } else {
      kept.push_back(index);
    }
  }
  return kept;
}

std::string QualifiedTrackName(const WalkTrack& track, size_t index) {
  std::string name = track.name.empty() ? "track" + std::to_string(index) : track.name;
  return track.character.empty() ? name : track.character + "/" + name;
}

std::vector<std::string> UniqueNames(const std::vector<std::string>& names,
                                     const std::vector<bool>& first_claim) {
  std::unordered_set<std::string> taken(names.begin(), names.end());
  std::unordered_set<std::string> used;
  std::unordered_map<std::string, int> next_suffix;  // per name: the first suffix to try
  std::vector<std::string> unique(names.size());
  auto place = [&](size_t i) {
    const std::string& name = names[i];
    // A suffixed name never takes a name that another track carries as its own.
    std::string candidate = name;
    int& suffix = next_suffix.emplace(name, 2).first->second;
    while (used.count(candidate) != 0 || (candidate != name && taken.count(candidate) != 0)) {
      candidate = name + "_" + std::to_string(suffix++);
    }
    used.insert(candidate);
    unique[i] = candidate;
  };
  auto claims_first = [&](size_t i) { return i < first_claim.size() && first_claim[i]; };
  for (size_t i = 0; i < names.size(); ++i)
    if (claims_first(i)) place(i);
  for (size_t i = 0; i < names.size(); ++i)
    if (!claims_first(i)) place(i);
  return unique;
}

std::string ValidUtf8(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  const size_t n = text.size();
  for (size_t i = 0; i < n;) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    // The length of the sequence `c` starts and the range of its second byte (RFC 3629: no
    // overlong forms, no surrogates, nothing above U+10FFFF).
    size_t length = 0;
    unsigned char low = 0x80, high = 0xBF;
    if (c < 0x80) {
      length = 1;
    } else if (c >= 0xC2 && c <= 0xDF) {
      length = 2;
    } else if (c >= 0xE0 && c <= 0xEF) {
      length = 3;
      if (c == 0xE0) low = 0xA0;
      if (c == 0xED) high = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      length = 4;
      if (c == 0xF0) low = 0x90;
      if (c == 0xF4) high = 0x8F;
    }
    bool valid = length > 0 && i + length <= n;
    for (size_t k = 1; valid && k < length; ++k) {
      const unsigned char next = static_cast<unsigned char>(text[i + k]);
      valid = k == 1 ? next >= low && next <= high : next >= 0x80 && next <= 0xBF;
    }
    if (valid) {
      out.append(text, i, length);
      i += length;
    } else {
      out += "\xEF\xBF\xBD";  // U+FFFD for the first byte; the next one starts afresh
      ++i;
    }
  }
  return out;
}

Quat Normalized(const Quat& q) {
  // Scaled by its largest component first, so that no square overflows or underflows.
  const double m = MaxAbs(q);
  const Quat s{q.x / m, q.y / m, q.z / m, q.w / m};
  const double n = std::sqrt(Norm2(s));
  return {s.x / n, s.y / n, s.z / n, s.w / n};
}

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
  const auto body = body_of_.find(foot.character);
  std::vector<Quat> out(foot.keys.size());
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

}  // namespace walk_export
}  // namespace footfall
