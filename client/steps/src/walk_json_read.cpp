// Reading walk JSON: each key taken as the parser finishes it (KeyStream), the rest of the
// document checked field by field, and a refused value located by its line.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "footfall/steps/linear_units.h"
#include "footfall/steps/walk_json.h"
#include "json_input.h"

namespace footfall {
namespace {

using nlohmann::json;

struct Reader {
  std::string source;
  std::string error;
  std::string where;  // the value the error is about
  bool Fail(const std::string& where_, const std::string& what) {
    if (error.empty()) error = source + ": " + where_ + ": " + what, where = where_;
    return false;
  }
  // Fails on the first field of object `j` not in `known` (a misspelt "normal" left a default
  // normal unseen), said of `j`, and on a "comment" that is not a string. `at`: where `j` stands
  // ("" for the root).
  bool Known(const json& j, const std::string& at, const std::set<std::string>& known) {
    const std::string prefix = at.empty() ? "" : at + ".";
    std::string key;
    if (detail::FindUnknownKey(j, known, &key)) {
      // Said of the object that holds it (the key, shown safely, may hold any character).
      if (error.empty()) {
        error =
            source + ": " + (at.empty() ? "" : at + ": ") + detail::UnknownFieldMessage(key, known);
        where = at;
      }
      return false;
    }
    if (j.contains("comment") && !j["comment"].is_string())
      return Fail(prefix + "comment",
                  std::string("expected a string, found ") + j["comment"].type_name());
    return true;
  }
  bool Finite(const json& j, const std::string& where, double* out) {
    if (!j.is_number() || !std::isfinite(j.get<double>()))
      return Fail(where, "expected a finite number");
    *out = j.get<double>();
    return true;
  }
  bool Array(const json& j, size_t n, const std::string& where, double* out) {
    if (!j.is_array() || j.size() != n)
      return Fail(where, "expected an array of " + std::to_string(n) + " numbers");
    for (size_t i = 0; i < n; ++i)
      if (!Finite(j[i], where + "[" + std::to_string(i) + "]", &out[i])) return false;
    return true;
  }
  bool Vec(const json& j, const std::string& where, Vec3* out) {
    double v[3];
    if (!Array(j, 3, where, v)) return false;
    *out = {v[0], v[1], v[2]};
    return true;
  }
  // A key's position: within +-kMaxKeyCoordinate (a viewer framing a key at 1e300 got NaN).
  bool Position(const json& j, const std::string& where, Vec3* out) {
    if (!Vec(j, where, out)) return false;
    for (double v : {out->x, out->y, out->z})
      if (!(std::fabs(v) <= kMaxKeyCoordinate))
        return Fail(where,
                    "expected coordinates within +-1e15 (terrain samples lie within +-5e14)");
    return true;
  }
};

// Reads the "rotation" of key object `k` (at `kw`; the identity when it has none) onto the end
// of track->rotations; false, with r's error, when it is not four numbers, not all zero.
bool ReadRotation(Reader& r, const json& k, const std::string& kw, WalkTrack* track) {
  double q[4] = {0, 0, 0, 1};
  if (k.contains("rotation") && !r.Array(k["rotation"], 4, kw + ".rotation", q)) return false;
  // Any non-zero length (1e-10 or 1e300 components alike): readers normalise it.
  if (std::max({std::fabs(q[0]), std::fabs(q[1]), std::fabs(q[2]), std::fabs(q[3])}) == 0) {
    r.Fail(kw + ".rotation", "expected a non-zero quaternion [qx, qy, qz, qw]");
    return false;
  }
  track->rotations.push_back({q[0], q[1], q[2], q[3]});
  return true;
}

// Reads key object `k` (at `kw`, for messages) onto the end of `track`, whose kind says which
// fields it has; false, with r's error, when it is refused.
bool ReadKey(Reader& r, const json& k, const std::string& kw, WalkTrack* track) {
  WalkKey key;
  if (!k.is_object() || !k.contains("frame") || !k.contains("position")) {
    r.Fail(kw, "expected an object with frame and position");
    return false;
  }
  static const std::set<std::string> kFootKey = {"frame",  "phase",    "position",
                                                 "normal", "rotation", "comment"};
  static const std::set<std::string> kBodyKey = {"frame", "position", "rotation", "comment"};
  if (!r.Known(k, kw, track->kind == TrackKind::kFoot ? kFootKey : kBodyKey)) return false;
  if (!r.Finite(k["frame"], kw + ".frame", &key.frame)) return false;
  if (!track->keys.empty() && !(key.frame > track->keys.back().frame)) {
    r.Fail(kw + ".frame", "frames must increase along a track");
    return false;
  }
  if (!r.Position(k["position"], kw + ".position", &key.position)) return false;
  if (track->kind == TrackKind::kFoot) {
    const std::string phase =
        k.contains("phase") && k["phase"].is_string() ? k["phase"].get<std::string>() : "?";
    if (phase == "start")
      key.phase = KeyPhase::kStart;
    else if (phase == "mid")
      key.phase = KeyPhase::kMid;
    else if (phase == "end")
      key.phase = KeyPhase::kEnd;
    else {
      r.Fail(kw + ".phase", "expected \"start\", \"mid\" or \"end\"");
      return false;
    }
    if (k.contains("normal")) {
      if (!r.Vec(k["normal"], kw + ".normal", &key.normal)) return false;
      // Any non-zero length, as samples' normals and body rotations (zero has no direction).
      if (std::max({std::fabs(key.normal.x), std::fabs(key.normal.y), std::fabs(key.normal.z)}) ==
          0) {
        r.Fail(kw + ".normal", "expected a non-zero normal [nx, ny, nz]");
        return false;
      }
    }
    // A foot's orientations (AddFootRotations) are on every key of its track or on none.
    const bool rotated = k.contains("rotation");
    if (!track->keys.empty() && rotated != (track->rotations.size() == track->keys.size())) {
      r.Fail(rotated ? kw + ".rotation" : kw,
             "expected a rotation on every key of a foot track or on none (the first key has " +
                 std::string(track->rotations.empty() ? "none" : "one") + ")");
      return false;
    }
    if (rotated && !ReadRotation(r, k, kw, track)) return false;
  } else if (!ReadRotation(r, k, kw, track)) {
    return false;
  }
  track->keys.push_back(key);
  return true;
}

// The keys of each track, read as the parser finishes each key object and then left out of the
// document: a crowd's walk of millions of keys never stands whole as a document (about five times
// its text). A track's keys are taken so only when its "kind" comes before its "keys" (as footfall
// writes it); otherwise they stay in the document, for the reading below. A refused key stops the
// parse (Restart): the whole document is then read again, so that the first error in reading
// order is the one reported, word for word as before.
class KeyStream {
 public:
  struct Restart {};

