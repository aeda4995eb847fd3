#include "footfall/steps/character.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "character_read.h"
#include "footfall/terrain/file_extension.h"
#include "footfall/terrain/shown_text.h"
#include "json_input.h"

namespace footfall {
namespace {

// [Units: wu] The largest length a character file may give (rests, step, heights, reach).
constexpr double kMaxLength = 1e9;

// [Units: wu] How far foot f's rest lies from the body standing over the rests' `centroid`,
// which `reach` must exceed.
double RestFromBody(const Character& c, const FootSpec& f, const Vec3& centroid) {
  return Length(f.rest - centroid + Vec3{0, -c.body_height, 0});
}

using nlohmann::json;

// Collects the first error while reading fields; every reader returns false once it fails.
struct Reader {
  std::string source;
  std::string error;
  Status status = Status::kOk;

  bool Fail(Status s, const std::string& what) {
    if (status == Status::kOk) status = s, error = source + ": " + what;
    return false;
  }
  // "'KEY' must be EXPECTED, found TYPE" for a field of the wrong JSON type.
  bool Mistyped(const std::string& key, const char* expected, const json& found) {
    return Fail(Status::kParseError,
                "'" + key + "' must be " + expected + ", found " + found.type_name());
  }
  bool Number(const json& j, const char* key, bool required, double* out) {
    auto it = j.find(key);
    if (it == j.end())
      return required
                 ? Fail(Status::kParseError, std::string("missing field '") + key + "' (a number)")
                 : true;
    if (!it->is_number()) return Mistyped(key, "a number", *it);
    if (!std::isfinite(it->get<double>()))
      return Fail(Status::kParseError, std::string("'") + key + "': expected a finite number");
    *out = it->get<double>();
    return true;
  }
  bool Vector(const json& j, const std::string& where, Vec3* out) {
    if (!j.is_array() || j.size() != 3)
      return Fail(Status::kParseError, where + ": expected [x, y, z]");
    double v[3];
    for (int i = 0; i < 3; ++i) {
      if (!j[i].is_number() || !std::isfinite(j[i].get<double>()))
        return Fail(Status::kParseError, where + ": expected finite numbers");
      if (!(std::fabs(j[i].get<double>()) <= kMaxLength))
        return Fail(Status::kInvalidArgument,
                    where + ": " + NumberText(j[i].get<double>()) + " is out of range [-1e9, 1e9]");
      v[i] = j[i].get<double>();
    }
    *out = {v[0], v[1], v[2]};
    return true;
  }
  bool Range(double v, double lo, double hi, bool lo_open, bool hi_open, const char* key) {
    const bool ok = (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
    if (ok) return true;
    return Fail(Status::kInvalidArgument, std::string("'") + key + "' = " + NumberText(v) +
                                              " is out of range " + (lo_open ? "(" : "[") +
                                              NumberText(lo) + ", " + NumberText(hi) +
                                              (hi_open ? ")" : "]"));
  }
  // A list of groups of foot names, each name used exactly once over all groups.
  bool Groups(const json& j, const char* key, const std::map<std::string, int>& feet,
              size_t max_group, std::vector<std::vector<int>>* out) {
    const std::string k = std::string("'") + key + "'";
    if (!j.is_array() || j.empty())
      return Fail(Status::kParseError, k + ": expected a non-empty array of arrays of foot names");
    std::set<int> seen;
    for (size_t g = 0; g < j.size(); ++g) {
      const std::string where = k + "[" + std::to_string(g) + "]";
      if (!j[g].is_array() || j[g].empty() || j[g].size() > max_group)
        return Fail(Status::kParseError, where + ": expected an array of 1 to " +
                                             std::to_string(max_group) + " foot names");
      std::vector<int> group;
      for (const json& name : j[g]) {
        if (!name.is_string()) return Fail(Status::kParseError, where + ": expected foot names");
        auto it = feet.find(name.get<std::string>());
        if (it == feet.end())
          return Fail(Status::kInvalidArgument,
                      where + ": no foot named '" + ShownText(name.get<std::string>()) + "'");
        if (!seen.insert(it->second).second)
          return Fail(Status::kInvalidArgument,
                      where + ": foot '" + it->first + "' is listed twice");
        group.push_back(it->second);
      }
      out->push_back(group);
    }
    if (seen.size() != feet.size()) {
      for (const auto& [name, index] : feet)
        if (!seen.count(index))
          return Fail(Status::kInvalidArgument,
                      k + ": foot '" + name + "' is in none of them (list every foot once" +
                          (k == "'pairs'" ? ", one alone as [\"" + name + "\"])" : ")"));
    }
    return true;
  }
};

}  // namespace

Status ParseCharacter(const std::string& text, const std::string& source, Character* out,
                      std::string* error) {
  detail::JsonDocument document;
  if (!detail::ParseJsonText(text, source, &document, error)) return Status::kParseError;
  const Status status = detail::ReadCharacter(document.value, source, out, error);
  if (status != Status::kOk) *error = detail::WithLine(text, source, *error);  // the field's line
  return status;
}

namespace detail {

Status ReadCharacter(const json& j, const std::string& source, Character* out, std::string* error) {
  Reader r;
  r.source = source;
  if (!j.is_object()) {
    *error = source + ": not a JSON object (expected a footfall character file)";
    return Status::kParseError;
  }
  static const std::set<std::string> kKnown = {"format",
                                               "version",
                                               "name",
                                               "feet",
                                               "gait",
                                               "pairs",
                                               "step_length",
                                               "step_height",
                                               "body_height",
                                               "frames_per_step",
                                               "align_to_normal",
                                               "slope_threshold_deg",
                                               "slope_step_scale",
                                               "max_slope_deg",
                                               "max_rise",
                                               "reach",
                                               "max_turn_deg",
                                               "foot_length",
                                               "foot_width",
                                               "comment"};
  static const std::set<std::string> kKnownFoot = {"name", "rest", "comment"};
  // Another format's file (a scene, a walk) is named by its format, not by the first of its
  // fields a character file does not know.
  if (j.contains("format") && j["format"].is_string() &&
      j["format"].get<std::string>() != "footfall-character")
    r.Fail(Status::kParseError, "'format': expected \"footfall-character\", found \"" +
                                    ShownText(j["format"].get<std::string>()) + "\"");
  std::string unknown;
  if (r.status == Status::kOk && detail::FindUnknownKey(j, kKnown, &unknown))
    r.Fail(Status::kParseError, detail::UnknownFieldMessage(unknown, kKnown));
  Character c;
  if (r.status == Status::kOk) {
    if (!j.contains("format"))
      r.Fail(Status::kParseError, "missing field 'format' (expected \"footfall-character\")");
    else if (!j["format"].is_string())
      r.Mistyped("format", "a string", j["format"]);
    else if (!j.contains("version"))
      r.Fail(Status::kParseError, "missing field 'version' (expected 1)");
    else if (!j["version"].is_number())
      r.Fail(Status::kParseError, "'version': expected an integer");
    else if (!detail::IsInteger(j["version"], kCharacterFormatVersion))
      r.Fail(Status::kParseError, "'version' " + j["version"].dump() +
                                      " is not supported (this build reads version " +
                                      std::to_string(kCharacterFormatVersion) + ")");
  }
  // A comment is text (a number or an object there is a misplaced field, not a remark).
  if (r.status == Status::kOk && j.contains("comment") && !j["comment"].is_string())
    r.Mistyped("comment", "a string", j["comment"]);
  if (r.status == Status::kOk && j.contains("name")) {
    if (!j["name"].is_string())
      r.Mistyped("name", "a string", j["name"]);
    else if (!detail::ControlCharacterIn(j["name"].get<std::string>()).empty())
      r.Fail(Status::kParseError,
             "'name': " + detail::ControlCharacterIn(j["name"].get<std::string>()));
    else
      c.name = j["name"].get<std::string>();
  }
  std::map<std::string, int> foot_index;
  if (r.status == Status::kOk) {
    const json* feet = j.contains("feet") ? &j["feet"] : nullptr;
    if (!feet || !feet->is_array() || feet->empty()) {
      r.Fail(Status::kParseError, "'feet': expected a non-empty array of {\"name\", \"rest\"}");
    } else {
      for (size_t i = 0; i < feet->size() && r.status == Status::kOk; ++i) {
        const json& f = (*feet)[i];
        const std::string where = "'feet'[" + std::to_string(i) + "]";
        FootSpec spec;
        // A misspelt field is named before the missing one it was meant to be.
        if (f.is_object() && detail::FindUnknownKey(f, kKnownFoot, &unknown)) {
          r.Fail(Status::kParseError,
                 where + ": " + detail::UnknownFieldMessage(unknown, kKnownFoot));
          break;
        }
        if (f.is_object() && f.contains("comment") && !f["comment"].is_string()) {
          r.Fail(Status::kParseError, where + ".comment: expected a string, found " +
                                          std::string(f["comment"].type_name()));
          break;
        }
        if (!f.is_object() || !f.contains("name") || !f["name"].is_string() ||
            !f.contains("rest")) {
          r.Fail(Status::kParseError, where + ": expected {\"name\": STRING, \"rest\": [x, y, z]}");
          break;
        }
        if (f["name"].get<std::string>().empty()) {
          r.Fail(Status::kParseError, where + ".name: expected a non-empty name");
          break;
        }
        const std::string control = detail::ControlCharacterIn(f["name"].get<std::string>());
        if (!control.empty()) {
          r.Fail(Status::kParseError, where + ".name: " + control);
          break;
        }
        // Walks, exporters and DCC rigs name the body's track and node "body".
        if (f["name"].get<std::string>() == "body") {
          r.Fail(Status::kInvalidArgument,
                 where + ".name: 'body' names the body's track; choose another foot name");
          break;
        }
        spec.name = f["name"].get<std::string>();
        if (!r.Vector(f["rest"], where + ".rest", &spec.rest)) break;
        const auto same_rest = std::find_if(c.feet.begin(), c.feet.end(), [&](const FootSpec& o) {
          return o.rest.x == spec.rest.x && o.rest.y == spec.rest.y && o.rest.z == spec.rest.z;
        });
        if (same_rest != c.feet.end()) {
          r.Fail(Status::kInvalidArgument, where + ".rest: the same as foot '" + same_rest->name +
                                               "''s: each foot needs its own rest position");
          break;
        }
        if (!foot_index.emplace(spec.name, static_cast<int>(i)).second) {
          r.Fail(Status::kInvalidArgument, where + ": foot name '" + spec.name + "' is used twice");
          break;
        }
        c.feet.push_back(spec);
      }
    }
  }
  if (r.status == Status::kOk) {
    if (!j.contains("gait"))
      r.Fail(Status::kParseError, "missing field 'gait' (groups of foot names)");
    else
      r.Groups(j["gait"], "gait", foot_index, c.feet.size(), &c.gait);
  }
  if (r.status == Status::kOk) {
    if (j.contains("pairs")) {
      r.Groups(j["pairs"], "pairs", foot_index, 2, &c.pairs);
    } else {
      for (size_t i = 0; i < c.feet.size(); ++i) c.pairs.push_back({static_cast<int>(i)});
    }
  }
  double fps = c.frames_per_step;
  if (r.status == Status::kOk) {
    r.Number(j, "step_length", true, &c.step_length) &&
        r.Number(j, "step_height", true, &c.step_height) &&
        r.Number(j, "body_height", true, &c.body_height) &&
        r.Number(j, "frames_per_step", true, &fps) &&
        r.Number(j, "slope_threshold_deg", false, &c.slope_threshold_deg) &&
        r.Number(j, "slope_step_scale", false, &c.slope_step_scale) &&
        r.Number(j, "max_slope_deg", false, &c.max_slope_deg) &&
        r.Number(j, "max_rise", false, &c.max_rise) && r.Number(j, "reach", true, &c.reach) &&
        r.Number(j, "max_turn_deg", false, &c.max_turn_deg) &&
        r.Number(j, "foot_length", false, &c.foot_length) &&
        r.Number(j, "foot_width", false, &c.foot_width);
  }
  if (r.status == Status::kOk) {
    if (!j.contains("align_to_normal") || !j["align_to_normal"].is_boolean())
      r.Fail(Status::kParseError, "'align_to_normal': expected true (multipeds) or false (bipeds)");
    else
      c.align_to_normal = j["align_to_normal"].get<bool>();
  }
  if (r.status == Status::kOk) {
    if (fps != std::floor(fps))
      r.Fail(Status::kParseError, "'frames_per_step': expected an integer");
    // Clamped before the conversion (out of int's range it is undefined); refused below.
    c.frames_per_step = static_cast<int>(std::clamp(fps, 0.0, 1e6));
  }
  if (r.status == Status::kOk) {
    r.Range(c.step_length, 0, kMaxLength, true, false, "step_length") &&
        r.Range(c.step_height, 0, kMaxLength, true, false, "step_height") &&
        r.Range(c.body_height, 0, kMaxLength, false, false, "body_height") &&
        r.Range(fps, 2, 1e6, false, false, "frames_per_step") &&
        r.Range(c.slope_threshold_deg, 0, 90, false, false, "slope_threshold_deg") &&
        r.Range(c.slope_step_scale, 0, 1, true, false, "slope_step_scale") &&
        r.Range(c.max_slope_deg, 0, 180, true, true, "max_slope_deg") &&
        r.Range(c.max_rise, 0, kMaxLength, true, false, "max_rise") &&
        r.Range(c.reach, 0, kMaxLength, true, false, "reach") &&
        r.Range(c.max_turn_deg, 0, 180, true, false, "max_turn_deg") &&
        r.Range(c.foot_length, 0, kMaxLength, false, false, "foot_length") &&
        r.Range(c.foot_width, 0, kMaxLength, false, false, "foot_width");
    if (r.status == Status::kOk && c.foot_width > 0 && !(c.foot_length > 0))
      r.Fail(Status::kInvalidArgument,
             "'foot_width': needs a 'foot_length' above 0 (a sole has both, or neither)");
  }
  if (r.status == Status::kOk) {
    const Vec3 centroid = RestCentroid(c);
    for (const FootSpec& f : c.feet) {
      const double rest = RestFromBody(c, f, centroid);
      if (rest >= c.reach) {
        r.Fail(Status::kInvalidArgument, "'reach' = " + NumberText(c.reach) +
                                             " must exceed the distance from the body to the "
                                             "rest of foot '" +
                                             f.name + "' (" + NumberText(rest) + ")");
        break;
      }
    }
  }
  if (r.status != Status::kOk) {
    *error = r.error;
    return r.status;
  }
  *out = std::move(c);
  return Status::kOk;
}

}  // namespace detail

Vec3 RestCentroid(const Character& c) {
  Vec3 sum;
  for (const FootSpec& f : c.feet) sum += f.rest;
  return c.feet.empty() ? sum : sum / static_cast<double>(c.feet.size());
}

Status ScaleCharacter(double scale, Character* c, std::string* error) {
  if (!(scale >= kMinCharacterScale && scale <= kMaxCharacterScale)) {
    *error = "scale " + NumberText(scale) + " is out of range [" + NumberText(kMinCharacterScale) +
             ", " + NumberText(kMaxCharacterScale) + "]";
    return Status::kInvalidArgument;
  }
  Character scaled = *c;
  for (FootSpec& f : scaled.feet) f.rest = f.rest * scale;
  struct ScaledLength {
    const char* key;
    double* value;
    bool positive;  // must stay above 0 (else at least 0)
  };
  const ScaledLength lengths[] = {{"step_length", &scaled.step_length, true},
                                  {"step_height", &scaled.step_height, true},
                                  {"body_height", &scaled.body_height, false},
                                  {"max_rise", &scaled.max_rise, true},
                                  {"reach", &scaled.reach, true},
                                  {"foot_length", &scaled.foot_length, false},
                                  {"foot_width", &scaled.foot_width, false}};
  for (const ScaledLength& l : lengths) {
    *l.value *= scale;
    if (!(*l.value <= kMaxLength) || (l.positive && !(*l.value > 0))) {
      *error = "scale " + NumberText(scale) + " makes '" + l.key + "' " + NumberText(*l.value) +
               ", out of a character's range " + (l.positive ? "(0" : "[0") + ", " +
               NumberText(kMaxLength) + "]";
      return Status::kInvalidArgument;
    }
  }
  for (const FootSpec& f : scaled.feet) {
    const double largest =
        std::max({std::fabs(f.rest.x), std::fabs(f.rest.y), std::fabs(f.rest.z)});
    if (!(largest <= kMaxLength)) {
      *error = "scale " + NumberText(scale) + " puts the rest of foot '" + f.name + "' " +
               NumberText(largest) + " from the body, out of a character's range [-" +
               NumberText(kMaxLength) + ", " + NumberText(kMaxLength) + "]";
      return Status::kInvalidArgument;
    }
  }
  // Rounded, a rest just inside the reach may land on it.
  const Vec3 centroid = RestCentroid(scaled);
  for (const FootSpec& f : scaled.feet) {
    if (!(RestFromBody(scaled, f, centroid) < scaled.reach)) {
      *error = "scale " + NumberText(scale) + " puts the rest of foot '" + f.name +
               "' at the character's reach, " + NumberText(scaled.reach);
      return Status::kInvalidArgument;
    }
  }
  *c = std::move(scaled);
  return Status::kOk;
}

Status LoadCharacter(const std::string& path, Character* out, std::string* error) {
  std::string text;
  const Status status =
      detail::ReadJsonFile(path, "character file", &text, error, detail::kMaxCharacterFileBytes);
  if (status != Status::kOk) return status;
  const Status parsed = ParseCharacter(text, path, out, error);
  // Without a name, the file's: messages said "resampled for  at ...", and scene characters
  // were named "1", "2".
  if (parsed == Status::kOk && out->name.empty()) out->name = FileStem(path);
  return parsed;
}

}  // namespace footfall
