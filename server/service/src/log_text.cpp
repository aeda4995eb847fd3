#include "log_text.h"

#include <algorithm>

#include "footfall/terrain/shown_text.h"

namespace footfall {

std::string EscapeControl(const std::string& text) {
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  const auto escape = [&](unsigned char u) {
    out += "\\x";
    out += kHex[u >> 4];
    out += kHex[u & 15];
  };
  for (size_t at = 0; at < text.size();) {
    const char c = text[at];
    const unsigned char u = static_cast<unsigned char>(c);
    const size_t length = Utf8SequenceLength(text, at);
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (length == 0) {
      escape(u);  // one byte, then read on from the next: the log stays in step
    } else if (IsControlCharacter(text, at, length)) {
      for (size_t k = 0; k < length; ++k) escape(static_cast<unsigned char>(text[at + k]));
    } else {
      out.append(text, at, length);
    }
    at += std::max<size_t>(length, 1);
  }
  return out;
}

}  // namespace footfall
