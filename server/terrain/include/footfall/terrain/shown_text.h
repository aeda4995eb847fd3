// How error messages show text and numbers taken from input: a bad token of a megabyte, or one
// holding NUL or control bytes, must not become a megabyte of stderr or a message cut short.
#pragma once

#include <charconv>
#include <string>
#include <string_view>

namespace footfall {

// `text` with control bytes shown as '?', at most 40 bytes of it: longer text as its first 32
// bytes, "...", and its length.
inline std::string ShownText(std::string_view text) {
  constexpr size_t kMax = 40, kHead = 32;
  std::string out(text.substr(0, text.size() > kMax ? kHead : text.size()));
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  if (text.size() > kMax) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

// The shortest text that reads back as `value` ("1.0000001", "2147483648", "0.1"): a message's
// number never rounds onto the limit it breaks.
inline std::string NumberText(double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

}  // namespace footfall
