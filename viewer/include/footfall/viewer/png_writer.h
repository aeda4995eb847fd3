// Writes screenshots as PNG (stb_image_write).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace footfall::viewer {

// Writes width x height RGBA rows (top row first) to `path` as an RGB PNG. False with a
// message naming the file on failure.
bool WritePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgba,
              std::string* error);

}  // namespace footfall::viewer
