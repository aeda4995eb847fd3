#include "mesh_file_checks.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "footfall/terrain/ascii.h"
#include "footfall/terrain/decimal_number.h"
#include "footfall/terrain/input_file.h"
#include "footfall/terrain/samples.h"
#include "footfall/terrain/shown_text.h"
#include "footfall/terrain/text_stream.h"

namespace footfall::detail {
namespace {

Status Fail(const std::string& where, const std::string& what, std::string* error) {
  if (error) *error = where + ": " + what;
  return Status::kParseError;
}

std::string At(const std::string& path, size_t line) { return path + ":" + std::to_string(line); }

// The error for a line of a text mesh longer than kMaxLineBytes.
Status TooLongLine(const std::string& path, const LineReader& lines, std::string* error) {
  return Fail(At(path, lines.line_number()), LineReader::TooLongMessage("the lines of a text mesh"),
              error);
}

// Reads binary PLY values of a named type, in the file's byte order, through a buffer.
class PlyValues {
 public:
  PlyValues(std::istream& in, bool big_endian) : in_(in), swap_(big_endian) {}
  // The next value of `type` as a double; false at the end of the data.
  bool Next(const std::string& type, double* out) {
    unsigned char b[8];
    const int size = SizeOf(type);
    if (size == 0 || !Take(b, size)) return false;
    if (swap_) std::reverse(b, b + size);
    if (type == "char" || type == "int8")
      *out = static_cast<int8_t>(b[0]);
    else if (type == "uchar" || type == "uint8")
      *out = b[0];
    else if (type == "short" || type == "int16")
      *out = Get<int16_t>(b);
    else if (type == "ushort" || type == "uint16")
      *out = Get<uint16_t>(b);
    else if (type == "int" || type == "int32")
      *out = Get<int32_t>(b);
    else if (type == "uint" || type == "uint32")
      *out = Get<uint32_t>(b);
    else if (type == "float" || type == "float32")
      *out = Get<float>(b);
    else
      *out = Get<double>(b);
    return true;
  }
  // Bytes of a PLY type, 0 for an unknown one.
  static int SizeOf(const std::string& type) {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" ||
        type == "float32")
      return 4;
    if (type == "double" || type == "float64") return 8;
    return 0;
  }

  // Bytes read through Next so far.
  long long taken() const { return taken_; }
  // Whether the `count` bytes after those read are only a line end ("\n" or "\r\n"), as some
  // writers end a binary PLY.
  bool RestIsLineEnd(long long count) {
    unsigned char b[2];
    if (count > 2 || !Take(b, static_cast<int>(count))) return false;
    return count == 0 || (b[count - 1] == '\n' && (count == 1 || b[0] == '\r'));
  }

 private:
  template <typename T>
  static T Get(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof v);  // little-endian hosts (every platform we build for)
    return v;
  }
  bool Take(unsigned char* out, int size) {
    for (int i = 0; i < size; ++i) {
      if (at_ == end_) {
        in_.read(reinterpret_cast<char*>(buffer_), sizeof buffer_);
        at_ = buffer_, end_ = buffer_ + in_.gcount();
        if (at_ == end_) return false;
      }
      out[i] = *at_++;
    }
    taken_ += size;
    return true;
  }
  std::istream& in_;
  const bool swap_;
  long long taken_ = 0;
  unsigned char buffer_[1 << 16];
  unsigned char* at_ = buffer_;
  unsigned char* end_ = buffer_;
};

std::vector<std::string> Tokens(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> tokens;
  for (std::string t; in >> t;) tokens.push_back(t);
  return tokens;
}

// kOk and *value when `token` is entirely a finite decimal number within
// +-terrain::kMaxCoordinate; otherwise kParseError with "WHERE: what was expected".
Status CheckCoordinate(const std::string& where, const std::string& token, double* value_out,
                       std::string* error) {
  double value = 0;
  if (!ParseFiniteDecimal(token, &value))
    return Fail(where,
                "vertex coordinate '" + ShownText(token) + "'" + HiddenBytesNote(token) +
                    " is not a finite number" + NotFiniteNote(token) + CommaNote(token),
                error);
  *value_out = value;
  if (std::fabs(value) > terrain::kMaxCoordinate) {
    TextStream m;
    m << "vertex coordinate " << ShownText(token)
      << " is out of range (expected |coordinate| <= " << terrain::kMaxCoordinate << ")";
    return Fail(where, m.str(), error);
  }
  return Status::kOk;
}

// a + b and a * b for counts >= 0, held at LLONG_MAX where they would overflow (element counts
// near 2^63 added up to a negative total).
long long SaturatingAdd(long long a, long long b) {
  long long sum;
  return __builtin_add_overflow(a, b, &sum) ? LLONG_MAX : sum;
}
long long SaturatingMultiply(long long a, long long b) {
  long long product;
  return __builtin_mul_overflow(a, b, &product) ? LLONG_MAX : product;
}

bool ParseInteger(const std::string& token, long long* value) {
  const char* begin = token.c_str();
  char* end = nullptr;
  *value = std::strtoll(begin, &end, 10);
  return end != begin && *end == '\0';
}

// ParseInteger for a count the file declares: false beyond long long too (strtoll held
// 99999999999999999999 at 2^63 - 1, and "header declares 9223372036854775807 faces" named a
// count the file does not hold).
bool ParseCount(const std::string& token, long long* value) {
  errno = 0;
  return ParseInteger(token, value) && errno != ERANGE;
}

