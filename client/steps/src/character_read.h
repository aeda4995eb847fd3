// Reading a character from JSON already parsed: a character file's text (ParseCharacter) or a
// character object inside a generate request or scene entry.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "footfall/steps/character.h"

namespace footfall::detail {

// Reads the character object `j`; errors begin with `source` and name the field, without a line
// (the caller knows which text `j` came from).
Status ReadCharacter(const nlohmann::json& j, const std::string& source, Character* out,
                     std::string* error);

}  // namespace footfall::detail
