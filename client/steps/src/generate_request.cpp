#include "footfall/steps/generate_request.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "character_read.h"
#include "footfall/steps/generator.h"
#include "footfall/steps/linear_units.h"
#include "footfall/terrain/shown_text.h"
#include "footfall/terrain/text_stream.h"
#include "json_input.h"
#include "request_fields.h"

namespace footfall {
namespace {

using nlohmann::json;

bool ReadVec(const json& j, const std::string& source, const char* key, Vec3* out,
             std::string* error) {
  if (!j.is_array() || j.size() != 3) {
    *error = source + ": '" + key + "': expected [x, y, z]";
    return false;
  }
  double v[3];
  for (int i = 0; i < 3; ++i) {
    if (!j[i].is_number() || !std::isfinite(j[i].get<double>())) {
      *error = source + ": '" + key + "': expected finite numbers";
      return false;
    }
    v[i] = j[i].get<double>();
  }
  *out = {v[0], v[1], v[2]};
  return true;
}

bool ReadNumber(const json& j, const std::string& source, const char* key, double* out,
                std::string* error) {
  if (!j.is_number() || !std::isfinite(j.get<double>())) {
    *error = source + ": '" + key + "': expected a finite number";
    return false;
  }
  *out = j.get<double>();
  return true;
}

}  // namespace

Status ParseGenerateRequest(const std::string& text, Character* character, GenerateOptions* options,
                            std::string* error) {
  // Nesting deeper than any request needs is refused: serialising the character object again
  // (below) recurses once per level, and a plugin thread's stack is small.
  constexpr int kMaxDepth = 32;
  detail::JsonDocument document;
  json& j = document.value;
  if (!detail::ParseJsonText(text, "request", &document, error, kMaxDepth))
    return Status::kParseError;
  return detail::ReadGenerateRequest(j, "request", "", {}, {}, character, options, nullptr, error);
}

namespace detail {

Status ReadGenerateRequest(const json& j, const std::string& source, const std::string& folder,
                           const std::set<std::string>& refused,
                           const std::set<std::string>& read_by_caller, Character* character,
                           GenerateOptions* options, std::string* character_file,
                           std::string* error) {
  if (!j.is_object()) {
    *error = source + ": not a JSON object";
    return Status::kParseError;
  }
  static const std::set<std::string> kKnown = {
      "character",     "character_file", "start", "heading", "path",
      "steps",         "start_frame",    "up",    "fps",     "crowd",
      "crowd_spacing", "foot_rotations", "scale", "unit"};
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (read_by_caller.count(it.key())) continue;
    if (!kKnown.count(it.key()) || refused.count(it.key())) {
      std::set<std::string> known = read_by_caller;
      for (const std::string& k : kKnown)
        if (!refused.count(k)) known.insert(k);
      *error = source + ": " + detail::UnknownFieldMessage(it.key(), known);
      return Status::kParseError;
    }
  }
  GenerateOptions o;
  // Messages about the start, heading, up and steps name this request's fields.
  o.names.start = source + ": 'start'";
  o.names.heading = source + ": 'heading'";
  o.names.up = source + ": 'up'";
  o.names.steps = source + ": 'steps'";
  o.names.crowd_spacing = source + ": 'crowd_spacing'";
  o.names.scale = source + ": 'scale'";
  Status s;
  if (j.contains("character") == j.contains("character_file")) {
    *error = source + ": give exactly one of 'character' (an object) or 'character_file' (a path)";
    return Status::kInvalidArgument;
  }
  if (j.contains("character")) {
    if (!j["character"].is_object()) {
      *error = source + ": 'character': expected a character file's object";
      return Status::kParseError;
    }
    if (character_file) character_file->clear();
    s = ReadCharacter(j["character"], source + " character", character, error);
  } else {
    if (!j["character_file"].is_string() || j["character_file"].get<std::string>().empty() ||
        j["character_file"].get<std::string>().find('\0') != std::string::npos) {
      *error = source + ": 'character_file': expected a path (not empty, without NUL bytes)";
      return Status::kParseError;
    }
    // A relative path is read from `folder` (the scene file's), if one is given; the file's
    // errors then also name the scene's character.
    const std::string given = j["character_file"].get<std::string>();
    const std::string file = !folder.empty() && given[0] != '/' ? folder + "/" + given : given;
    if (character_file) *character_file = file;
    s = LoadCharacter(file, character, error);
    if (s != Status::kOk && !folder.empty()) *error = source + ": " + *error;
  }
  if (s != Status::kOk) return s;
  if (j.contains("scale")) {
    double scale = 1;
    if (!ReadNumber(j["scale"], source, "scale", &scale, error)) return Status::kParseError;
    if (ScaleCharacter(scale, character, error) != Status::kOk) {
      *error = source + ": 'scale': " + *error;
      return Status::kInvalidArgument;
    }
  }
  bool ok = true;
  if (ok && j.contains("start")) {
    ok = ReadVec(j["start"], source, "start", &o.start, error), o.has_start = true;
    if (ok && !WithinQueryReach(o.start)) {
      *error =
          source + ": 'start' is too far from the terrain to snap (queries reach 1e15 from it)";
      ok = false;
    }
  }
  if (ok && j.contains("heading")) ok = ReadVec(j["heading"], source, "heading", &o.heading, error);
  if (ok && j.contains("up")) ok = ReadVec(j["up"], source, "up", &o.up, error);
  // The bounds of `footfall generate`'s flags.
  if (ok && j.contains("start_frame")) {
    ok = ReadNumber(j["start_frame"], source, "start_frame", &o.start_frame, error);
    if (ok && !(std::fabs(o.start_frame) <= kMaxStartFrame)) {
      *error = source + ": 'start_frame': expected a number from -1e+09 to 1e+09";
      ok = false;
    }
  }
  if (ok && j.contains("fps")) {
    ok = ReadNumber(j["fps"], source, "fps", &o.fps, error);
    if (ok && !(o.fps >= 0.001 && o.fps <= kMaxFps)) {
      *error = source + ": 'fps': expected a number from 0.001 to 1e+06";
      ok = false;
    }
  }
  if (ok && j.contains("crowd_spacing")) {
    ok = ReadNumber(j["crowd_spacing"], source, "crowd_spacing", &o.crowd_spacing, error);
    if (ok && !(o.crowd_spacing >= 0 && o.crowd_spacing <= 1e6)) {
      *error = source + ": 'crowd_spacing': expected a number from 0 (the default) to 1e+06";
      ok = false;
    }
  }
  if (ok && j.contains("unit")) {
    ok = j["unit"].is_string() && MetresPerLinearUnit(j["unit"].get<std::string>()) > 0;
    if (ok)
      o.unit = j["unit"].get<std::string>();
    else
      *error = source + ": 'unit': expected one of " + LinearUnitNames();
  }
  if (ok && j.contains("foot_rotations")) {
    ok = j["foot_rotations"].is_boolean();
    if (ok)
      o.foot_rotations = j["foot_rotations"].get<bool>();
    else
      *error = source + ": 'foot_rotations': expected true or false";
  }
  for (const char* key : {"steps", "crowd"}) {
    if (!ok || !j.contains(key)) continue;
    // A whole number written with a point or an exponent (20.0, 4e0: Python's floats) is one.
    const bool whole_float = j[key].is_number_float() && std::isfinite(j[key].get<double>()) &&
                             j[key].get<double>() == std::floor(j[key].get<double>());
    if (!j[key].is_number_integer() && !whole_float) {
      *error = source + ": '" + key + "': expected an integer";
      ok = false;
    } else {
      // Clamped before it is converted: an unsigned number above 2^63 would read as negative,
      // a float beyond long long's range is undefined.
      long long v = 1000001;
      if (whole_float)
        v = static_cast<long long>(std::clamp(j[key].get<double>(), -1.0, 1000001.0));
      else if (!j[key].is_number_unsigned() || j[key].get<uint64_t>() <= 1000000)
        v = j[key].get<long long>();
      const long long lo = std::string(key) == "steps" ? 0 : 1;
      if (v < lo || v > 1000000) {
        *error = source + ": '" + key + "': out of range (expected " + std::to_string(lo) +
                 " to 1000000)";
        ok = false;
      } else {
        (std::string(key) == "steps" ? o.steps : o.crowd) = static_cast<int>(v);
      }
    }
  }
  if (ok && j.contains("path")) {
    // (An empty one was taken for no path, where --path "" is refused.)
    if (!j["path"].is_array() || j["path"].empty()) {
      *error = source + ": 'path': expected an array of at least one waypoint [x, y, z]";
      ok = false;
    }
    // Each waypoint named by its place ("'path[0]'"), and a path of one point written flat
    // ([x, y, z]) told as such: "'path': expected [x, y, z]" was what the user wrote.
    if (ok && j["path"].size() == 3 && j["path"][0].is_number()) {
      *error = source +
               ": 'path': expected an array of waypoints, [[x, y, z], ...] (one "
               "waypoint is [[x, y, z]])";
      ok = false;
    }
    for (size_t i = 0; ok && i < j["path"].size(); ++i) {
      Vec3 p;
      const std::string key = "path[" + std::to_string(i) + "]";
      ok = ReadVec(j["path"][i], source, key.c_str(), &p, error);
      // Named here, with its field and line (the generator's check names neither).
      if (ok &&
          std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) > kMaxWaypointCoordinate) {
        TextStream m;
        m << source << ": '" << key << "': (" << p.x << ", " << p.y << ", " << p.z
          << ") has a coordinate beyond +-" << kMaxWaypointCoordinate
          << " (the reach of terrain queries)";
        *error = m.str();
        ok = false;
      }
      o.path.push_back(p);
    }
  }
  if (!ok) return Status::kParseError;
  *options = std::move(o);
  return Status::kOk;
}

}  // namespace detail
}  // namespace footfall
