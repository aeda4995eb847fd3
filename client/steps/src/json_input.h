// Reading footfall's JSON files (character files, walks): syntax errors with their line and
// column, JSON type names for messages, exact version numbers and unknown fields. Private to
// footfall::steps.
#pragma once

#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "footfall/terrain/status.h"

namespace footfall::detail {

// A parsed JSON document, released from its deepest values up when it goes, allocating nothing:
// nlohmann's destructor of a value with children allocates (a list of them), and an exception
// from a destructor ends the process, so a document destroyed while memory ran out aborted the
// program, or the host of the C ABI. Parse into one with ParseJsonText, so that memory running
// out while it is parsed or read is an error, not an abort.
class JsonDocument {
 public:
  nlohmann::json value;

  JsonDocument() { path_.reserve(16); }
  ~JsonDocument() { Release(); }
  JsonDocument(const JsonDocument&) = delete;
  JsonDocument& operator=(const JsonDocument&) = delete;

  // Makes room to release `value` nested `depth` levels deep in time linear in its size (a
  // deeper one is released all the same, the levels beyond in time proportional to their
  // depth). Throws std::bad_alloc, unchanged, when memory runs out.
  void ReserveDepth(size_t depth);
  // Empties `value` (null), allocating nothing, recursing not at all.
  void Release() noexcept;

 private:
  std::vector<nlohmann::json*> path_;  // the values from `value` down to the one being emptied
};

// Parses `text` (a leading UTF-8 byte order mark is skipped) into out->value. On malformed
// JSON returns false with "SOURCE:LINE:COLUMN: malformed JSON: WHAT" in *error, LINE and COLUMN
// (1-based, column in bytes) locating the last byte the parser read. Also refused, as malformed: a
// NUL byte, a number beyond the range of a double, a key repeated within one object, and (when
// max_depth > 0) nesting deeper than max_depth.
//
// `filter`, when given, sees every parse event after those checks, as nlohmann's parser callback
// does (depth, event, the value parsed), and returns false to leave that value out of *out: a
// reader can take values as they are parsed, rather than hold the whole document.
using JsonFilter =
    std::function<bool(int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed)>;
bool ParseJsonText(const std::string& text, const std::string& source, JsonDocument* out,
                   std::string* error, int max_depth = 0, const JsonFilter& filter = nullptr);

// The largest character and scene files read [Units: bytes]: a character is a few kilobytes,
// a scene of thousands of inline characters some megabytes (a 3 GB file was read whole, into
// 3 GB of memory, before its first byte was refused).
constexpr uint64_t kMaxCharacterFileBytes = uint64_t{16} << 20;
constexpr uint64_t kMaxSceneFileBytes = uint64_t{256} << 20;

// Reads the whole of the file at `path` into *text, after CheckInputFile (a regular file);
// `what` names it in errors ("character file": "PATH: cannot open character file"). A file of
// more than `max_bytes` (0: no bound) is kLimitExceeded before it is read, and one memory does
// not hold kLimitExceeded naming it.
Status ReadJsonFile(const std::string& path, const char* what, std::string* text,
                    std::string* error, uint64_t max_bytes = 0);

// When `name` holds a control character (a byte below 0x20, or 0x7f: NUL, newline, escape...),
// which no exporter or DCC can keep in a name: "a name without control characters (byte 0xNN
// at offset K)"; else "".
std::string ControlCharacterIn(const std::string& name);

// True when `j` is a number equal to the integer `expected` (1 or 1.0), with no wrap-around
// (4294967297 is not 1).
bool IsInteger(const nlohmann::json& j, int64_t expected);

// True when object `j` has a key not in `known`; *key is then the first such key.
bool FindUnknownKey(const nlohmann::json& j, const std::set<std::string>& known, std::string* key);

// "unknown field 'KEY' (known fields: a, b, c)", with the known fields in sorted order.
std::string UnknownFieldMessage(const std::string& key, const std::set<std::string>& known);

// The 1-based line of `text` (valid JSON) where the value at `where` starts ("tracks[2].keys[5]
// .position": field names and array indices from the root object), or, when there is no such
// value (a missing field), where the nearest enclosing value that exists starts.
size_t LineOf(const std::string& text, const std::string& where);

// `message` (an error about `text`, read from `source`) with " (line N)" added: the line of the
// field it names first, as "SOURCE: [WITHIN: ]'field'..." (within: a path such as
// "characters[1]" the field lies in, said in the message as `within_text` when that is given),
// or of `within` itself when it names none. Unchanged when it names neither.
std::string WithLine(const std::string& text, const std::string& source, std::string message,
                     const std::string& within = "", const std::string& within_text = "");

}  // namespace footfall::detail