  explicit KeyStream(const std::string& source) { reader_.source = source; }

  // The parser callback (detail::JsonFilter).
  bool operator()(int depth, json::parse_event_t event, json& parsed) {
    using E = json::parse_event_t;
    const size_t d = static_cast<size_t>(depth);
    switch (event) {
      case E::object_start:
      case E::array_start:
        if (d == levels_.size()) {  // always so: the depth of the value that starts
          Count(d);
          levels_.push_back({event == E::object_start, std::string(), 0});
        }
        return true;
      case E::key:
        if (d >= 1 && d <= levels_.size() && parsed.is_string())
          levels_[d - 1].key = parsed.get<std::string>();
        return true;
      case E::value:
        Count(d);
        if (d == 3 && InTrack() && levels_[2].key == "kind" && parsed.is_string()) {
          Track& t = Of(levels_[1].count - 1);
          const std::string kind = parsed.get<std::string>();
          if (kind == "foot" || kind == "body") {
            t.known = true;
            t.keys.kind = kind == "foot" ? TrackKind::kFoot : TrackKind::kBody;
          }
        }
        return true;
      case E::object_end:
      case E::array_end: {
        const bool key = event == E::object_end && d == 4 && levels_.size() == 5 && InKeys();
        if (d + 1 == levels_.size()) levels_.pop_back();
        if (!key) return true;
        Track& t = Of(levels_[1].count - 1);
        // Kind unknown here (after the keys, or not a kind): keep every key of this track.
        if (!t.known || t.kept) {
          t.kept = true;
          return true;
        }
        if (!ReadKey(reader_, parsed, std::string(), &t.keys)) throw Restart{};
        t.taken = true;
        return false;
      }
    }
    return true;
  }

