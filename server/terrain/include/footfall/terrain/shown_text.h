// How error messages show text taken from input: a bad token of a megabyte, or one holding NUL
// or control bytes, must not become a megabyte of stderr or a message cut short.
#pragma once

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

}  // namespace footfall
