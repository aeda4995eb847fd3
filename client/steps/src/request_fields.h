// The fields of a generate request (generate_request.h), read from an object already parsed:
// shared by the C ABI's requests and the characters of a scene file (scene.h). Private to
// footfall::steps.
#pragma once

#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "footfall/steps/character.h"
#include "footfall/steps/generator.h"

namespace footfall::detail {

// Fills *character and *options from the request object `j`, naming errors after `source`
// ("request", "scene.json: characters[2]"); a relative character_file is read from `folder`
// when it is not empty, and that file's errors are then prefixed with `source` too. Fields in
// `refused` are unknown here; fields in `read_by_caller` are skipped (the caller reads them) and
// listed among the known fields when an unknown one is refused. *character_file (if not null)
// receives the path the character was read from, or "" for an inline character. Statuses as
// ParseGenerateRequest.
Status ReadGenerateRequest(const nlohmann::json& j, const std::string& source,
                           const std::string& folder, const std::set<std::string>& refused,
                           const std::set<std::string>& read_by_caller, Character* character,
                           GenerateOptions* options, std::string* character_file,
                           std::string* error);

}  // namespace footfall::detail
