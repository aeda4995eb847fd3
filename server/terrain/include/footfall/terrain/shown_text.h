// How error messages show text and numbers taken from input: a bad token of a megabyte, or one
// holding NUL or control bytes, must not become a megabyte of stderr or a message cut short.
#pragma once

#include <charconv>
#include <cstddef>
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

// " (bytes 1A)" for a token of at most 8 bytes holding bytes that do not show as themselves in
// ShownText or on a terminal (control bytes, a NUL, a no-break space, a DOS end-of-file mark),
// else "": a NUL shown as '?' read as the question mark it is not.
inline std::string HiddenBytesNote(std::string_view token) {
  bool hidden = false;
  for (const char c : token)
    hidden |= static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f;
  if (!hidden || token.size() > 8) return "";
  static const char kDigits[] = "0123456789ABCDEF";
  std::string out = " (bytes";
  for (const char c : token) {
    const unsigned char b = static_cast<unsigned char>(c);
    out += ' ', out += kDigits[b >> 4], out += kDigits[b & 15];
  }
  return out + ")";
}

// The length of the well-formed UTF-8 sequence at `text[at]` (RFC 3629: no overlong forms, no
// surrogates, nothing past U+10FFFF), or 0 when the bytes there are not one (or `at` is past the
// end).
inline size_t Utf8SequenceLength(std::string_view text, size_t at) {
  const auto byte = [&](size_t i) -> unsigned {
    return at + i < text.size() ? static_cast<unsigned char>(text[at + i]) : 0u;
  };
  if (at >= text.size()) return 0;
  const unsigned lead = byte(0);
  size_t length = 0;
  unsigned low = 0x80, high = 0xBF;  // the second byte's range
  if (lead < 0x80) return 1;
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) low = 0xA0;   // overlong
    if (lead == 0xED) high = 0x9F;  // surrogates
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) low = 0x90;   // overlong
    if (lead == 0xF4) high = 0x8F;  // past U+10FFFF
  } else {
    return 0;  // a continuation byte, an overlong lead (C0, C1), or F5 to FF
  }
  if (byte(1) < low || byte(1) > high) return 0;
  for (size_t i = 2; i < length; ++i)
    if (byte(i) < 0x80 || byte(i) > 0xBF) return 0;
  return length;
}

// True when the UTF-8 sequence of `length` bytes (Utf8SequenceLength) at `text[at]` is a
// control character: C0, DEL, or C1 (U+0080 to U+009F, which some terminals obey as escapes).
inline bool IsControlCharacter(std::string_view text, size_t at, size_t length) {
  const unsigned c = static_cast<unsigned char>(text[at]);
  if (length == 1) return c < 0x20 || c == 0x7f;
  return length == 2 && c == 0xc2 && static_cast<unsigned char>(text[at + 1]) <= 0x9f;
}

// `text` cut to at most `bytes` bytes, never inside a UTF-8 sequence: a cut message stays text.
inline std::string_view Utf8Prefix(std::string_view text, size_t bytes) {
  if (text.size() <= bytes) return text;
  size_t cut = bytes;
  // Back over at most three continuation bytes to the start of the sequence the cut splits.
  for (int back = 0; back < 3 && cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80;
       ++back)
    --cut;
  if ((static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) cut = bytes;  // not UTF-8 anyway
  return text.substr(0, cut);
}

// `text` within `bytes` bytes (at least 64), cut in its middle where it is longer ("head ...
// tail", never inside a UTF-8 sequence): a message quoting a long path keeps its reason, which
// comes last (cut at its end, it lost it).
inline std::string Utf8Shortened(std::string_view text, size_t bytes) {
  if (text.size() <= bytes) return std::string(text);
  constexpr std::string_view kGap = " ... ";
  const size_t tail_bytes = bytes / 3;
  size_t from = text.size() - tail_bytes;
  // Forward over continuation bytes to the start of a sequence.
  for (int on = 0;
       on < 3 && from < text.size() && (static_cast<unsigned char>(text[from]) & 0xC0) == 0x80;
       ++on)
    ++from;
  const std::string_view tail = text.substr(from);
  std::string out(Utf8Prefix(text, bytes - kGap.size() - tail.size()));
  out += kGap;
  out += tail;
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
