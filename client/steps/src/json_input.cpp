#include "json_input.h"

#include <algorithm>
#include <cstdio>
#include <vector>

#include "footfall/terrain/shown_text.h"

namespace footfall::detail {

using nlohmann::json;

namespace {

// 1-based line and column (in bytes) of byte `at` of `text`.
std::string Where(const std::string& text, size_t at) {
  size_t line = 1, column = 1;
  for (size_t i = 0; i < std::min(at, text.size()); ++i) {
    if (text[i] == '\n')
      ++line, column = 1;
    else
      ++column;
  }
  return std::to_string(line) + ":" + std::to_string(column);
}

// Thrown from the parser callback to stop at a repeated key.
struct DuplicateKey {
  std::string key;
};

}  // namespace

bool ParseJsonText(const std::string& text, const std::string& source, json* out,
                   std::string* error, int max_depth) {
  // nlohmann stops at a NUL byte as at the end of the input ("unexpected end of input" with 40
  // lines still to come): name it.
  const size_t nul = text.find('\0');
  if (nul != std::string::npos) {
    *error = source + ":" + Where(text, nul) + ": malformed JSON: a NUL byte (JSON text has none)";
    return false;
  }
  bool too_deep = false;
  // Keys seen in each object being parsed, innermost last.
  std::vector<std::set<std::string>> keys;
  auto check = [&](int depth, json::parse_event_t event, json& parsed) {
    too_deep |= max_depth > 0 && depth > max_depth;
    if (event == json::parse_event_t::object_start) {
      keys.emplace_back();
    } else if (event == json::parse_event_t::object_end) {
      if (!keys.empty()) keys.pop_back();
    } else if (event == json::parse_event_t::key && !keys.empty() && parsed.is_string()) {
      if (!keys.back().insert(parsed.get<std::string>()).second)
        throw DuplicateKey{parsed.get<std::string>()};
    }
    return true;
  };
  try {
    *out = json::parse(text, check);  // nlohmann skips a leading UTF-8 byte order mark
  } catch (const json::parse_error& e) {
    // e.what() is "[json.exception.parse_error.101] parse error at line L, column C: WHAT".
    std::string what = e.what();
    const size_t at = what.find("parse error");
    if (at != std::string::npos) {
      const size_t colon = what.find(": ", at);
      what = colon != std::string::npos ? what.substr(colon + 2) : what.substr(at);
    }
    *error = source + ":" + Where(text, e.byte > 0 ? static_cast<size_t>(e.byte - 1) : 0) +
             ": malformed JSON: " + what;
    return false;
  } catch (const json::out_of_range& e) {
    // "[json.exception.out_of_range.406] number overflow parsing '1e999'": located at the first
    // place the number is written.
    std::string what = e.what();
    const size_t bracket = what.find("] ");
    if (bracket != std::string::npos) what = what.substr(bracket + 2);
    const size_t q = what.find('\'');
    const size_t q2 = q == std::string::npos ? q : what.find('\'', q + 1);
    size_t found = std::string::npos;
    if (q2 != std::string::npos) {
      const std::string token = what.substr(q + 1, q2 - q - 1);
      found = text.find(token);
      what = what.substr(0, q + 1) + ShownText(token) + what.substr(q2);
    }
    *error = source + (found != std::string::npos ? ":" + Where(text, found) : std::string()) +
             ": malformed JSON: " + what + " (beyond the range of a double)";
    return false;
  } catch (const json::exception& e) {
    *error = source + ": malformed JSON: " + e.what();
    return false;
  } catch (const DuplicateKey& d) {
    *error = source + ": malformed JSON: the key '" + ShownText(d.key) +
             "' appears twice in one object (each field once)";
    return false;
  }
  if (too_deep) {
    *error = source + ": nested deeper than " + std::to_string(max_depth) + " levels";
    return false;
  }
  return true;
}

std::string ControlCharacterIn(const std::string& name) {
  for (size_t i = 0; i < name.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (c < 0x20 || c == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02x", c);
      return "expected a name without control characters (byte " + std::string(hex) +
             " at offset " + std::to_string(i) + ")";
    }
  }
  return "";
}

bool IsInteger(const json& j, int64_t expected) {
  if (j.is_number_unsigned()) return expected >= 0 && j.get<uint64_t>() == uint64_t(expected);
  return j.is_number_integer() && j.get<int64_t>() == expected;
}

bool FindUnknownKey(const json& j, const std::set<std::string>& known, std::string* key) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!known.count(it.key())) {
      *key = it.key();
      return true;
    }
  }
  return false;
}

std::string UnknownFieldMessage(const std::string& key, const std::set<std::string>& known) {
  std::string list;
  for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
  return "unknown field '" + key + "' (known fields: " + list + ")";
}

}  // namespace footfall::detail
