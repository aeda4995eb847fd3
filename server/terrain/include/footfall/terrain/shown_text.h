// How error messages show text and numbers taken from input: a bad token of a megabyte, or one
// holding NUL or control bytes, must not become a megabyte of stderr or a message cut short.
#pragma once

#include <charconv>
#include <string>
#include <string_view>

namespace footfall {

// `text` with control characters shown as '?' (C0 bytes, DEL, and the C1 controls U+0080 to
// U+009F as UTF-8, which some terminals obey as escapes), at most 40 bytes of it: longer text
// as its first 32 bytes, "...", and its length.
inline std::string ShownText(std::string_view text) {
  constexpr size_t kMax = 40, kHead = 32;
  const std::string_view head = text.substr(0, text.size() > kMax ? kHead : text.size());
  std::string out;
  for (size_t i = 0; i < head.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(head[i]);
    // A C1 control is 0xC2 then 0x80 to 0x9F (its second byte may lie past the head).
    const bool c1 = c == 0xc2 && i + 1 < text.size() &&
                    static_cast<unsigned char>(text[i + 1]) >= 0x80 &&
                    static_cast<unsigned char>(text[i + 1]) <= 0x9f;
    if (c1) ++i;
    out += c < 0x20 || c == 0x7f || c1 ? '?' : head[i];
  }
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