// The line up to its '#' comment (a '#' in Microsoft C's "1.#QNAN" starts none), without a
// final CR.
// Whether an ASCII PLY value is a decimal number (NaN, infinity and numbers beyond a double
// included, as Microsoft C writes them too).
bool IsPlyNumber(const std::string& token) {
  double value = 0;
  return ReadDecimal(token, &value) != DecimalRead::kNotANumber || IsMicrosoftNonFinite(token);
}

std::string StripComment(const std::string& line) {
  std::string s = line.substr(0, CommentStart(line));
  if (!s.empty() && s.back() == '\r') s.pop_back();
  return s;
}

// What text mesh readers misread at the start of a file: lines ended by CR alone (read as one
// line) and UTF-16 text (an OBJ read as empty). A UTF-8 byte order mark is skipped instead
// (SkipByteOrderMark).
Status CheckTextStart(const std::string& path, std::string* error) {
  std::ifstream in(path, std::ios::binary);
  char head[65536];
  in.read(head, sizeof head);
  const std::string_view text(head, static_cast<size_t>(in.gcount()));
  const std::string wide = WideTextProblem(text);
  if (!wide.empty()) return Fail(path, wide, error);
  const size_t cr = text.find('\r');
  if (cr != std::string_view::npos && text.find('\n') == std::string_view::npos &&
      cr + 1 < text.size()) {
    return Fail(path, "lines end in CR alone (classic Mac OS): convert them to LF or CR LF", error);
  }
  return Status::kOk;
}

}  // namespace

// Skips a UTF-8 byte order mark at the start of `in` (a file saved by a Windows editor), as
// point files and height maps do; line numbers are unchanged.
void SkipByteOrderMark(std::istream& in) {
  char head[3] = {};
  in.read(head, sizeof head);
  if (in.gcount() == 3 && std::string_view(head, 3) == "\xEF\xBB\xBF") return;
  in.clear();
  in.seekg(0);
}

namespace {

// Whether `word` starts a statement of the OBJ format (those read and those passed over).
bool IsObjStatement(const std::string& word) {
  static const char* const kWords[] = {
      "v",      "vt",    "vn",       "vp",       "f",          "fo",        "l",      "p",
      "o",      "g",     "s",        "mg",       "usemtl",     "mtllib",    "maplib", "usemap",
      "lod",    "bevel", "c_interp", "d_interp", "shadow_obj", "trace_obj", "ctech",  "stech",
      "cstype", "deg",   "bmat",     "step",     "curv",       "curv2",     "surf",   "parm",
      "trim",   "hole",  "scrv",     "sp",       "end",        "con",       "call",   "csh"};
  return std::find(std::begin(kWords), std::end(kWords), word) != std::end(kWords);
}

}  // namespace

Status ParseObjFile(const std::string& path, ParsedMesh* out, std::string* error) {
  const Status start = CheckTextStart(path, error);
  if (start != Status::kOk) return start;
  std::ifstream in(path);
  SkipByteOrderMark(in);
  LineReader lines(in);
  std::string line, statement;
  long long vertices = 0;
  size_t number = 0, read = 0;  // the statement's first line; the line last read
  size_t unknown = 0;           // the line of the first statement that is not OBJ's
  std::string unknown_word;
  bool continues = false;  // the last line read ends in '\' (a backslash)
  while (lines.Next(&line)) {
    // A line whose statement ends in '\' continues on the next (the OBJ format's line
    // continuation; a '\' in a comment continues nothing): they are read as one statement,
    // named by its first line.
    ++read;
    if (!continues) statement.clear(), number = read;
    const std::string data = StripComment(line);
    const size_t end = data.find_last_not_of(" \t\r\f\v");
    continues = end != std::string::npos && data[end] == '\\';
    statement.append(data, 0, continues ? end : std::string::npos);
    if (statement.size() > kMaxLineBytes) {
      return Fail(At(path, number),
                  "a statement continued ('\\' at line ends) over more than 1 MiB, up to line " +
                      std::to_string(read) + " (expected lines that end)",
                  error);
    }
    if (continues) {
      statement += ' ';
      continue;
    }
    const std::vector<std::string> t = Tokens(statement);
    if (t.empty()) continue;
    if (t[0] == "v") {
      if (t.size() < 4) {
        return Fail(At(path, number),
                    "vertex has " + std::to_string(t.size() - 1) + " coordinates, expected 3",
                    error);
      }
      double c[3];
      for (int i = 1; i <= 3; ++i) {
        const Status s = CheckCoordinate(At(path, number), t[i], &c[i - 1], error);
        if (s != Status::kOk) return s;
      }
      out->vertices.push_back({c[0], c[1], c[2]});
      ++vertices;
    } else if (t[0] == "f" || t[0] == "fo") {  // "fo": the faces of older files
      if (t.size() < 4) {
        return Fail(At(path, number),
                    "face has " + std::to_string(t.size() - 1) + " vertices, expected 3 or more",
                    error);
      }
      for (size_t i = 1; i < t.size(); ++i) {
        long long index = 0;
        const std::string digits = t[i].substr(0, t[i].find('/'));
        // The texture and normal indices after it (not used) are whole numbers or absent.
        size_t slashes = 0;
        bool other_indices = true;
        for (size_t at = t[i].find('/'); at != std::string::npos; at = t[i].find('/', at + 1)) {
          const size_t end = t[i].find('/', at + 1);
          const std::string part =
              t[i].substr(at + 1, end == std::string::npos ? end : end - at - 1);
          long long unused = 0;
          if (++slashes > 2 || !(part.empty() || (ParseInteger(part, &unused) && unused != 0)))
            other_indices = false;
        }
        if (!other_indices) {
          return Fail(At(path, number),
                      "face vertex '" + ShownText(t[i]) +
                          "' is not v, v/vt, v//vn or v/vt/vn (1-based or negative indices)",
                      error);
        }
        if (!ParseInteger(digits, &index) || index == 0) {
          return Fail(
              At(path, number),
              "face vertex '" + ShownText(t[i]) + "' is not a vertex index (1-based or negative)",
              error);
        }
        // (Compared without negating: -LLONG_MIN overflows, and strtoll saturates to it.)
        if (index > vertices || index < -vertices) {
          return Fail(At(path, number),
                      "face uses vertex " + ShownText(digits) + " but only " +
                          std::to_string(vertices) + " vertices are defined before it",
                      error);
        }
        out->corners.push_back(static_cast<uint32_t>(index > 0 ? index - 1 : vertices + index));
      }
      out->EndFace(number);
    } else if (t[0] == "surf") {
      // A free-form surface: the mesh would load without it.
      return Fail(At(path, number),
                  "free-form surfaces ('surf') are not read (expected polygons: export the "
                  "surface as a polygon mesh)",
                  error);
    } else if (unknown == 0 && !IsObjStatement(t[0])) {
      unknown = number, unknown_word = t[0];
    }
  }
  if (lines.too_long()) return TooLongLine(path, lines, error);
  if (continues) {
    return Fail(At(path, read),
                "the line ends in '\\' (continued on the next line), but the file ends there",
                error);
  }
  // A file of statements this reader does not know ("V", "F") was "no vertices: the mesh is
  // empty".
  if (unknown != 0 && (out->vertices.empty() || out->Faces() == 0)) {
    return Fail(At(path, unknown),
                "'" + ShownText(unknown_word) + "' is not an OBJ statement, and the file has no " +
                    (out->vertices.empty() ? "vertices" : "faces") +
                    " (expected 'v x y z' and 'f v1 v2 v3 ...', in lower case)",
                error);
  }
  return Status::kOk;
}

