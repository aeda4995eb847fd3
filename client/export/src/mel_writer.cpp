#include "footfall/export/mel_writer.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "footfall/export/euler.h"
#include "footfall/steps/foot_rotations.h"
#include "footfall/steps/linear_units.h"
#include "footfall/terrain/ordered_text.h"
#include "footfall/terrain/output_file.h"
#include "footfall/terrain/shown_text.h"
#include "footfall/version.h"
#include "walk_prep.h"

namespace footfall {
namespace {

// Appends a decimal MEL literal without exponent that reads back as `value` exactly: the fewest
// significant digits that round-trip, written in fixed notation, trailing zeros trimmed, "-0"
// as "0". A whole number beyond MEL's 32-bit int keeps a ".0": MEL reads a literal without a
// point as an int. `value` must be finite. std::to_chars, unlike printf, ignores the C locale:
// a host that sets a decimal-comma LC_NUMERIC (Maya, Blender) still gets points.
void AppendNumber(std::string& out, double value) {
  // The shortest scientific form that reads back to the same double: what the shortest
  // "%.{p}e" in the "C" locale gives (the correctly rounded digits, ties to even).
  char text[64];
  const std::to_chars_result written =
      std::to_chars(text, text + sizeof text, value, std::chars_format::scientific);
  // text is "[-]d[.ddd]e<sign><exp>": split into sign, digits and the power of ten of the first
  // digit.
  const bool negative = text[0] == '-';
  const char* e = std::find(text, written.ptr, 'e');
  char digits[32];
  int count = 0;
  for (const char* c = text + (negative ? 1 : 0); c < e; ++c)
    if (*c != '.') digits[count++] = *c;
  int exponent = 0;
  const char* exponent_text = e + 1;
  if (*exponent_text == '+') ++exponent_text;  // from_chars takes '-' but not '+'
  std::from_chars(exponent_text, written.ptr, exponent);
  // Fixed notation: at most "0." and 323 zeros before 17 digits, or 309 digits.
  char s[400];
  int n = 0;
  if (exponent < 0) {
    s[n++] = '0', s[n++] = '.';
    for (int z = 0; z < -exponent - 1; ++z) s[n++] = '0';
    for (int d = 0; d < count; ++d) s[n++] = digits[d];
  } else if (exponent + 1 >= count) {
    for (int d = 0; d < count; ++d) s[n++] = digits[d];
    for (int z = 0; z < exponent + 1 - count; ++z) s[n++] = '0';
  } else {
    for (int d = 0; d <= exponent; ++d) s[n++] = digits[d];
    s[n++] = '.';
    for (int d = exponent + 1; d < count; ++d) s[n++] = digits[d];
  }
  const bool point = std::find(s, s + n, '.') != s + n;
  if (point) {
    while (s[n - 1] == '0') --n;
    if (s[n - 1] == '.') --n;
  }
  if (n == 1 && s[0] == '0') {
    out += '0';
    return;
  }
  if (negative) out += '-';
  out.append(s, static_cast<size_t>(n));
  if (!std::count(s, s + n, '.') && std::fabs(value) > 2147483647.0) out += ".0";
}

std::string Number(double value) {
  std::string s;
  AppendNumber(s, value);
  return s;
}

// A valid Maya node name: [A-Za-z_][A-Za-z0-9_]*.
std::string MayaName(const std::string& name) {
  std::string out;
  for (unsigned char c : name) {
    out += (std::isalnum(c) != 0 || c == '_') && c < 128 ? static_cast<char>(c) : '_';
  }
  if (out.empty()) out = "track";
  if (std::isdigit(static_cast<unsigned char>(out[0])) != 0) out.insert(out.begin(), '_');
  return out;
}

// True when `name` is a Maya node name as it stands (MayaName leaves it as it is).
bool LegalAsGiven(const std::string& name) { return !name.empty() && MayaName(name) == name; }

// True when every '/'-separated part of a crowd character's name ("c1", a scene's "dogs/c1")
// is legal as given: its MEL name joins them with '_', which makes nothing legal that was not.
bool CharacterLegalAsGiven(const std::string& character) {
  size_t begin = 0;
  for (;;) {
    const size_t end = character.find('/', begin);
    if (!LegalAsGiven(character.substr(begin, end - begin))) return false;
    if (end == std::string::npos) return true;
    begin = end + 1;
  }
}

// A double-quoted MEL string literal holding `text`.
std::string MelString(const std::string& text) {
  std::string out = "\"";
  for (char c : walk_export::ValidUtf8(text)) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        // Other control bytes have no MEL escape (names with them are refused on reading).
        out += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
    }
  }
  return out + "\"";
}

