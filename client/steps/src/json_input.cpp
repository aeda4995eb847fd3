#include "json_input.h"

#include <algorithm>

namespace footfall::detail {

using nlohmann::json;

bool ParseJsonText(const std::string& text, const std::string& source, json* out,
                   std::string* error) {
  try {
    *out = json::parse(text);  // nlohmann skips a leading UTF-8 byte order mark
    return true;
  } catch (const json::parse_error& e) {
    size_t line = 1, column = 1;
    const size_t end = std::min(text.size(), e.byte > 0 ? static_cast<size_t>(e.byte - 1) : 0);
    for (size_t i = 0; i < end; ++i) {
      if (text[i] == '\n')
        ++line, column = 1;
      else
        ++column;
    }
    // e.what() is "[json.exception.parse_error.101] parse error at line L, column C: WHAT".
    std::string what = e.what();
    const size_t at = what.find("parse error");
    if (at != std::string::npos) {
      const size_t colon = what.find(": ", at);
      what = colon != std::string::npos ? what.substr(colon + 2) : what.substr(at);
    }
    *error = source + ":" + std::to_string(line) + ":" + std::to_string(column) +
             ": malformed JSON: " + what;
    return false;
  }
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
