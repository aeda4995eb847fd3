#include "walk_prep.h"
#include "footfall/terrain/text_stream.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <unordered_map>
#include <unordered_set>

namespace footfall {
namespace walk_export {
namespace {

bool Finite(const Quat& q) {
  return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w);
}

double MaxAbs(const Quat& q) {
  return std::max({std::fabs(q.x), std::fabs(q.y), std::fabs(q.z), std::fabs(q.w)});
}

}  // namespace

void SetError(std::string* error, const std::string& message) {
  if (error != nullptr) *error = message;
}

Status CheckWalk(const Walk& walk, std::string* error) {
  if (!std::isfinite(walk.fps) || walk.fps <= 0) {
    TextStream message;
    message << "walk fps must be finite and > 0, got " << walk.fps;
    SetError(error, message.str());
    return Status::kInvalidArgument;
  }
  for (size_t t = 0; t < walk.tracks.size(); ++t) {
    const WalkTrack& track = walk.tracks[t];
    // Bodies have one rotation per key; feet none, or one per key (AddFootRotations).
    const bool rotated = track.kind == TrackKind::kBody || !track.rotations.empty();
    if (rotated && track.rotations.size() != track.keys.size()) {
      TextStream message;
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
      } else if (rotated && !Finite(track.rotations[k])) {
        what = "a non-finite rotation";
      } else if (rotated && MaxAbs(track.rotations[k]) == 0) {
        what = "a zero rotation quaternion";
      }
      if (what != nullptr) {
        TextStream message;
        message << "track " << t << " '" << QualifiedTrackName(track, t) << "' key " << k << " has "
                << what;
        SetError(error, message.str());
        return Status::kInvalidArgument;
      }
    }
  }
  return Status::kOk;
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

}  // namespace walk_export
}  // namespace footfall