// Text safe inside a `//` comment line: no line breaks or other control bytes, and no
// backslash (one at the end of the line could join the next line to the comment).
std::string CommentText(const std::string& text) {
  std::string out = walk_export::ValidUtf8(text);
  for (char& c : out) {
    if (c == '\n' || c == '\r' || c == '\t')
      c = ' ';
    else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == '\\')
      c = '?';
  }
  return out;
}

// Maya's name for a time unit of `fps` frames per second, or "" when it has none.
std::string MayaTimeUnit(double fps) {
  struct Named {
    double fps;
    const char* unit;
  };
  static const Named kNamed[] = {
      {15, "game"},        {24, "film"},          {25, "pal"},         {30, "ntsc"},
      {48, "show"},        {50, "palf"},          {60, "ntscf"},       {23.976, "23.976fps"},
      {29.97, "29.97fps"}, {47.952, "47.952fps"}, {59.94, "59.94fps"}, {119.88, "119.88fps"},
      {1, "sec"},          {1000, "millisec"}};
  for (const Named& named : kNamed) {
    if (std::abs(fps - named.fps) < 1e-3) return named.unit;
  }
  // A frame a minute or an hour: near to a millionth of the rate (1e-3 would take every rate
  // below 0.001 for an hour).
  if (std::abs(fps * 60 - 1) < 1e-6) return "min";
  if (std::abs(fps * 3600 - 1) < 1e-6) return "hour";
  // Whole rates Maya accepts as "<n>fps" (90 from Maya 2020, the others from 2017).
  static const int kWhole[] = {2,   3,   4,   5,    6,    8,    10,   12,   16,    20,   40,  75,
                               80,  90,  100, 120,  125,  150,  200,  240,  250,   300,  375, 400,
                               500, 600, 750, 1200, 1500, 2000, 3000, 6000, 44100, 48000};
  for (int rate : kWhole) {
    if (std::abs(fps - rate) < 1e-9) return std::to_string(rate) + "fps";
  }
  return "";
}

// The name of the group holding the whole walk.
constexpr char kRootName[] = "footfall_walk";

}  // namespace

Status WriteMel(const Walk& walk, const std::string& path, std::string* error) {
  return WriteMel(walk, path, MelOptions{}, error);
}

