#include "json_input.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "footfall/terrain/c_locale.h"
#include "footfall/terrain/input_file.h"
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

// Where in `text` (valid JSON up to it) a key first appears a second time in one object: the byte
// offset of its opening quote, or npos. (nlohmann's callback says which key, not where.)
size_t RepeatedKeyAt(const std::string& text) {
  std::vector<std::set<std::string>> objects;  // keys of each open object, innermost last
  std::vector<bool> is_object;                 // each open bracket: object or array
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '{' || c == '[') {
      is_object.push_back(c == '{');
      if (c == '{') objects.emplace_back();
    } else if (c == '}' || c == ']') {
      if (!is_object.empty() && is_object.back() && !objects.empty()) objects.pop_back();
      if (!is_object.empty()) is_object.pop_back();
    } else if (c == '"') {
      size_t end = i + 1;
      while (end < text.size() && text[end] != '"') end += text[end] == '\\' ? 2 : 1;
      if (end >= text.size()) return std::string::npos;
      size_t next = text.find_first_not_of(" \t\r\n", end + 1);
      if (next != std::string::npos && text[next] == ':' && !is_object.empty() &&
          is_object.back() && !objects.empty()) {
        std::string key;
        try {
          key = json::parse(text.substr(i, end + 1 - i)).get<std::string>();
        } catch (const json::exception&) {
          return std::string::npos;
        }
        if (!objects.back().insert(key).second) return i;
      }
      i = end;
    }
  }
  return std::string::npos;
}

}  // namespace

namespace {

bool HasChildren(const json& j) { return (j.is_array() || j.is_object()) && !j.empty(); }

json& LastChild(json& j) { return j.is_array() ? j.back() : std::prev(j.end()).value(); }

// Removes the last child of `j` (one without children: destroyed without allocating).
void DropLastChild(json* j) {
  if (j->is_array())
    j->get_ref<json::array_t&>().pop_back();
  else
    j->get_ref<json::object_t&>().erase(std::prev(j->get_ref<json::object_t&>().end()));
}

}  // namespace

void JsonDocument::ReserveDepth(size_t depth) {
  if (path_.capacity() < depth + 2) path_.reserve(2 * (depth + 2));
}

void JsonDocument::Release() noexcept {
  path_.clear();
  if (HasChildren(value)) path_.push_back(&value);  // room reserved at construction
  while (!path_.empty()) {
    json* node = path_.back();
    if (!HasChildren(*node)) {
      path_.pop_back();  // emptied: its parent drops it next
      continue;
    }
    json* last = &LastChild(*node);
    if (!HasChildren(*last)) {
      DropLastChild(node);
      continue;
    }
    if (path_.size() < path_.capacity()) {
      path_.push_back(last);
      continue;
    }
    // Deeper than reserved: down the last children from here to one whose last child has none,
    // which goes.
    while (HasChildren(LastChild(*last))) last = &LastChild(*last);
    DropLastChild(last);
  }
  value = nullptr;
}

