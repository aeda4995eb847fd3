// A generate request as JSON, the form plugins send through the C ABI (ffc_generate):
//   {"character": {...a character file's object...} or "character_file": PATH,
//    "start": [x, y, z], "heading": [x, y, z], "path": [[x, y, z], ...], "steps": N,
//    "start_frame": F, "up": [x, y, z], "fps": 24, "crowd": N, "crowd_spacing": D,
//    "foot_rotations": true, "scale": S, "unit": "cm"}
// Every field but the character is optional, with GenerateOptions' defaults, so a request means
// the same as `footfall generate` with the same flags ("foot_rotations": --foot-rotations, the
// walk JSON's foot keys then carrying their rotations; "scale": --scale, the character's lengths
// multiplied by ScaleCharacter; "unit": --unit, the walk's unit).
#pragma once

#include <string>

#include "footfall/steps/character.h"
#include "footfall/steps/generator.h"

namespace footfall {

// Fills *character and *options from the request. kParseError / kInvalidArgument with a
// message naming the field; kIoError when character_file cannot be read.
Status ParseGenerateRequest(const std::string& text, Character* character, GenerateOptions* options,
                            std::string* error);

}  // namespace footfall