Status WriteMel(const Walk& walk, const std::string& path, const MelOptions& options,
                std::string* error) {
  Status status = walk_export::CheckWalk(walk, error);
  if (status != Status::kOk) return status;
  const std::string& linear = walk.unit;
  if (!linear.empty() && !(MetresPerLinearUnit(linear) > 0)) {
    if (error)
      *error = "the walk's unit '" + ShownText(linear) + "' is none of Maya's linear units (" +
               LinearUnitNames() + ")";
    return Status::kInvalidArgument;
  }

  // Group names (one per crowd character, in order of appearance) and locator names, all
  // unique in the file and none the root group's name (Maya would rename one of the two).
  std::vector<std::string> characters;
  std::unordered_map<std::string, int> group_index;
  std::vector<int> group_of(walk.tracks.size(), -1);
  for (size_t t = 0; t < walk.tracks.size(); ++t) {
    const std::string& character = walk.tracks[t].character;
    if (character.empty()) continue;
    const auto found = group_index.emplace(character, static_cast<int>(characters.size()));
    if (found.second) characters.push_back(character);
    group_of[t] = found.first->second;
  }
  // Names that are legal as given claim them before names made legal here (a foot `left_foot`
  // keeps its name beside a foot `left foot`, which becomes left_foot_2), in a crowd too: a
  // crowd track's name is its character's and its own joined by '_' (c1_left_foot), as given
  // when both are. A track without a name (named track<i> here) claims nothing.
  std::vector<std::string> names = {kRootName};
  std::vector<bool> as_given = {true};
  for (const std::string& character : characters) {
    names.push_back(MayaName(character));
    as_given.push_back(CharacterLegalAsGiven(character));
  }
  for (size_t t = 0; t < walk.tracks.size(); ++t) {
    const WalkTrack& track = walk.tracks[t];
    names.push_back(MayaName(walk_export::QualifiedTrackName(track, t)));
    as_given.push_back(LegalAsGiven(track.name) &&
                       (track.character.empty() || CharacterLegalAsGiven(track.character)));
  }
  names = walk_export::UniqueNames(names, as_given);  // the root, first, keeps its name
  names.erase(names.begin());

  double first_frame = std::numeric_limits<double>::infinity();
  double last_frame = -std::numeric_limits<double>::infinity();
  for (const WalkTrack& track : walk.tracks) {
    for (const WalkKey& key : track.keys) {
      first_frame = std::min(first_frame, key.frame);
      last_frame = std::max(last_frame, key.frame);
    }
  }

  // The script's end: the user's angle (and linear) unit back, the walk's root selected.
  const std::string tail = std::string("currentUnit -angle $footfall_angle_unit;\n") +
                           (linear.empty() ? "" : "currentUnit -linear $footfall_linear_unit;\n") +
                           "select -replace $footfall_root;\n}\n";
  // The script's head: time unit, playback range, the root and the characters' groups.
  std::string head;
  {
    std::string& mel = head;
    mel += "// footfall walk: " + std::to_string(walk.tracks.size()) + " tracks at " +
           Number(walk.fps) + " fps. Generated by footfall " FOOTFALL_VERSION ".\n";
    // The same bytes whatever the file is called: the header names no file.
    mel +=
        "// In Maya: source this file (File > Source Script); one keyed locator per foot IK "
        "target and body.\n";
    mel += linear.empty() ? "// Lengths are keyed in the scene's linear unit: one walk unit to one "
                            "scene unit (footfall generate --unit names the walk's).\n"
                          : "// Lengths are in " + linear +
                                " and keyed so whatever the scene's linear unit.\n";
    if (!walk.stopped.empty())
      mel += "// The walk stopped early: " + CommentText(walk.stopped) + "\n";
    mel += "{\n";
    const std::string unit = MayaTimeUnit(walk.fps);
    if (!unit.empty()) {
      mel += "currentUnit -time " + MelString(unit) + ";\n";
    } else {
      mel += "warning " +
             MelString("footfall: Maya has no time unit for " + Number(walk.fps) +
                       " fps; keys are at the walk's frames in the scene's current unit") +
             ";\n";
    }
    // setKeyframe values are in the scene's units: rotations are keyed in degrees whatever the
    // user's angle unit (a scene in radians turned bodies 57.3 times too far), which is put back
    // at the end. Lengths stay in the scene's linear unit, one footfall unit to one scene unit,
    // as the Maya plugin sends the scene's terrain, unless the walk's unit is named (below).
    mel += "string $footfall_angle_unit = `currentUnit -query -angle`;\n";
    mel += "currentUnit -angle \"deg\";\n";
    // Lengths in the walk's unit when it has one (Walk::unit): Maya converts them
    // to the scene's, whose unit is put back at the end.
    if (!linear.empty()) {
      mel += "string $footfall_linear_unit = `currentUnit -query -linear`;\n";
      mel += "currentUnit -linear " + MelString(linear) + ";\n";
    }
    if (first_frame <= last_frame) {
      mel += "playbackOptions -minTime " + Number(first_frame) + " -maxTime " + Number(last_frame) +
             " -animationStartTime " + Number(first_frame) + " -animationEndTime " +
             Number(last_frame) + ";\n";
    }
    mel += "string $footfall_root = `createNode transform -name " + MelString(kRootName) + "`;\n";
    mel += "string $footfall_groups[];\n";
    mel += "string $footfall_node[];\n";
    for (size_t c = 0; c < characters.size(); ++c) {
      mel += "$footfall_groups[" + std::to_string(c) + "] = `createNode transform -name " +
             MelString(names[c]) + " -parent $footfall_root`;\n";
    }
  }
  // Then each track's locator and keys, in runs of at most kRunKeys keys, formatted on one
  // thread per core and written in order (FormatInOrder), never whole in memory: a crowd's
  // script runs to gigabytes. Each track's keys in written order (empty: as they are, their
  // frames increasing) and its body rotations (each following on from the one before) are
  // worked out first.
  constexpr size_t kRunKeys = 4000;
  struct Run {
    size_t track, first, end;
  };
  std::vector<Run> runs;
  std::vector<std::vector<size_t>> orders(walk.tracks.size());
  std::vector<std::vector<Vec3>> eulers(walk.tracks.size());
  FootOrientation feet(walk);
  // Which tracks are keyed with rotations: bodies, and feet when asked.
  auto rotated = [&](const WalkTrack& track) {
    return track.kind == TrackKind::kBody || options.foot_rotations;
  };
  for (size_t t = 0; t < walk.tracks.size(); ++t) {
    const WalkTrack& track = walk.tracks[t];
    bool increasing = true;
    for (size_t k = 1; k < track.keys.size() && increasing; ++k)
      increasing = track.keys[k - 1].frame < track.keys[k].frame;
    if (!increasing) orders[t] = KeyOrder(track);
    const size_t count = increasing ? track.keys.size() : orders[t].size();
    if (rotated(track)) {
      const bool body = track.kind == TrackKind::kBody;
      const std::vector<Quat> foot = body ? std::vector<Quat>{} : feet.Rotations(t);
      std::vector<Quat> rotations(count);
      for (size_t k = 0; k < count; ++k) {
        const size_t key = increasing ? k : orders[t][k];
        rotations[k] = body ? track.Rotation(key) : foot[key];
      }
      eulers[t] = ContinuousEulerZxyDegrees(rotations);
    }
    size_t first = 0;
    do {
      const size_t end = std::min(count, first + kRunKeys);
      runs.push_back({t, first, end});
      first = end;
    } while (first < count);
  }
  auto format = [&](size_t r, std::string* text) {
    std::string& mel = *text;
    if (r == 0) mel += head;
    const size_t t = runs[r].track;
    static const char* kAxes[] = {"X", "Y", "Z"};
    // Linear in and out tangents on every key, as the glTF export's LINEAR samplers: the motion
    // between keys does not depend on the Maya user's default tangent (a spline default made a
    // planted foot drift between its equal end and start keys).
    static const char* kLinear = " -itt linear -ott linear";
    const WalkTrack& track = walk.tracks[t];
    const bool body = track.kind == TrackKind::kBody, turns = rotated(track);
    if (runs[r].first == 0) {
      const std::string qualified = walk_export::QualifiedTrackName(track, t);
      mel += "// track " + std::to_string(t) + ": " + (body ? "body " : "foot ") +
             CommentText(qualified) + "\n";
      mel +=
          "$footfall_node = `spaceLocator -n " + MelString(names[characters.size() + t]) + "`;\n";
      const std::string parent = group_of[t] < 0
                                     ? std::string("$footfall_root")
                                     : "$footfall_groups[" + std::to_string(group_of[t]) + "]";
      mel += "$footfall_node = `parent $footfall_node[0] " + parent + "`;\n";
      mel += "addAttr -longName \"footfallTrack\" -dataType \"string\" $footfall_node[0];\n";
      mel += "setAttr -type \"string\" ($footfall_node[0] + \".footfallTrack\") " +
             MelString(qualified) + ";\n";
      mel += "addAttr -longName \"footfallKind\" -dataType \"string\" $footfall_node[0];\n";
      mel += "setAttr -type \"string\" ($footfall_node[0] + \".footfallKind\") " +
             MelString(body ? "body" : "foot") + ";\n";
      // Bodies (and feet keyed with rotations) turn in rotate order ZXY (enum 2): heading
      // about Y is applied last, so an upright body is never at gimbal lock whatever its
      // heading (in XYZ, heading +-X is: a small turn there swung each channel by tens of
      // degrees).
      if (turns) mel += "setAttr ($footfall_node[0] + \".rotateOrder\") 2;\n";
    }
    std::string time;
    for (size_t k = runs[r].first; k < runs[r].end; ++k) {
      const WalkKey& key = track.keys[orders[t].empty() ? k : orders[t][k]];
      time.assign("setKeyframe -t ");
      AppendNumber(time, key.frame);
      time += " -at ";
      // One attribute's key, appended piece by piece (no string made per number).
      auto key_line = [&](const char* attribute, const char* axis, double v) {
        mel += time;
        mel += attribute;
        mel += axis;
        mel += " -v ";
        AppendNumber(mel, v);
        mel += kLinear;
        mel += " $footfall_node[0];\n";
      };
      const double translate[] = {key.position.x, key.position.y, key.position.z};
      for (int axis = 0; axis < 3; ++axis) key_line("translate", kAxes[axis], translate[axis]);
      if (turns) {
        const Vec3& euler = eulers[t][k];
        const double rotate[] = {euler.x, euler.y, euler.z};
        for (int axis = 0; axis < 3; ++axis) key_line("rotate", kAxes[axis], rotate[axis]);
      }
    }
    if (r + 1 == runs.size()) mel += tail;
  };
  std::string message;
  const Status written = ReplaceFile(
      path,
      [&](std::FILE* file) {
        if (runs.empty()) {  // no tracks: the head and the end
          const std::string all = head + tail;
          return std::fwrite(all.data(), 1, all.size(), file) == all.size();
        }
        return FormatInOrder(runs.size(), 0, format, [file](std::string_view text) {
          return std::fwrite(text.data(), 1, text.size(), file) == text.size();
        });
      },
      &message);
  if (written != Status::kOk) walk_export::SetError(error, message);
  return written;
}

}  // namespace footfall