  // Track `ti`'s keys and rotations, when they were taken from the document (moved out).
  bool Take(size_t ti, WalkTrack* track) {
    if (ti >= tracks_.size() || !tracks_[ti].taken) return false;
    track->keys = std::move(tracks_[ti].keys.keys);
    track->rotations = std::move(tracks_[ti].keys.rotations);
    return true;
  }

 private:
  struct Level {
    bool object;
    std::string key;  // objects: the last key read
    size_t count;     // arrays: the values started in it
  };
  struct Track {
    WalkTrack keys;      // its kind, and the keys taken
    bool known = false;  // its kind came before its keys
    bool taken = false;  // keys were taken from the document
    bool kept = false;   // keys were left in it
  };

  // A value starts at depth d: one more in the array holding it.
  void Count(size_t d) {
    if (d >= 1 && d <= levels_.size() && !levels_[d - 1].object) ++levels_[d - 1].count;
  }
  // Inside a track object: {"tracks": [{...}]}.
  bool InTrack() const {
    return levels_.size() >= 3 && levels_[0].object && levels_[0].key == "tracks" &&
           !levels_[1].object && levels_[2].object;
  }
  // Inside the keys array of a track: {"tracks": [{"keys": [...]}]}.
  bool InKeys() const {
    return levels_.size() >= 4 && InTrack() && levels_[2].key == "keys" && !levels_[3].object;
  }
  Track& Of(size_t ti) {
    if (ti >= tracks_.size()) tracks_.resize(ti + 1);
    return tracks_[ti];
  }