namespace {

// ParseOffFile on the file's lines.
Status ParseOffLines(const std::string& path, LineReader& lines, ParsedMesh* out,
                     std::string* error) {
  std::string line;
  size_t number = 0;
  // The next non-blank line's tokens, or false at the end of the file. OpenMesh's OFF reader
  // skips no comments (it read none of the vertices, or faces of vertices that do not exist).
  size_t comment = 0;  // the first line with a '#'
  auto next = [&](std::vector<std::string>* tokens) {
    while (lines.Next(&line)) {
      ++number;
      if (comment == 0 && line.find('#') != std::string::npos) comment = number;
      *tokens = Tokens(StripComment(line));
      if (!tokens->empty()) return true;
    }
    return false;
  };
  std::vector<std::string> t;
  if (!next(&t)) return Fail(path, "empty OFF file, expected the OFF header", error);
  // OFF and its text variants [ST][C][N]OFF: texture coordinates, colours and normals follow
  // each vertex's three coordinates (checked as far as the coordinates). 4OFF and nOFF (other
  // dimensions) and binary OFF are refused: OpenMesh reads them unchecked, and a wrong count in
  // them can take all memory.
  const std::string header = t[0];  // (a copy: t is erased below)
  const bool off = std::regex_match(header, std::regex("(ST)?C?N?OFF"));
  if (!off) {
    if (header.size() >= 3 && header.compare(header.size() - 3, 3, "OFF") == 0) {
      return Fail(At(path, number),
                  "'" + ShownText(header) +
                      "' files are not read (expected OFF, COFF, NOFF, CNOFF or STOFF "
                      "in text)",
                  error);
    }
    return Fail(At(path, number), "expected the header 'OFF', found '" + ShownText(header) + "'",
                error);
  }
  t.erase(t.begin());
  if (!t.empty() && t[0] == "BINARY") {
    return Fail(At(path, number), "binary OFF is not read (expected a text OFF)", error);
  }
  if (!t.empty()) {
    return Fail(At(path, number),
                "expected the counts on the line after '" + ShownText(header) +
                    "' (OpenMesh reads them there: it read no vertices)",
                error);
  }
  if (t.empty() && !next(&t)) return Fail(path, "truncated: expected the OFF counts", error);
  long long nv = 0, nf = 0;
  if (t.size() < 2 || !ParseCount(t[0], &nv) || !ParseCount(t[1], &nf) || nv < 0 || nf < 0) {
    return Fail(At(path, number), "expected counts 'VERTICES FACES EDGES'", error);
  }
  for (long long v = 0; v < nv; ++v) {
    if (!next(&t)) {
      return Fail(path,
                  "truncated: header declares " + std::to_string(nv) + " vertices, found " +
                      std::to_string(v),
                  error);
    }
    if (t.size() < 3) return Fail(At(path, number), "vertex needs 3 coordinates", error);
    double c[3];
    for (int i = 0; i < 3; ++i) {
      const Status s = CheckCoordinate(At(path, number), t[i], &c[i], error);
      if (s != Status::kOk) return s;
    }
    out->vertices.push_back({c[0], c[1], c[2]});
  }
  for (long long f = 0; f < nf; ++f) {
    if (!next(&t)) {
      return Fail(
          path,
          "truncated: header declares " + std::to_string(nf) + " faces, found " + std::to_string(f),
          error);
    }
    long long n = 0;
    if (!ParseCount(t[0], &n) || n < 3) {
      return Fail(At(path, number), "face must start with its vertex count (3 or more)", error);
    }
    if (static_cast<long long>(t.size()) < n + 1) {
      return Fail(
          At(path, number),
          "face declares " + std::to_string(n) + " vertices, found " + std::to_string(t.size() - 1),
          error);
    }
    for (long long i = 1; i <= n; ++i) {
      long long index = 0;
      if (!ParseInteger(t[i], &index) || index < 0 || index >= nv) {
        return Fail(
            At(path, number),
            "face vertex '" + ShownText(t[i]) + "' is not an index below " + std::to_string(nv),
            error);
      }
      out->corners.push_back(static_cast<uint32_t>(index));
    }
    // After the indices, OFF allows a face colour: none, a colour map index, or R G B [A]
    // (integers 0 to 255 or numbers 0 to 1). It is dropped.
    const size_t extra = t.size() - static_cast<size_t>(n) - 1;
    if (extra == 2 || extra > 4) {
      return Fail(At(path, number),
                  "expected " + std::to_string(n) +
                      " vertex indices and then nothing or a colour (1, 3 or 4 numbers), found " +
                      std::to_string(extra) + " values after the indices",
                  error);
    }
    for (size_t i = static_cast<size_t>(n) + 1; i < t.size(); ++i) {
      double value = 0;
      if (!ParseFiniteDecimal(t[i], &value)) {
        return Fail(At(path, number),
                    "face colour value '" + ShownText(t[i]) + "' is not a number (expected " +
                        std::to_string(n) + " vertex indices, then nothing or R G B [A])",
                    error);
      }
    }
    out->EndFace(number);
  }
  if (next(&t)) {
    return Fail(At(path, number),
                "a line after the " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                    " faces the counts declare (expected the end of the file)",
                error);
  }
  if (comment != 0) {
    return Fail(At(path, comment),
                "a '#' comment, which footfall's OFF reader does not read: remove it", error);
  }
  return Status::kOk;
}

}  // namespace

