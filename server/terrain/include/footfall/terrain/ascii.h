// Letter case of ASCII text whatever the process's locale: std::tolower follows LC_CTYPE, and a
// host program's Turkish locale (a plugin's Maya or Blender) does not lower 'I' to 'i', so a
// height map's CELLSIZE header was refused as unknown.
#pragma once

namespace footfall {

inline char AsciiLower(char c) {
  return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c;
}
inline char AsciiUpper(char c) {
  return c >= 'a' && c <= 'z' ? static_cast<char>(c - 'a' + 'A') : c;
}

}  // namespace footfall