bool ParseJsonText(const std::string& text, const std::string& source, JsonDocument* document,
                   std::string* error, int max_depth, const JsonFilter& filter) {
  // UTF-16 and UTF-32 text are named as such (their NUL bytes are not a stray byte).
  const std::string wide = WideTextProblem(text);
  if (!wide.empty()) {
    *error = source + ":1: " + wide;
    return false;
  }
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
  // Where an object or array the filter leaves out is released (the parser would destroy it
  // with nlohmann's destructor, which allocates).
  JsonDocument left_out;
  auto check = [&](int depth, json::parse_event_t event, json& parsed) {
    too_deep |= max_depth > 0 && depth > max_depth;
    if (event == json::parse_event_t::object_start || event == json::parse_event_t::array_start) {
      document->ReserveDepth(static_cast<size_t>(depth) + 1);
      if (filter) left_out.ReserveDepth(static_cast<size_t>(depth) + 1);
    }
    if (event == json::parse_event_t::object_start) {
      keys.emplace_back();
    } else if (event == json::parse_event_t::object_end) {
      if (!keys.empty()) keys.pop_back();
    } else if (event == json::parse_event_t::key && !keys.empty() && parsed.is_string()) {
      if (!keys.back().insert(parsed.get<std::string>()).second)
        throw DuplicateKey{parsed.get<std::string>()};
    }
    if (!filter || filter(depth, event, parsed)) return true;
    if (event == json::parse_event_t::object_end || event == json::parse_event_t::array_end) {
      using std::swap;
      swap(parsed, left_out.value);  // (noexcept) the parser then discards a null
      left_out.Release();
    }
    return false;
  };
  // Numbers read as written whatever the host program's locale (a Pashto decimal point).
  const CLocaleScope c_locale;
  try {
    // Parsed straight into the document (nlohmann's parse builds it in a value of its own,
    // destroyed by its destructor when parsing throws). nlohmann skips a leading UTF-8 byte
    // order mark.
    document->Release();
    json* out = &document->value;
    nlohmann::detail::json_sax_dom_callback_parser<json> builder(*out, check, true);
    json::sax_parse(text, &builder);
    if (out->is_discarded()) *out = nullptr;  // the whole document left out by the filter
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
    const size_t at = RepeatedKeyAt(text);
    *error = source + (at != std::string::npos ? ":" + Where(text, at) : std::string()) +
             ": malformed JSON: the key '" + ShownText(d.key) +
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
    char what[32] = "";
    if (c < 0x20 || c == 0x7f) {
      std::snprintf(what, sizeof what, "byte 0x%02x", c);
    } else if (c == 0xC2 && i + 1 < name.size() &&
               static_cast<unsigned char>(name[i + 1]) >= 0x80 &&
               static_cast<unsigned char>(name[i + 1]) <= 0x9F) {
      // C1 controls (U+0080 to U+009F) are 0xC2 0x80..0x9F in UTF-8.
      std::snprintf(what, sizeof what, "character U+%04X", static_cast<unsigned char>(name[i + 1]));
    }
    if (what[0] != '\0')
      return "expected a name without control characters (" + std::string(what) + " at offset " +
             std::to_string(i) + ")";
  }
  return "";
}

bool IsInteger(const json& j, int64_t expected) {
  if (j.is_number_unsigned()) return expected >= 0 && j.get<uint64_t>() == uint64_t(expected);
  if (j.is_number_float()) return j.get<double>() == static_cast<double>(expected);  // 1.0
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
  return "unknown field '" + ShownText(key) + "' (known fields: " + list + ")";
}

Status ReadJsonFile(const std::string& path, const char* what, std::string* text,
                    std::string* error, uint64_t max_bytes) {
  const Status status = CheckInputFile(path, what, error);
  if (status != Status::kOk) return status;
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    // The file exists (CheckInputFile): the reason is the open's (permissions, descriptors).
    const int open_error = errno;
    *error = path + ": cannot open " + what +
             (open_error ? ": " + std::string(std::strerror(open_error)) : "");
    return Status::kIoError;
  }
  // Read straight into the string (through a stringstream the text stood twice in memory).
  // A file whose end cannot be sought (those of /proc) has no size to read ahead: it is read
  // to its end all the same (it read as empty).
  in.seekg(0, std::ios::end);
  const std::streamoff size = std::max<std::streamoff>(0, in.tellg());
  in.clear();
  in.seekg(0, std::ios::beg);
  auto too_large = [&](uint64_t bytes) {
    *error = path + ": " + std::to_string(bytes) + " bytes, more than the " +
             std::to_string(max_bytes >> 20) + " MB a " + what + " may have";
    return Status::kLimitExceeded;
  };
  if (max_bytes > 0 && static_cast<uint64_t>(size) > max_bytes) return too_large(size);
  text->clear();
  try {
    if (size > 0) {
      text->resize(static_cast<size_t>(size));
      in.read(text->data(), size);
      text->resize(static_cast<size_t>(in.gcount()));
    }
    // A file that grew while it was read: the rest too.
    char buffer[65536];
    while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
      text->append(buffer, static_cast<size_t>(in.gcount()));
      if (max_bytes > 0 && text->size() > max_bytes) {
        const uint64_t bytes = text->size();
        std::string().swap(*text);
        return too_large(bytes);
      }
    }
  } catch (const std::bad_alloc&) {
    std::string().swap(*text);
    *error = path + ": out of memory reading the " + std::string(what) + " (" +
             std::to_string(size) + " bytes)";
    return Status::kLimitExceeded;
  }
  if (in.bad()) {
    *error = path + ": cannot read " + what;
    return Status::kIoError;
  }
  return Status::kOk;
}