Status ParseOffFile(const std::string& path, ParsedMesh* out, std::string* error) {
  const Status start = CheckTextStart(path, error);
  if (start != Status::kOk) return start;
  std::ifstream in(path);
  SkipByteOrderMark(in);
  LineReader lines(in);
  const Status status = ParseOffLines(path, lines, out, error);
  return lines.too_long() ? TooLongLine(path, lines, error) : status;
}

Status ParsePlyFile(const std::string& path, ParsedMesh* out, std::string* error) {
  std::ifstream in(path, std::ios::binary);
  LineReader lines(in);
  std::string line;
  size_t number = 0;
  if (!lines.Next(&line) || StripComment(line) != "ply") {
    // A byte order mark before 'ply' (a Windows editor's): the line reads 'ply' on screen.
    if (line.compare(0, 6, "\xEF\xBB\xBFply") == 0)
      return Fail(At(path, 1),
                  "starts with a UTF-8 byte order mark before 'ply', which PLY readers do not "
                  "take: save it without the mark",
                  error);
    // Lines ended by CR alone (classic Mac OS): the first line reads "ply\rformat ...".
    if (line.compare(0, 4, "ply\r") == 0 && line.size() > 4)
      return Fail(path, "lines end in CR alone (classic Mac OS): convert them to LF or CR LF",
                  error);
    return Fail(At(path, 1), "expected the header line 'ply'", error);
  }
  number = 1;
  struct Element {
    std::string name;
    long long count = 0;
    long long fixed_bytes = 0;             // fixed-size properties
    long long list_min_bytes = 0;          // list properties: their counts alone (a face with
                                           // fewer than 3 items is told so as it is read)
    std::vector<std::string> properties;   // names, in order
    std::vector<bool> lists;               // whether each is a list
    std::vector<std::string> types;        // each one's type (lists: their items')
    std::vector<std::string> count_types;  // lists: their counts' type ("" for scalars)
    std::vector<size_t> lines;             // each one's header line
    size_t line = 0;                       // the element's header line
  };
  std::vector<Element> elements;
  std::string format;
  const auto type_size = PlyValues::SizeOf;
  bool ended = false;
  while (lines.Next(&line)) {
    ++number;
    const std::vector<std::string> t = Tokens(StripComment(line));
    if (t.empty() || t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header") {
      ended = true;
      break;
    }
    // Header lines the reader passed over (a keyword misspelt, a property without its name or
    // before any element) left a file read with properties of the wrong element, or none.
    if (t[0] == "format") {
      if (t.size() < 2) {
        return Fail(At(path, number),
                    "expected 'format ascii 1.0' (or binary_little_endian or binary_big_endian)",
                    error);
      }
      format = t[1];
    } else if (t[0] == "element") {
      // A line without its count was passed over: its properties went to the element before.
      if (t.size() < 2)
        return Fail(At(path, number), "expected 'element NAME COUNT', found 'element'", error);
      Element e;
      e.name = t[1];
      if (t.size() < 3) {
        return Fail(
            At(path, number),
            "element '" + ShownText(e.name) + "' has no count (expected 'element NAME COUNT')",
            error);
      }
      if (!ParseCount(t[2], &e.count) || e.count < 0) {
        return Fail(At(path, number),
                    "element '" + ShownText(e.name) + "' count '" + ShownText(t[2]) +
                        "' is not a whole number >= 0 (expected 'element NAME COUNT')",
                    error);
      }
      for (const Element& earlier : elements) {
        if (earlier.name == e.name) {
          return Fail(At(path, number),
                      "element '" + ShownText(e.name) + "' given again (first on line " +
                          std::to_string(earlier.line) + ")",
                      error);
        }
      }
      e.line = number;
      elements.push_back(e);
    } else if (t[0] == "property") {
      if (elements.empty()) {
        return Fail(At(path, number),
                    "a property before any element (expected 'element NAME COUNT' before it)",
                    error);
      }
      Element& e = elements.back();
      const bool list = t.size() >= 2 && t[1] == "list";
      if (t.size() < (list ? 5u : 3u)) {
        return Fail(At(path, number),
                    list ? "expected 'property list COUNT_TYPE ITEM_TYPE NAME'"
                         : "expected 'property TYPE NAME'",
                    error);
      }
      const std::string& name = t[list ? 4 : 2];
      for (size_t p = 0; p < e.properties.size(); ++p) {
        if (e.properties[p] == name) {
          return Fail(At(path, number),
                      ShownText(e.name) + " property '" + ShownText(name) +
                          "' given again (first on line " + std::to_string(e.lines[p]) + ")",
                      error);
        }
      }
      e.lines.push_back(number);
      if (list) {
        const int count_size = type_size(t[2]), item_size = type_size(t[3]);
        if (!count_size || !item_size) {
          return Fail(At(path, number),
                      "unknown PLY type '" + ShownText(count_size ? t[3] : t[2]) + "'", error);
        }
        if (e.name == "vertex") {
          // Kept from when OpenMesh read PLY: it read no vertex with a list (and then no face).
          return Fail(
              At(path, number),
              "vertex property '" + ShownText(t[4]) +
                  "' is a list, which footfall's PLY reader does not read on vertices: remove it",
              error);
        }
        e.list_min_bytes += count_size;
        e.properties.push_back(t[4]), e.lists.push_back(true);
        e.types.push_back(t[3]), e.count_types.push_back(t[2]);
      } else {
        const int size = type_size(t[1]);
        if (!size)
          return Fail(At(path, number), "unknown PLY type '" + ShownText(t[1]) + "'", error);
        e.fixed_bytes += size;
        e.properties.push_back(t[2]), e.lists.push_back(false);
        e.types.push_back(t[1]), e.count_types.push_back("");
      }
    } else {
      return Fail(At(path, number),
                  "'" + ShownText(t[0]) +
                      "' does not start a PLY header line (expected format, element, property, "
                      "comment, obj_info or end_header)",
                  error);
    }
  }
  if (lines.too_long()) return TooLongLine(path, lines, error);
  if (!ended) return Fail(path, "truncated: the PLY header has no 'end_header'", error);
  // The vertices' x, y, z and the faces' index lists, in whatever order the elements come.
  long long vertices = 0;
  for (const Element& e : elements) {
    if (e.name != "vertex") continue;
    vertices = e.count;
    for (const char* axis : {"x", "y", "z"}) {
      if (std::find(e.properties.begin(), e.properties.end(), axis) == e.properties.end() &&
          e.count > 0) {
        return Fail(path, std::string("the vertex element has no property '") + axis + "'", error);
      }
    }
  }
  auto axis_of = [](const Element& e, size_t p) {
    const std::string& name = e.properties[p];
    if (e.name != "vertex" || e.lists[p] || name.size() != 1) return -1;
    return name[0] == 'x' ? 0 : name[0] == 'y' ? 1 : name[0] == 'z' ? 2 : -1;
  };
  auto is_indices = [](const Element& e, size_t p) {
    return (e.name == "face" || e.name == "tristrips") && e.lists[p] &&
           (e.properties[p] == "vertex_indices" || e.properties[p] == "vertex_index");
  };
  for (const Element& e : elements) {
    if ((e.name != "face" && e.name != "tristrips") || e.count == 0) continue;
    bool has_indices = false;
    for (size_t p = 0; p < e.properties.size(); ++p) has_indices |= is_indices(e, p);
    if (!has_indices) {
      return Fail(At(path, e.line),
                  "element '" + ShownText(e.name) +
                      "' has no list property 'vertex_indices' (or 'vertex_index'): its " +
                      std::to_string(e.count) + " records cannot be read",
                  error);
    }
  }
  // A tristrips element's index list: strips of vertices, each ended by -1 or the list's end.
  // Triangle k of a strip takes its vertices k, k + 1, k + 2, every other one wound the other
  // way, so that the strip is wound one way; triangles repeating a vertex (which join strips
  // written as one) are left out.
  std::vector<long long> strip;
  auto add_strip = [&](size_t line) {
    strip.push_back(-1);
    size_t begin = 0;
    for (size_t i = 0; i < strip.size(); ++i) {
      if (strip[i] != -1) continue;
      for (size_t k = begin; k + 2 < i; ++k) {
        const bool odd = (k - begin) % 2 != 0;
        const long long a = strip[odd ? k + 1 : k], b = strip[odd ? k : k + 1], c = strip[k + 2];
        if (a == b || b == c || a == c) continue;
        for (long long v : {a, b, c}) out->corners.push_back(static_cast<uint32_t>(v));
        out->EndFace(line);
      }
      begin = i + 1;
    }
    strip.clear();
  };
  if (format == "ascii") {
    long long records = 0;
    for (const Element& e : elements) records = SaturatingAdd(records, e.count);
    // One record per line, checked against its element: vertices' x, y, z finite; faces'
    // index lists of 3 or more indices of declared vertices.
    // A value of a property that is not read is still a number (NaN and infinity too).
    auto not_a_number = [&](const Element& e, size_t p, const std::string& token) {
      return Fail(At(path, number),
                  ShownText(e.name) + " property '" + ShownText(e.properties[p]) + "': '" +
                      ShownText(token) + "'" + HiddenBytesNote(token) + " is not a number" +
                      CommaNote(token),
                  error);
    };
    long long found = 0;
    size_t element = 0;
    long long in_element = 0;
    while (lines.Next(&line)) {
      ++number;
      const std::vector<std::string> t = Tokens(line);
      if (t.empty()) continue;
      ++found;
      while (element < elements.size() && in_element >= elements[element].count)
        ++element, in_element = 0;
      if (element >= elements.size()) {
        return Fail(At(path, number),
                    "a record after the " + std::to_string(records) +
                        " the header declares (expected the end of the file)",
                    error);
      }
      ++in_element;
      const Element& e = elements[element];
      size_t at = 0;
      Vec3 point;
      bool face = false;
      std::string expected;  // the properties, as read: "x y z" or "vertex_indices (4 + 4)"
      for (size_t p = 0; p < e.properties.size(); ++p) {
        if (at >= t.size()) {
          return Fail(At(path, number),
                      "expected a value for " + ShownText(e.name) + " property '" +
                          ShownText(e.properties[p]) + "'",
                      error);
        }
        if (!e.lists[p]) {
          const int axis = axis_of(e, p);
          if (axis >= 0) {
            double value = 0;
            const Status s = CheckCoordinate(At(path, number), t[at], &value, error);
            if (s != Status::kOk) return s;
            (axis == 0 ? point.x : axis == 1 ? point.y : point.z) = value;
          } else if (!IsPlyNumber(t[at])) {
            return not_a_number(e, p, t[at]);
          }
          ++at;
          expected += (expected.empty() ? "" : " ") + ShownText(e.properties[p]);
          continue;
        }
        long long n = 0;
        if (!ParseInteger(t[at], &n) || n < 0 || at + 1 + static_cast<size_t>(n) > t.size()) {
          return Fail(
              At(path, number),
              "list '" + ShownText(e.properties[p]) + "' needs its count and that many items",
              error);
        }
        const bool indices = is_indices(e, p) && !face;
        const bool strips = indices && e.name == "tristrips";
        if (indices && !strips && n < 3) {
          return Fail(At(path, number),
                      "face has " + std::to_string(n) + " vertices, expected 3 or more", error);
        }
        for (long long i = 1; indices && i <= n; ++i) {
          long long index = 0;
          if (!ParseInteger(t[at + i], &index) || index < (strips ? -1 : 0) || index >= vertices) {
            return Fail(At(path, number),
                        ShownText(e.name) + " vertex '" + ShownText(t[at + i]) + "' is not " +
                            (strips ? "-1 or " : "") + "an index below " + std::to_string(vertices),
                        error);
          }
          if (strips)
            strip.push_back(index);
          else
            out->corners.push_back(static_cast<uint32_t>(index));
        }
        for (long long i = 1; !indices && i <= n; ++i) {
          if (!IsPlyNumber(t[at + i])) return not_a_number(e, p, t[at + i]);
        }
        if (strips) add_strip(number);
        if (indices) face = true;
        at += 1 + static_cast<size_t>(n);
        expected += (expected.empty() ? "" : " ") + ShownText(e.properties[p]) + " (its count, " +
                    std::to_string(n) + ", and " + std::to_string(n) + " items)";
      }
      if (at < t.size()) {
        return Fail(At(path, number),
                    "expected " + std::to_string(at) + " values for " + ShownText(e.name) + " " +
                        std::to_string(in_element) + ": " + expected + "; found " +
                        std::to_string(t.size()),
                    error);
      }
      if (e.name == "vertex") out->vertices.push_back(point);
      if (face && e.name == "face") out->EndFace(number);
    }
    if (lines.too_long()) return TooLongLine(path, lines, error);
    if (found < records) {
      return Fail(path,
                  "truncated: the header declares " + std::to_string(records) +
                      " data lines, found " + std::to_string(found),
                  error);
    }
    return Status::kOk;
  }
  if (format != "binary_little_endian" && format != "binary_big_endian") {
    return Fail(path,
                "format '" + ShownText(format) +
                    "' is not a PLY format (expected ascii, binary_little_endian or "
                    "binary_big_endian)",
                error);
  }
  const std::streamoff data_start = in.tellg();
  in.seekg(0, std::ios::end);
  const long long data_bytes = static_cast<long long>(in.tellg() - data_start);
  long long need = 0;
  for (const Element& e : elements)
    need = SaturatingAdd(need, SaturatingMultiply(e.count, e.fixed_bytes + e.list_min_bytes));
  if (data_bytes < need) {
    return Fail(path,
                "truncated: the header's elements need at least " + std::to_string(need) +
                    " bytes of " + ShownText(format) + " data, the file has " +
                    std::to_string(data_bytes),
                error);
  }
  // Binary data, as the ASCII lines are checked: vertices' x, y, z finite, faces' index lists
  // of 3 or more indices of declared vertices.
  in.clear();
  in.seekg(data_start);
  PlyValues values(in, format == "binary_big_endian");
  auto truncated = [&](const Element& e, long long r) {
    return Fail(path,
                "truncated: the binary data ends in " + ShownText(e.name) + " " +
                    std::to_string(r + 1) + " of " + std::to_string(e.count),
                error);
  };
  for (const Element& e : elements) {
    // An element without properties has no bytes to read: its records, up to 2^63 of them in
    // the header, were counted through one by one (the load hung).
    if (e.properties.empty()) continue;
    for (long long r = 0; r < e.count; ++r) {
      Vec3 point;
      bool face = false;
      for (size_t p = 0; p < e.properties.size(); ++p) {
        double v = 0;
        const std::string& name = e.properties[p];
        if (!e.lists[p]) {
          if (!values.Next(e.types[p], &v)) return truncated(e, r);
          const int axis = axis_of(e, p);
          if (axis >= 0 && !(std::fabs(v) <= terrain::kMaxCoordinate)) {
            return Fail(path,
                        "vertex " + std::to_string(r + 1) + ": coordinate " + ShownText(name) +
                            " is NaN, infinite or beyond +-5e14",
                        error);
          }
          if (axis >= 0) (axis == 0 ? point.x : axis == 1 ? point.y : point.z) = v;
          continue;
        }
        double n = 0;
        if (!values.Next(e.count_types[p], &n)) return truncated(e, r);
        if (!(n >= 0 && n == std::floor(n))) {  // a float count: the rest of the data misread
          TextStream m;
          m << ShownText(e.name) << " " << r + 1 << ": list '" << ShownText(name) << "' count " << n
            << " is not a whole number >= 0";
          return Fail(path, m.str(), error);
        }
        const bool indices = is_indices(e, p) && !face;
        const bool strips = indices && e.name == "tristrips";
        if (indices && !strips && n < 3) {
          return Fail(path,
                      "face " + std::to_string(r + 1) + " has " +
                          std::to_string(static_cast<long long>(n)) +
                          " vertices, expected 3 or more",
                      error);
        }
        for (double i = 0; i < n; ++i) {
          if (!values.Next(e.types[p], &v)) return truncated(e, r);
          if (indices && !(v >= (strips ? -1 : 0) && v < static_cast<double>(vertices) &&
                           v == std::floor(v))) {
            TextStream m;
            m << ShownText(e.name) << " " << r + 1 << ": vertex index ";
            if (std::fabs(v) < 1e18 && v == std::floor(v))
              m << static_cast<long long>(v);
            else
              m << v;
            m << " is not " << (strips ? "-1 or " : "") << "an index below " << vertices;
            return Fail(path, m.str(), error);
          }
          if (strips)
            strip.push_back(static_cast<long long>(v));
          else if (indices)
            out->corners.push_back(static_cast<uint32_t>(v));
        }
        if (strips) add_strip(0);
        if (indices) face = true;
      }
      if (e.name == "vertex") out->vertices.push_back(point);
      if (face && e.name == "face") out->EndFace(0);
    }
  }
  // Data left over: the header declares fewer records than the file holds (the rest was
  // dropped, silently), or the elements' properties are not those written.
  const long long left = data_bytes - values.taken();
  if (left > 0 && !values.RestIsLineEnd(left)) {
    return Fail(path,
                std::to_string(left) + " bytes after the data the header declares (expected " +
                    "the end of the file: check the header's element counts and properties)",
                error);
  }
  return Status::kOk;
}