  Reader reader_;
  std::vector<Level> levels_;
  std::vector<Track> tracks_;
};

// Parses walk JSON; `stream` takes the keys as they are parsed (KeyStream).
Status ParseWalk(const std::string& text, const std::string& source, Walk* out, std::string* error,
                 bool stream) {
  detail::JsonDocument document;
  json& j = document.value;
  KeyStream keys(source);
  try {
    const detail::JsonFilter filter = stream ? detail::JsonFilter(std::ref(keys)) : nullptr;
    if (!detail::ParseJsonText(text, source, &document, error, 0, filter))
      return Status::kParseError;
  } catch (const KeyStream::Restart&) {
    return ParseWalk(text, source, out, error, false);
  }
  Reader r;
  r.source = source;
  Walk walk;
  if (!j.is_object()) {
    *error = source + ": not a JSON object (expected a footfall walk)";
    return Status::kParseError;
  }
  if (j.contains("format") && !j["format"].is_string()) {
    r.Fail("format", std::string("must be a string, found ") + j["format"].type_name());
  } else if (j.value("format", std::string()) != "footfall-walk") {
    r.Fail("format", "expected \"footfall-walk\"");
  } else if (!j.contains("version") || !detail::IsInteger(j["version"], kWalkFormatVersion)) {
    r.Fail("version", "expected " + std::to_string(kWalkFormatVersion));
  } else if (!j.contains("fps") || !r.Finite(j["fps"], "fps", &walk.fps)) {
    r.Fail("fps", "expected a positive number");
  } else if (!(walk.fps > 0)) {
    r.Fail("fps", "expected a positive number");
  } else if (j.contains("unit") &&
             !(j["unit"].is_string() && MetresPerLinearUnit(j["unit"].get<std::string>()) > 0)) {
    r.Fail("unit", std::string("expected one of ") + LinearUnitNames());
  } else if (j.contains("stopped") && !j["stopped"].is_string()) {
    r.Fail("stopped", "expected a string");
  } else if (!j.contains("tracks") || !j["tracks"].is_array()) {
    r.Fail("tracks", "expected an array");
  } else {
    r.Known(j, "", {"format", "version", "fps", "unit", "stopped", "tracks", "comment"});
  }
  if (r.error.empty()) {
    walk.unit = j.value("unit", std::string());
    walk.stopped = j.value("stopped", std::string());
    const json& tracks = j["tracks"];
    for (size_t ti = 0; ti < tracks.size() && r.error.empty(); ++ti) {
      const json& t = tracks[ti];
      const std::string tw = "tracks[" + std::to_string(ti) + "]";
      WalkTrack track;
      if (!t.is_object() || !t.contains("name") || !t["name"].is_string()) {
        r.Fail(tw, "expected {\"name\": STRING, \"kind\": \"foot\"|\"body\", \"keys\": [...]}");
        break;
      }
      if (!r.Known(t, tw,
                   {"name", "kind", "character", "foot_length", "foot_width", "keys", "comment"}))
        break;
      track.name = t["name"].get<std::string>();
      if (!detail::ControlCharacterIn(track.name).empty()) {
        r.Fail(tw + ".name", detail::ControlCharacterIn(track.name));
        break;
      }
      if (t.contains("character")) {
        if (!t["character"].is_string()) {
          r.Fail(tw + ".character", "expected a string");
          break;
        }
        track.character = t["character"].get<std::string>();
        if (!detail::ControlCharacterIn(track.character).empty()) {
          r.Fail(tw + ".character", detail::ControlCharacterIn(track.character));
          break;
        }
      }
      const std::string kind =
          t.contains("kind") && t["kind"].is_string() ? t["kind"].get<std::string>() : "";
      if (kind == "foot")
        track.kind = TrackKind::kFoot;
      else if (kind == "body")
        track.kind = TrackKind::kBody;
      else {
        r.Fail(tw + ".kind", "expected \"foot\" or \"body\"");
        break;
      }
      // The sole (a foot track's foot_length and foot_width).
      bool sole_read = true;
      for (const auto& [field, value] :
           {std::pair<const char*, double*>{"foot_length", &track.foot_length},
            {"foot_width", &track.foot_width}}) {
        if (!sole_read || !t.contains(field)) continue;
        const std::string at = tw + "." + field;
        if (track.kind != TrackKind::kFoot)
          sole_read = r.Fail(at, std::string("only a foot track has a ") + field);
        else if (!r.Finite(t[field], at, value))
          sole_read = false;
        else if (!(*value >= 0 && *value <= kMaxFootLength))
          sole_read = r.Fail(
              at, std::string("expected a length in [0, 1e9] (the character's ") + field + ")");
      }
      if (!sole_read) break;
      if (!t.contains("keys") || !t["keys"].is_array()) {
        r.Fail(tw + ".keys", "expected an array");
        break;
      }
      if (!keys.Take(ti, &track)) {
        const json& dom_keys = t["keys"];
        track.keys.reserve(dom_keys.size());
        for (size_t ki = 0; ki < dom_keys.size(); ++ki) {
          if (!ReadKey(r, dom_keys[ki], tw + ".keys[" + std::to_string(ki) + "]", &track)) break;
        }
      }
      walk.tracks.push_back(std::move(track));
    }
  }
  if (!r.error.empty()) {
    // Where it stands in the file, for an editor: the path alone left a long file to count.
    *error = r.error + " (line " + std::to_string(detail::LineOf(text, r.where)) + ")";
    return Status::kParseError;
  }
  *out = std::move(walk);
  return Status::kOk;
}

}  // namespace

Status ParseWalkJson(const std::string& text, const std::string& source, Walk* out,
                     std::string* error) {
  return ParseWalk(text, source, out, error, true);
}

namespace detail {
Status ParseWalkJsonWhole(const std::string& text, const std::string& source, Walk* out,
                          std::string* error) {
  return ParseWalk(text, source, out, error, false);
}
}  // namespace detail

Status ReadWalkJson(const std::string& path, Walk* out, std::string* error) {
  std::string text;
  const Status status = detail::ReadJsonFile(path, "walk file", &text, error);
  if (status != Status::kOk) return status;
  return ParseWalkJson(text, path, out, error);
}

}  // namespace footfall
