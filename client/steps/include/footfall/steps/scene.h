// A scene file: several characters on one terrain, each with its own character file, start,
// heading, path, steps and crowd, for `footfall generate --scene`. JSON, versioned:
//   {"format": "footfall-scene", "version": 1, "comment": "...",
//    "characters": [{"name": "spider", "character_file": "octopod.json", "start": [x, y, z],
//                    "heading": [x, y, z], "path": [[x, y, z], ...], "steps": N,
//                    "start_frame": F, "up": [x, y, z], "crowd": N, "crowd_spacing": D,
//                    "scale": S}, ...]}
// Each character takes the fields of a generate request (generate_request.h) but "fps",
// "foot_rotations" and "unit", which are the whole walk's; "name" names its tracks (default: its
// character's name and its place in the list, "biped1"); a relative character_file is read from the
// scene file's folder.
#pragma once

#include <string>
#include <vector>

#include "footfall/steps/character.h"
#include "footfall/steps/generator.h"
#include "footfall/steps/walk.h"

namespace footfall {

constexpr int kSceneFormatVersion = 1;
constexpr size_t kMaxSceneCharacters = 10000;

struct SceneCharacter {
  std::string name;  // unique within the scene
  Character character;
  // Its start, heading, path, steps, crowd and spacing as given; start_frame and up as given
  // when has_start_frame / has_up, else the command's.
  GenerateOptions options;
  bool has_start_frame = false;
  bool has_up = false;
  std::string character_file;  // as read (resolved against the scene's folder), or ""
};

// Reads the scene file at `path`. kParseError / kInvalidArgument with "PATH: ..." naming the
// field (characters[i] and its key); a character file's own errors as LoadCharacter gives them.
Status LoadScene(const std::string& path, std::vector<SceneCharacter>* out, std::string* error);

// The same from text; `source` names it in errors, `folder` is where relative character files
// are read from.
Status ParseScene(const std::string& text, const std::string& source, const std::string& folder,
                  std::vector<SceneCharacter>* out, std::string* error);

// Adds the walk of scene character `name` to the scene's walk: its tracks, their `character`
// set to the name (a crowd's "NAME/c1" ...), and its stop reasons and notes prefixed with the
// name. The scene's `stopped` is the first character's to stop, with a count of the others.
void AddToSceneWalk(const std::string& name, Walk&& walk, Walk* scene);

// Records in the scene's walk the characters that could not walk at all, as (name, reason):
// first among its stops ("NAME did not walk: REASON"), so that the files written with the
// others' walks say who is missing.
void AddFailuresToSceneWalk(const std::vector<std::pair<std::string, std::string>>& failures,
                            Walk* scene);

// Notes for scene characters that start on top of each other: for each pair of `names` whose
// walks' first feet centre under a quarter of the smaller `reaches` apart, "A and B start D
// apart: they walk through each other" (two scene characters given one start were walked as
// one, silently). Each member of a crowd is compared with the other walks' characters (named
// "NAME/cK"), not with its own crowd, which keeps its members apart.
// walks[i] may be null (a character that did not walk). Up to kMaxOverlappingStartNotes pairs
// are named, the others counted in one more note (a scene of thousands at one start has
// millions of pairs).
std::vector<std::string> OverlappingStartNotes(const std::vector<std::string>& names,
                                               const std::vector<const Walk*>& walks,
                                               const std::vector<double>& reaches);

// The most pairs OverlappingStartNotes names.
constexpr size_t kMaxOverlappingStartNotes = 10;

// Scene characters walked at once over a session that is not in process (GenerateSceneWalks).
constexpr size_t kJoinedSceneCharacters = 64;

// One scene character's walk, as GenerateSceneWalks made it.
struct SceneWalk {
  bool walked = false;          // GenerateWalk ran for it (false: an earlier one ran out of memory)
  Status status = Status::kOk;  // GenerateWalk's
  std::string error;
  bool out_of_memory = false;  // generating it ran out of memory (status kLimitExceeded)
  Walk walk;
};

// Generates the walk of every scene character on one loaded terrain: (*out)[i] for
// characters[i] with options[i], as GenerateWalk takes them. Over a session that answers in
// process, they walk one after the other. Over any other (RPC), up to kJoinedSceneCharacters
// walk at once, each on a thread of its own, their rounds of queries joined into one session
// call per round (JoinedCalls): one round trip for the whole scene, not one per character.
// Either way a character that fails leaves the others walking (in process, one that runs out of
// memory leaves the rest unwalked).
// The walks are the same either way. options[i].progress may be called from several threads
// at once.
void GenerateSceneWalks(TerrainSession& session, TerrainHandle terrain,
                        const std::vector<const Character*>& characters,
                        const std::vector<GenerateOptions>& options, std::vector<SceneWalk>* out);

}  // namespace footfall