// Merges STL corners at the same point into one vertex.
class StlVertices {
 public:
  explicit StlVertices(std::vector<Vec3>* vertices) : vertices_(vertices) {}
  uint32_t Add(const Vec3& p) {
    const Key key{p.x + 0.0, p.y + 0.0, p.z + 0.0};  // -0 and 0 alike
    const auto [it, added] = index_.emplace(key, static_cast<uint32_t>(vertices_->size()));
    if (added) vertices_->push_back(p);
    return it->second;
  }

 private:
  using Key = std::array<double, 3>;
  struct Hash {
    size_t operator()(const Key& k) const {
      size_t h = 0;
      for (double c : k) h = h * 1000003u ^ std::hash<double>()(c);
      return h;
    }
  };
  std::vector<Vec3>* vertices_;
  std::unordered_map<Key, uint32_t, Hash> index_;
};

Status ParseStlFile(const std::string& path, ParsedMesh* out, std::string* error) {
  StlVertices merged(&out->vertices);
  std::ifstream in(path, std::ios::binary);
  in.seekg(0, std::ios::end);
  const long long size = static_cast<long long>(in.tellg());
  in.seekg(0);
  std::string head(std::min<long long>(size, 84), '\0');
  in.read(&head[0], static_cast<std::streamsize>(head.size()));
  if (size >= 84) {
    uint32_t count = 0;
    std::memcpy(&count, head.data() + 80, 4);  // little-endian on every platform we build for
    if (84 + 50ll * count == size) {  // a complete binary STL: its vertices finite (OpenMesh
      in.clear();                     // dropped a facet with a NaN vertex, silently)
      in.seekg(84);
      std::vector<char> facets(50 * 4096);
      for (uint32_t done = 0; done < count;) {
        const uint32_t n = std::min<uint32_t>(count - done, 4096);
        if (!in.read(facets.data(), 50 * static_cast<std::streamsize>(n)))
          return Fail(path, "truncated: cannot read facet " + std::to_string(done + 1), error);
        for (uint32_t f = 0; f < n; ++f) {
          float v[9];
          std::memcpy(v, facets.data() + 50 * f + 12, sizeof v);
          for (float c : v) {
            if (!(std::fabs(c) <= terrain::kMaxCoordinate)) {
              return Fail(path,
                          "facet " + std::to_string(done + f + 1) +
                              ": a vertex coordinate is NaN, infinite or beyond +-5e14",
                          error);
            }
          }
          for (int k = 0; k < 3; ++k)
            out->corners.push_back(merged.Add({v[3 * k], v[3 * k + 1], v[3 * k + 2]}));
          out->EndFace(0);
        }
        done += n;
      }
      return Status::kOk;
    }
  }
  // A byte order mark before 'solid' (a Windows editor's): read as a binary STL's header, it
  // declared some billions of triangles.
  if (head.size() >= 8 && head.compare(0, 3, "\xEF\xBB\xBF") == 0 &&
      std::equal(head.begin() + 3, head.begin() + 8, "solid",
                 [](char a, char b) { return AsciiLower(a) == b; })) {
    return Fail(path,
                "starts with a UTF-8 byte order mark before 'solid', which makes OpenMesh read "
                "it as a binary STL: save it without the mark",
                error);
  }
  if (head.size() >= 5 && head.compare(0, 5, "solid") != 0 &&
      std::equal(head.begin(), head.begin() + 5, "solid",
                 [](char a, char b) { return AsciiLower(a) == b; })) {
    return Fail(path,
                "an ASCII STL must begin with 'solid' in lower case (OpenMesh reads it as "
                "binary otherwise)",
                error);
  }
  // Binary bytes (NUL or other control bytes) in the first facet: a binary STL, even when its
  // header begins with 'solid', as some exporters write it.
  std::string first(static_cast<size_t>(std::min<long long>(size, 84 + 50)), '\0');
  in.clear();
  in.seekg(0);
  in.read(&first[0], static_cast<std::streamsize>(first.size()));
  const bool binary_bytes = std::any_of(first.begin(), first.end(), [](char c) {
    const unsigned char u = static_cast<unsigned char>(c);
    return u < 0x20 && u != '\t' && u != '\n' && u != '\r' && u != '\f' && u != '\v';
  });
  if (head.compare(0, 5, "solid") != 0 || (binary_bytes && size >= 84)) {
    if (size < 84) return Fail(path, "truncated: a binary STL needs an 84-byte header", error);
    uint32_t count = 0;
    std::memcpy(&count, head.data() + 80, 4);
    const long long want = 84 + 50ll * count;
    return Fail(path,
                std::string(size < want ? "truncated: " : "extra bytes: ") +
                    "binary STL declares " + std::to_string(count) + " triangles (" +
                    std::to_string(want) + " bytes), the file has " + std::to_string(size) +
                    " bytes",
                error);
  }
  // ASCII STL: finite vertices, three to a facet's loop, and a closing 'endsolid'. Lines ended
  // by CR alone are said as such (read as one line, they ended in "no closing 'endsolid'").
  const Status start = CheckTextStart(path, error);
  if (start != Status::kOk) return start;
  in.clear();
  in.seekg(0);
  std::string line;
  bool closed = false;
  int in_loop = -1;      // vertices of the open loop; -1 outside one
  size_t loop_line = 0;  // the line of the open loop's 'outer loop'
  LineReader lines(in);
  for (size_t number = 1; lines.Next(&line); ++number) {
    const std::vector<std::string> t = Tokens(line);
    if (t.empty()) continue;
    // A loop left open (its facet was dropped, silently) before the next one or the end.
    if (in_loop >= 0 && (t[0] == "outer" || t[0] == "endfacet" || t[0] == "endsolid")) {
      return Fail(At(path, number),
                  "'" + ShownText(t[0]) + "' inside the facet loop opened on line " +
                      std::to_string(loop_line) + " (expected 'endloop' after its 3 vertices)",
                  error);
    }
    // A line of another kind (a damaged file) was passed over.
    if (t[0] != "solid" && t[0] != "facet" && t[0] != "outer" && t[0] != "vertex" &&
        t[0] != "endloop" && t[0] != "endfacet" && t[0] != "endsolid") {
      return Fail(At(path, number),
                  "'" + ShownText(t[0]) +
                      "' does not start an ASCII STL line (expected solid, facet normal, outer "
                      "loop, vertex, endloop, endfacet or endsolid)",
                  error);
    }
    if (t[0] == "endsolid") closed = true;
    if (t[0] == "outer") in_loop = 0, loop_line = number;
    if (t[0] == "endloop") {
      if (in_loop >= 0 && in_loop != 3) {
        return Fail(At(path, number),
                    "facet loop has " + std::to_string(in_loop) +
                        " vertices, expected 3 (STL "
                        "facets are triangles)",
                    error);
      }
      if (in_loop == 3) out->EndFace(number);
      in_loop = -1;
    }
    if (t[0] == "vertex") {
      if (in_loop < 0) {
        return Fail(At(path, number),
                    "vertex outside a facet loop (expected 'outer loop' before it)", error);
      }
      ++in_loop;
      if (t.size() != 4) {
        return Fail(At(path, number),
                    "vertex has " + std::to_string(t.size() - 1) + " coordinates, expected 3",
                    error);
      }
      double c[3];
      for (int i = 1; i <= 3; ++i) {
        const Status s = CheckCoordinate(At(path, number), t[i], &c[i - 1], error);
        if (s != Status::kOk) return s;
      }
      if (in_loop <= 3) out->corners.push_back(merged.Add({c[0], c[1], c[2]}));
    }
  }
  if (lines.too_long()) return TooLongLine(path, lines, error);
  if (!closed) return Fail(path, "truncated: ASCII STL has no closing 'endsolid'", error);
  return Status::kOk;
}

}  // namespace footfall::detail