// The 1-based line of `text` (valid JSON) where the value at `where` starts ("tracks[2].keys[5]
// .position": field names and array indices from the root object), or, when there is no such
// value (a missing field), where the nearest enclosing value that exists starts.
size_t LineOf(const std::string& text, const std::string& where) {
  // `where` as steps: a field name, or an array index written "[i]".
  std::vector<std::string> steps;
  for (size_t i = 0; i < where.size();) {
    if (where[i] == '.') {
      ++i;
    } else if (where[i] == '[') {
      const size_t end = where.find(']', i);
      steps.push_back(where.substr(i, end - i + 1));
      i = end == std::string::npos ? where.size() : end + 1;
    } else {
      const size_t end = where.find_first_of(".[", i);
      steps.push_back(where.substr(i, end - i));
      i = end == std::string::npos ? where.size() : end;
    }
  }
  // The containers open around the scan: each one's step to the value being read.
  struct Level {
    bool object;
    bool expect_key;
    std::string step;  // the field name, or "[i]"
    size_t index;
  };
  std::vector<Level> levels;
  size_t line = 1, best_line = 1, best_depth = 0;
  // A value starts at the current path: the deepest one along `where` is remembered.
  auto value_starts = [&]() {
    size_t depth = 0;
    while (depth < levels.size() && depth < steps.size() && levels[depth].step == steps[depth])
      ++depth;
    if (depth == levels.size() && depth >= best_depth) {
      best_depth = depth, best_line = line;
      return depth == steps.size();
    }
    return false;
  };
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
    } else if (c == '"') {
      const size_t begin = i + 1;
      for (++i; i < text.size() && text[i] != '"'; ++i)
        if (text[i] == '\\') ++i;
      if (!levels.empty() && levels.back().object && levels.back().expect_key) {
        levels.back().step = text.substr(begin, i - begin);  // (as written: escapes kept)
        levels.back().expect_key = false;
      } else if (value_starts()) {
        return best_line;
      }
    } else if (c == ',') {
      if (!levels.empty() && levels.back().object)
        levels.back().expect_key = true;
      else if (!levels.empty())
        levels.back().step = "[" + std::to_string(++levels.back().index) + "]";
    } else if (c == '{' || c == '[') {
      if (value_starts()) return best_line;
      levels.push_back({c == '{', c == '{', c == '{' ? "" : "[0]", 0});
    } else if (c == '}' || c == ']') {
      if (!levels.empty()) levels.pop_back();
    } else if (c == '-' || (c >= '0' && c <= '9') || c == 't' || c == 'f' || c == 'n') {
      if (value_starts()) return best_line;
      // The rest of the number or literal (the text holds no NUL: ParseJsonText refuses it).
      while (i + 1 < text.size() && std::strchr(",]} \t\r\n", text[i + 1]) == nullptr) ++i;
    }
  }
  return best_line;
}

std::string WithLine(const std::string& text, const std::string& source, std::string message,
                     const std::string& within, const std::string& within_text) {
  // The field a message names first, right after the source and any "characters[i]: "
  // ("'feet'[2]: ...", "characters[1]: 'start': ..."), with its index when it has one.
  size_t at = message.compare(0, source.size() + 2, source + ": ") == 0 ? source.size() + 2 : 0;
  std::string where = within;
  const std::string& said = within_text.empty() ? within : within_text;
  if (!said.empty() && message.compare(at, said.size() + 2, said + ": ") == 0)
    at += said.size() + 2;
  for (const char* lead : {"unknown field ", "missing field "}) {
    if (message.compare(at, std::strlen(lead), lead) == 0) at += std::strlen(lead);
  }
  if (at < message.size() && message[at] == '\'') {
    const size_t close = message.find('\'', at + 1);
    if (close != std::string::npos) {
      std::string key = message.substr(at + 1, close - at - 1);
      // "path[1]" written inside the quotes, or "'feet'[2]" after them: an index.
      std::string index;
      const size_t bracket = key.find('[');
      if (bracket != std::string::npos) {
        index = key.substr(bracket), key.erase(bracket);
      } else if (close + 1 < message.size() && message[close + 1] == '[') {
        const size_t end = message.find(']', close + 1);
        if (end != std::string::npos) {
          index = message.substr(close + 1, end - close);
          // "'feet'[0].comment": the field within.
          size_t name_end = end + 1;
          if (name_end < message.size() && message[name_end] == '.') {
            ++name_end;
            while (name_end < message.size() &&
                   (std::isalnum(static_cast<unsigned char>(message[name_end])) ||
                    message[name_end] == '_'))
              ++name_end;
            index += message.substr(end + 1, name_end - end - 1);
          }
        }
      }
      where += (where.empty() ? "" : ".") + key + index;
    }
  }
  if (where.empty()) return message;
  return message + " (line " + std::to_string(LineOf(text, where)) + ")";
}

}  // namespace footfall::detail
