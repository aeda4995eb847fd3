#include "footfall/steps/scene.h"

#include <algorithm>
#include <cstring>
#include <set>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "footfall/terrain/shown_text.h"
#include "footfall/terrain/text_stream.h"
#include "json_input.h"
#include "request_fields.h"

namespace footfall {

Status ParseScene(const std::string& text, const std::string& source, const std::string& folder,
                  std::vector<SceneCharacter>* out, std::string* error) {
  // Nesting as deep as a request's (a character object inside a scene's list).
  constexpr int kMaxDepth = 34;
  detail::JsonDocument document;
  nlohmann::json& j = document.value;
  if (!detail::ParseJsonText(text, source, &document, error, kMaxDepth)) return Status::kParseError;
  // Errors name the line of the field they are about (of the entry, for an entry's own).
  auto fail = [&](Status status, const std::string& what) {
    *error = detail::WithLine(text, source, source + ": " + what);
    return status;
  };
  if (!j.is_object()) return fail(Status::kParseError, "not a JSON object (expected a scene file)");
  // The format first: a character or walk file given as a scene was refused for a field of
  // its own ("unknown field 'align_to_normal'").
  if (!j.contains("format") || j["format"] != "footfall-scene") {
    std::string found = j.contains("format") ? j["format"].dump() : "no 'format'";
    if (j.contains("format") && j["format"] == "footfall-character")
      found += ": a character file (give it with --character)";
    else if (j.contains("format") && j["format"] == "footfall-walk")
      found += ": a walk file, which footfall generate writes";
    return fail(Status::kParseError, "'format': expected \"footfall-scene\", found " + found);
  }
  static const std::set<std::string> kKnown = {"format", "version", "comment", "characters"};
  std::string unknown;
  if (detail::FindUnknownKey(j, kKnown, &unknown))
    return fail(Status::kParseError, detail::UnknownFieldMessage(unknown, kKnown));
  if (!j.contains("version") || !detail::IsInteger(j["version"], kSceneFormatVersion))
    return fail(Status::kParseError, "'version' must be " + std::to_string(kSceneFormatVersion));
  if (j.contains("comment") && !j["comment"].is_string())
    return fail(Status::kParseError, "'comment' must be a string");
  if (!j.contains("characters") || !j["characters"].is_array() || j["characters"].empty() ||
      j["characters"].size() > kMaxSceneCharacters) {
    return fail(Status::kParseError, "'characters' must be an array of 1 to " +
                                         std::to_string(kMaxSceneCharacters) + " objects");
  }
  std::vector<SceneCharacter> scene;
  std::set<std::string> names;
  for (size_t i = 0; i < j["characters"].size(); ++i) {
    const std::string where = source + ": characters[" + std::to_string(i) + "]";
    const nlohmann::json& entry = j["characters"][i];
    if (!entry.is_object()) {
      *error = detail::WithLine(text, source, where + ": expected an object",
                                "characters[" + std::to_string(i) + "]");
      return Status::kParseError;
    }
    SceneCharacter c;
    std::string name;
    if (entry.contains("name")) {
      if (!entry["name"].is_string() || entry["name"].get<std::string>().empty()) {
        *error = detail::WithLine(text, source, where + ": 'name' must be a non-empty string",
                                  "characters[" + std::to_string(i) + "]");
        return Status::kParseError;
      }
      name = entry["name"].get<std::string>();
      const std::string control = detail::ControlCharacterIn(name);
      if (!control.empty() || name.find('/') != std::string::npos) {
        *error =
            where + ": 'name': " +
            (control.empty() ? "a name without '/' (it separates a crowd's characters)" : control);
        return Status::kInvalidArgument;
      }
    }
    // "fps", "foot_rotations" and "unit" are the whole walk's (--fps, --foot-rotations,
    // --unit).
    const Status read =
        detail::ReadGenerateRequest(entry, where, folder, {"fps", "foot_rotations", "unit"},
                                    {"name"}, &c.character, &c.options, &c.character_file, error);
    if (read != Status::kOk) {
      // (Not one from the character file the entry names: that says its own file and line.)
      const std::string entry_path = "characters[" + std::to_string(i) + "]";
      const std::string own = where + ": ", inline_character = where + " character: ";
      if (error->compare(0, inline_character.size(), inline_character) == 0) {
        // The entry's own "character" object: its field's line in this file.
        *error = detail::WithLine(text, source, *error, entry_path + ".character",
                                  entry_path + " character");
        return read;
      }
      const std::string rest =
          error->compare(0, own.size(), own) == 0 ? error->substr(own.size()) : std::string();
      for (const char* lead : {"'", "unknown field", "missing field", "give exactly"}) {
        if (rest.compare(0, std::strlen(lead), lead) == 0) {
          *error = detail::WithLine(text, source, *error, entry_path);
          break;
        }
      }
      return read;
    }
    c.has_start_frame = entry.contains("start_frame");
    c.has_up = entry.contains("up");
    c.name = name;
    if (name.empty()) {
      // Named after its character, with '/' (which names a crowd's characters) as '_': a
      // character named "x/c" was "x/c1", crowd "x"'s first character.
      // (An inline character without a name is "character".)
      c.name = (c.character.name.empty() ? std::string("character") : c.character.name) +
               std::to_string(i + 1);
      std::replace(c.name.begin(), c.name.end(), '/', '_');
    }
    if (!names.insert(c.name).second) {
      *error = where + ": the name '" + ShownText(c.name) + "' is another character's " +
               (name.empty() ? "(it has no 'name', and is named after its character file's name "
                               "and its place in the list: give it a 'name' of its own)"
                             : "(give each a name of its own)");
      return Status::kInvalidArgument;
    }
    scene.push_back(std::move(c));
  }
  *out = std::move(scene);
  return Status::kOk;
}

Status LoadScene(const std::string& path, std::vector<SceneCharacter>* out, std::string* error) {
  std::string text;
  const Status status =
      detail::ReadJsonFile(path, "scene file", &text, error, detail::kMaxSceneFileBytes);
  if (status != Status::kOk) return status;
  const size_t slash = path.rfind('/');
  const std::string folder = slash == std::string::npos ? "."
                             : slash == 0               ? "/"
                                                        : path.substr(0, slash);
  return ParseScene(text, path, folder, out, error);
}

namespace {

// The scene's `stopped`: its first stop, with a count of the others.
void SetSceneStopped(Walk* scene) {
  if (scene->stops.empty()) return;
  scene->stopped = scene->stops.front();
  if (scene->stops.size() > 1)
    scene->stopped += " (and " + std::to_string(scene->stops.size() - 1) + " more stopped)";
}

}  // namespace

void AddToSceneWalk(const std::string& name, Walk&& walk, Walk* scene) {
  for (WalkTrack& track : walk.tracks) {
    track.character = track.character.empty() ? name : name + "/" + track.character;
    scene->tracks.push_back(std::move(track));
  }
  std::vector<std::string> stops;
  for (const std::string& stop : walk.stops) stops.push_back(name + ": " + stop);
  if (walk.stops.empty() && !walk.stopped.empty()) stops.push_back(name + ": " + walk.stopped);
  // The engine's failures go before the terrain's stops, after those of the characters added
  // before (a walk's stops begin with its failures), so the first failure said is the scene's
  // first character's.
  const size_t failed =
      std::min(stops.size(), std::max(walk.failed_stops, walk.session_failed ? size_t{1} : 0));
  scene->stops.insert(scene->stops.begin() + static_cast<std::ptrdiff_t>(scene->failed_stops),
                      stops.begin(), stops.begin() + static_cast<std::ptrdiff_t>(failed));
  scene->stops.insert(scene->stops.end(), stops.begin() + static_cast<std::ptrdiff_t>(failed),
                      stops.end());
  scene->failed_stops += failed;
  scene->session_failed |= walk.session_failed;
  for (const std::string& note : walk.notes) scene->notes.push_back(name + ": " + note);
  SetSceneStopped(scene);
}

std::vector<std::string> OverlappingStartNotes(const std::vector<std::string>& names,
                                               const std::vector<const Walk*>& walks,
                                               const std::vector<double>& reaches) {
  // Where each character stands at the start: its first feet's centroid, each crowd member's
  // apart (tracks by their `character`; a crowd keeps its own members apart, so only members of
  // different walks are compared). (Only a crowd's first member was compared: another
  // character on its fifth went unsaid.)
  struct Start {
    size_t walk;
    std::string member;  // "" or a crowd's "cK"
    Vec3 at;
  };
  std::vector<Start> starts;
  double widest = 0;  // the largest reach: pairs farther apart than a quarter of it are not near
  for (size_t i = 0; i < walks.size(); ++i) {
    if (!walks[i]) continue;
    const size_t first = starts.size();
    std::unordered_map<std::string, size_t> member_start;  // member -> its index in starts
    std::vector<int> feet;                                 // by start, from `first`
    for (const WalkTrack& track : walks[i]->tracks) {
      if (track.kind != TrackKind::kFoot || track.keys.empty()) continue;
      const auto [m, added] = member_start.emplace(track.character, starts.size());
      if (added) starts.push_back({i, track.character, Vec3{}}), feet.push_back(0);
      starts[m->second].at += track.keys.front().position, ++feet[m->second - first];
    }
    for (size_t k = first; k < starts.size(); ++k)
      starts[k].at = starts[k].at / static_cast<double>(feet[k - first]);
    if (starts.size() > first) widest = std::max(widest, reaches[i]);
  }
  // Pairs found by sweeping along x; the first kMaxOverlappingStartNotes in the starts' order
  // are named (a scene of thousands at one start has millions of pairs).
  std::vector<size_t> by_x(starts.size());
  for (size_t k = 0; k < by_x.size(); ++k) by_x[k] = k;
  std::sort(by_x.begin(), by_x.end(),
            [&](size_t a, size_t b) { return starts[a].at.x < starts[b].at.x; });
  std::vector<std::pair<size_t, size_t>> named;  // a max-heap of the first pairs
  size_t pairs = 0;
  for (size_t u = 0; u < by_x.size(); ++u) {
    for (size_t v = u + 1; v < by_x.size(); ++v) {
      if (!(starts[by_x[v]].at.x - starts[by_x[u]].at.x <= 0.25 * widest)) break;
      const size_t a = std::min(by_x[u], by_x[v]), b = std::max(by_x[u], by_x[v]);
      const size_t i = starts[a].walk, j = starts[b].walk;
      if (i == j) continue;
      if (!(Distance(starts[a].at, starts[b].at) < 0.25 * std::min(reaches[i], reaches[j])))
        continue;
      ++pairs;
      if (named.size() < kMaxOverlappingStartNotes || std::make_pair(a, b) < named.front()) {
        named.emplace_back(a, b);
        std::push_heap(named.begin(), named.end());
        if (named.size() > kMaxOverlappingStartNotes) {
          std::pop_heap(named.begin(), named.end());
          named.pop_back();
        }
      }
    }
  }
  std::sort(named.begin(), named.end());
  auto name = [&](const Start& s) {
    return s.member.empty() ? names[s.walk] : names[s.walk] + "/" + s.member;
  };
  std::vector<std::string> notes;
  for (const auto& [a, b] : named) {
    TextStream note;
    note.precision(3);
    note << name(starts[a]) << " and " << name(starts[b]) << " start "
         << Distance(starts[a].at, starts[b].at)
         << " apart, under a quarter of their reach: they walk through each other (give them "
            "starts farther apart)";
    notes.push_back(note.str());
  }
  const size_t more = pairs - named.size();
  if (more > 0) {
    notes.push_back("... and " + std::to_string(more) + (more == 1 ? " more pair" : " more pairs") +
                    " of characters start under a quarter of their reach apart");
  }
  return notes;
}

void AddFailuresToSceneWalk(const std::vector<std::pair<std::string, std::string>>& failures,
                            Walk* scene) {
  std::vector<std::string> stops;
  for (const auto& [name, error] : failures) stops.push_back(name + " did not walk: " + error);
  scene->stops.insert(scene->stops.begin(), stops.begin(), stops.end());
  SetSceneStopped(scene);
}

}  // namespace footfall
