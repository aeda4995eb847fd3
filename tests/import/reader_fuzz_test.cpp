// Deterministic mutation fuzzing of every input reader: point files, meshes (OBJ, OFF, PLY text and
// binary, STL text and binary), height maps (ASC, PGM P2 and P5), the terrain loader that picks
// among them by extension, character files and walk JSON. Small valid seeds are damaged by a
// fixed-seed generator (truncation, flipped bytes, inserted bytes, NUL, huge numbers, nan, inf,
// -0, long lines, deep nesting, lines deleted, repeated or swapped, tokens swapped, header counts
// changed) and read back through the public API. Every case must return without an exception,
// and either succeed with finite, valid output or fail with a message naming the file (and, where
// the message names a line, a line the file has).
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "footfall/import/height_map.h"
#include "footfall/import/mesh_reader.h"
#include "footfall/import/terrain_loader.h"
#include "footfall/steps/character.h"
#include "footfall/steps/scene.h"
#include "footfall/steps/walk_json.h"
#include "footfall/terrain/point_file.h"
#include "footfall/terrain/samples.h"
#include "test_support.h"

namespace footfall {
namespace {

// Cases per format in the random sweep: 400, or FOOTFALL_FUZZ_CASES for a longer search.
int CasesPerFormat() {
  const char* cases = std::getenv("FOOTFALL_FUZZ_CASES");
  return cases && std::atoi(cases) > 0 ? std::atoi(cases) : 400;
}

// ---------------------------------------------------------------------------------------------
// Seeds: small valid files of every format.

const char* const kPoints =
    "# x y z nx ny nz\n0 0 0 0 1 0\n1 0 0 0 1 0\n0 0 1 0 2 0\n1\t0.5\t1 0.1 1 0\n"
    "\n-1e3 2 3.5e-2 0 0 -1\n";
const char* const kPointsCrlf =
    "\xEF\xBB\xBF"
    "0 0 0 0 1 0\r\n1 1 1 1 1 1\r\n# end\r\n";

const char* const kCubeObj =
    "# cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "vn 0 0 1\nvt 0 0\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
const char* const kTetraObj =
    "o tetra\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\n"
    "f 1/1/1 3/1/1 2/1/1\nf 1//1 2//1 4//1\nf 1 4 3\nf -3 -2 -1\n";

// A wavy 5 x 5 grid of quads, with a concave hexagon beside it and coordinates far from the
// origin: enough faces for the winding, manifold and triangulation steps to meet damage.
std::string GridObj() {
  std::string text = "# grid\n";
  char line[128];
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) {
      std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", 1e5 + 0.5 * c, 0.1 * ((r * c) % 3),
                    -2e5 + 0.5 * r);
      text += line;
    }
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 5; ++c) {
      const int a = 1 + r * 6 + c;
      std::snprintf(line, sizeof line, "f %d %d %d %d\n", a, a + 6, a + 7, a + 1);
      text += line;
    }
  text += "v 0 0 0\nv 2 0 0\nv 2 0 2\nv 1 0 1\nv 0 0 2\nv -1 0 1\nf -6 -1 -2 -3 -4 -5\n";
  return text;
}

const char* const kCubeOff =
    "OFF\n8 6 12\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
    "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7 255 0 0\n";

const char* const kTetraPly =
    "ply\nformat ascii 1.0\ncomment tetra\nelement vertex 4\nproperty float x\n"
    "property float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\n"
    "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

std::string BinaryPly(bool big_endian) {
  std::string text = std::string("ply\nformat ") +
                     (big_endian ? "binary_big_endian" : "binary_little_endian") +
                     " 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty "
                     "float z\nproperty uchar red\nelement face 4\nproperty list uchar int "
                     "vertex_indices\nend_header\n";
  auto put = [&](const void* p, size_t n) {
    const char* c = static_cast<const char*>(p);
    std::string bytes(c, n);
    if (big_endian) std::reverse(bytes.begin(), bytes.end());
    text += bytes;
  };
  const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& p : v) {
    for (float c : p) put(&c, 4);
    text += '\x7f';
  }
  const int32_t f[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& face : f) {
    text += '\x03';
    for (int32_t i : face) put(&i, 4);
  }
  return text;
}

const char* const kTetraStl =
    "solid tetra\n"
    "facet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\n"
    "endfacet\n"
    "facet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\n"
    "endfacet\n"
    "facet normal -1 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 0 1 0\nendloop\n"
    "endfacet\n"
    "facet normal 1 1 1\nouter loop\nvertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\n"
    "endfacet\nendsolid tetra\n";

std::string BinaryStl() {
  std::string text(80, ' ');
  text.replace(0, 6, "binary");
  const uint32_t count = 4;
  text.append(reinterpret_cast<const char*>(&count), 4);
  const float facets[4][12] = {{0, 0, -1, 0, 0, 0, 0, 1, 0, 1, 0, 0},
                               {0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1},
                               {-1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 1, 0},
                               {1, 1, 1, 1, 0, 0, 0, 1, 0, 0, 0, 1}};
  for (const auto& facet : facets) {
    text.append(reinterpret_cast<const char*>(facet), sizeof facet);
    text.append(2, '\0');
  }
  return text;
}

const char* const kAsc =
    "ncols 4\nnrows 3\nxllcorner 100\nyllcorner 200\ncellsize 2\nNODATA_value -9999\n"
    "1 2 3 4\n4 -9999 6 7\n1.5 2.5 -3 0\n";
const char* const kAscCenter =
    "NCOLS 2\r\nNROWS 2\r\nXLLCENTER 0\r\nYLLCENTER 0\r\nCELLSIZE 0.5\r\n10 11\r\n12 13\r\n";

const char* const kPgmAscii = "P2\n# grey\n4 3\n255\n0 10 20 30\n40 50 60 70\n80 90 255 0\n";

std::string BinaryPgm(bool sixteen_bit) {
  std::string text = std::string("P5\n4 3\n") + (sixteen_bit ? "1000\n" : "255\n");
  for (int i = 0; i < 12; ++i) {
    const int level = i * 37 % (sixteen_bit ? 1000 : 255);
    if (sixteen_bit) text += static_cast<char>(level >> 8);
    text += static_cast<char>(level & 0xff);
  }
  return text;
}

const char* const kBiped = R"({"format": "footfall-character", "version": 1, "name": "b",
  "comment": "seed",
  "feet": [{"name": "L", "rest": [0.1, 0, 0]}, {"name": "R", "rest": [-0.1, 0, 0]}],
  "gait": [["L"], ["R"]], "pairs": [["L", "R"]], "step_length": 0.6, "step_height": 0.1,
  "body_height": 0.9, "frames_per_step": 10, "align_to_normal": false, "reach": 1.1,
  "slope_threshold_deg": 15, "slope_step_scale": 0.6, "max_slope_deg": 45, "max_rise": 0.4,
  "max_turn_deg": 30}
)";
const char* const kQuadruped = R"({
  "format": "footfall-character",
  "version": 1,
  "name": "quad",
  "feet": [
    {"name": "FL", "rest": [0.2, 0, 0.4]},
    {"name": "FR", "rest": [-0.2, 0, 0.4]},
    {"name": "HL", "rest": [0.2, 0, -0.4]},
    {"name": "HR", "rest": [-0.2, 0, -0.4]}
  ],
  "gait": [["FL", "HR"], ["FR", "HL"]],
  "pairs": [["FL", "FR"], ["HL", "HR"]],
  "step_length": 0.5,
  "step_height": 0.12,
  "body_height": 0.5,
  "frames_per_step": 8,
  "align_to_normal": true,
  "reach": 1.0
}
)";

// A scene of two characters, one given inline (a file beside it would not be damaged).
std::string SeedScene() {
  return std::string(R"({"format": "footfall-scene", "version": 1, "comment": "seed",
  "characters": [
    {"name": "walker", "character": )") +
         kBiped + R"(, "start": [1, 0, 2], "heading": [0, 0, 1],
     "path": [[1, 0, 4], [3, 0.5, 4]], "steps": 12, "start_frame": 5, "up": [0, 1, 0]},
    {"character": )" +
         kQuadruped + R"(, "crowd": 3, "crowd_spacing": 0.5}]}
)";
}

std::string SeedWalk() {
  Walk walk;
  walk.fps = 24;
  walk.stopped = "stopped at step 3";
  for (int t = 0; t < 2; ++t) {
    WalkTrack track;
    track.name = t == 0 ? "L" : "body";
    track.kind = t == 0 ? TrackKind::kFoot : TrackKind::kBody;
    if (t == 1) track.character = "c1";
    for (int k = 0; k < 4; ++k) {
      WalkKey key;
      key.frame = 1 + 6 * k;
      key.position = {0.1 * k, 0.02 * k, -0.5 * k};
      key.normal = {0, 1, 0};
      key.phase = t == 0 ? (k % 3 == 0   ? KeyPhase::kStart
                            : k % 3 == 1 ? KeyPhase::kMid
                                         : KeyPhase::kEnd)
                         : KeyPhase::kNone;
      track.keys.push_back(key);
      if (t == 1) track.rotations.push_back({0, 0.1 * k, 0, 1});
    }
    walk.tracks.push_back(std::move(track));
  }
  return WalkToJson(walk);
}

// ---------------------------------------------------------------------------------------------
// Mutations.

enum class Kind { kText, kBinary, kJson };

const char* const kSpecialTokens[] = {"nan",
                                      "NaN",
                                      "-nan",
                                      "inf",
                                      "-inf",
                                      "Infinity",
                                      "-0",
                                      "0",
                                      "-1",
                                      "1",
                                      "2",
                                      "3",
                                      "1e308",
                                      "-1e308",
                                      "1e400",
                                      "1e-400",
                                      "6e14",
                                      "1e15",
                                      "4e14",
                                      "-4.9e14",
                                      "1e-300",
                                      "4.9e-324",
                                      "123456789.123456789",
                                      "4294967295",
                                      "4294967296",
                                      "2147483647",
                                      "2147483648",
                                      "-2147483649",
                                      "18446744073709551616",
                                      "99999999999999999999999999",
                                      "100000001",
                                      "0x10",
                                      "1.5",
                                      "255",
                                      "256",
                                      "65535",
                                      "65536",
                                      "1e",
                                      "+",
                                      "-",
                                      ".",
                                      "#",
                                      "\"",
                                      "{}",
                                      "[]",
                                      "null",
                                      "true",
                                      "\xC2\x9B",
                                      "\xFF\xFE",
                                      "\xEF\xBB\xBF"};

const char* const kCounts[] = {"0",         "1",          "2",          "3",
                               "5",         "-1",         "100",        "1000000",
                               "100000001", "2000000000", "4294967295", "4294967296",
                               "1e9",       "2.5",        "nan",        "99999999999999999999"};

struct Token {
  size_t at, size;
};

std::vector<Token> Tokens(const std::string& s) {
  std::vector<Token> tokens;
  for (size_t i = 0; i < s.size();) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    const size_t start = i;
    while (i < s.size() && !std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    if (i > start) tokens.push_back({start, i - start});
  }
  return tokens;
}

// Offsets where lines start.
std::vector<size_t> LineStarts(const std::string& s) {
  std::vector<size_t> starts{0};
  for (size_t i = 0; i < s.size(); ++i)
    if (s[i] == '\n' && i + 1 < s.size()) starts.push_back(i + 1);
  return starts;
}

class Mutator {
 public:
  explicit Mutator(uint32_t seed) : rng_(seed) {}
  size_t Below(size_t n) {
    return n == 0 ? 0 : std::uniform_int_distribution<size_t>(0, n - 1)(rng_);
  }
  template <size_t N>
  const char* Pick(const char* const (&list)[N]) {
    return list[Below(N)];
  }

  // Applies one mutation to *s and says which.
  std::string Mutate(std::string* s, Kind kind,
                     const std::function<std::string(std::string*, Mutator*)>& special) {
    const size_t kinds = special ? 16 : 15;
    const size_t choice = Below(kinds);
    switch (choice) {
      case 0: {
        const size_t at = Below(s->size() + 1);
        s->resize(at);
        return "truncate at " + std::to_string(at);
      }
      case 1: {
        const size_t n = 1 + Below(4);
        for (size_t i = 0; i < n && !s->empty(); ++i)
          (*s)[Below(s->size())] ^= static_cast<char>(1u << Below(8));
        return "flip bits";
      }
      case 2: {
        std::string bytes;
        for (size_t i = 0, n = 1 + Below(16); i < n; ++i) bytes += static_cast<char>(Below(256));
        s->insert(Below(s->size() + 1), bytes);
        return "insert random bytes";
      }
      case 3:
        s->insert(Below(s->size() + 1), 1 + Below(3), '\0');
        return "insert NUL";
      case 4: {
        const std::string token = Pick(kSpecialTokens);
        s->insert(Below(s->size() + 1), Below(2) ? " " + token + " " : token);
        return "insert '" + token + "'";
      }
      case 5:
      case 6: {
        const auto tokens = Tokens(*s);
        if (tokens.empty()) return "no token";
        const Token t = tokens[Below(tokens.size())];
        const std::string token = choice == 5 ? Pick(kSpecialTokens) : Pick(kCounts);
        s->replace(t.at, t.size, token);
        return "token at " + std::to_string(t.at) + " -> '" + token + "'";
      }
      case 7: {
        const auto starts = LineStarts(*s);
        const size_t l = Below(starts.size());
        const size_t end = s->find('\n', starts[l]);
        s->erase(starts[l], end == std::string::npos ? std::string::npos : end + 1 - starts[l]);
        return "delete line " + std::to_string(l + 1);
      }
      case 8: {
        const auto starts = LineStarts(*s);
        const size_t l = Below(starts.size());
        const size_t end = s->find('\n', starts[l]);
        std::string line = s->substr(
            starts[l], end == std::string::npos ? std::string::npos : end + 1 - starts[l]);
        if (line.empty() || line.back() != '\n') line += '\n';
        s->insert(starts[l], line);
        return "repeat line " + std::to_string(l + 1);
      }
      case 9: {
        std::vector<std::string> lines;
        for (size_t at = 0; at <= s->size();) {
          const size_t end = s->find('\n', at);
          lines.push_back(s->substr(at, end == std::string::npos ? std::string::npos : end - at));
          if (end == std::string::npos) break;
          at = end + 1;
        }
        const size_t a = Below(lines.size()), b = Below(lines.size());
        std::swap(lines[a], lines[b]);
        std::string joined;
        for (size_t i = 0; i < lines.size(); ++i) joined += (i ? "\n" : "") + lines[i];
        *s = joined;
        return "swap lines " + std::to_string(a + 1) + " and " + std::to_string(b + 1);
      }
      case 10: {
        const auto tokens = Tokens(*s);
        if (tokens.size() < 2) return "no tokens";
        Token a = tokens[Below(tokens.size())], b = tokens[Below(tokens.size())];
        if (a.at > b.at) std::swap(a, b);
        if (a.at == b.at) return "same token";
        const std::string ta = s->substr(a.at, a.size), tb = s->substr(b.at, b.size);
        s->replace(b.at, b.size, ta);
        s->replace(a.at, a.size, tb);
        return "swap tokens at " + std::to_string(a.at) + " and " + std::to_string(b.at);
      }
      case 11: {
        // A long line: mostly long, now and then over the readers' 1 MiB line limit.
        const size_t n = Below(8) == 0 ? (1u << 20) + Below(1000) : 100 + Below(20000);
        const char fill = Pick(kSpecialTokens)[0];
        const auto starts = LineStarts(*s);
        const size_t at = starts[Below(starts.size())];
        s->insert(at, std::string(n, fill ? fill : '9') + (Below(2) ? "\n" : ""));
        return "long line of " + std::to_string(n) + " bytes";
      }
      case 12: {
        // A huge number where a number was.
        const auto tokens = Tokens(*s);
        if (tokens.empty()) return "no token";
        const Token t = tokens[Below(tokens.size())];
        const std::string digits(1 + Below(400), '9');
        s->replace(t.at, t.size,
                   Below(2) ? digits : "-" + digits + ".5e" + std::to_string(Below(5)));
        return "huge number at " + std::to_string(t.at);
      }
      case 13: {
        // Line ends changed: CR LF, CR alone, or none.
        const int how = static_cast<int>(Below(3));
        std::string out;
        for (char c : *s) {
          if (c != '\n')
            out += c;
          else
            out += how == 0 ? "\r\n" : how == 1 ? "\r" : " ";
        }
        *s = out;
        return how == 0 ? "CR LF" : how == 1 ? "CR" : "no line ends";
      }
      case 14: {
        if (kind != Kind::kJson) {
          // Whitespace where a token was split, or a token glued to its neighbour.
          const auto tokens = Tokens(*s);
          if (tokens.empty()) return "no token";
          const Token t = tokens[Below(tokens.size())];
          if (t.at + t.size < s->size()) s->erase(t.at + t.size, 1);
          return "glue token at " + std::to_string(t.at);
        }
        // Deep nesting in place of a value.
        const size_t depth = Below(4) == 0 ? 100000 + Below(100000) : 1 + Below(2000);
        std::string nest;
        const size_t how = Below(3);
        if (how == 0) {
          nest = std::string(depth, '[') + "1" + std::string(depth, ']') + ", \"x\": ";
        } else if (how == 1) {
          for (size_t d = 0; d < depth; ++d) nest += "{\"a\": ";
          nest += "1" + std::string(depth, '}') + ", \"x\": ";
        } else {
          nest = std::string(depth, '[');  // never closed
        }
        const size_t colon = s->find(':', Below(s->size() + 1));
        if (colon == std::string::npos) return "no value";
        s->insert(colon + 1, nest);
        return "nesting of " + std::to_string(depth);
      }
      default:
        return special(s, this);
    }
  }

 private:
  std::mt19937 rng_;
};

// Replaces the value after the first `key` (a token) with `value`; false when there is none.
bool ReplaceAfter(std::string* s, const std::string& key, const std::string& value,
                  size_t token = 1) {
  const auto tokens = Tokens(*s);
  for (size_t i = 0; i + token < tokens.size(); ++i) {
    if (s->compare(tokens[i].at, tokens[i].size, key) == 0) {
      const Token t = tokens[i + token];
      s->replace(t.at, t.size, value);
      return true;
    }
  }
  return false;
}

// Format-specific damage.
std::string ObjSpecial(std::string* s, Mutator* m) {
  // A face index out of range, zero or negative.
  const auto starts = LineStarts(*s);
  std::vector<size_t> faces;
  for (size_t at : starts)
    if (s->compare(at, 2, "f ") == 0) faces.push_back(at);
  if (faces.empty()) return "no face";
  const size_t at = faces[m->Below(faces.size())];
  const size_t end = std::min(s->find('\n', at), s->size());
  std::string line = s->substr(at, end - at);
  auto tokens = Tokens(line);
  if (tokens.size() < 2) return "short face";
  const Token t = tokens[1 + m->Below(tokens.size() - 1)];
  const char* const values[] = {"0",           "-1",        "-9",   "9",          "-100",
                                "2147483648",  "-0",        "1/-1", "4294967296", "4294967297",
                                "1//99999",    "1/2/3/4",   "",     "1.5",        "nan",
                                "-2147483649", "9999999999"};
  const std::string v = m->Pick(values);
  line.replace(t.at, t.size, v);
  s->replace(at, end - at, line);
  return "face index -> '" + v + "'";
}

std::string OffSpecial(std::string* s, Mutator* m) {
  const std::string v = m->Pick(kCounts);
  ReplaceAfter(s, "OFF", v, 1 + m->Below(3));
  return "OFF count -> '" + v + "'";
}

std::string PlySpecial(std::string* s, Mutator* m) {
  const std::string v = m->Pick(kCounts);
  switch (m->Below(4)) {
    case 0:
      ReplaceAfter(s, "vertex", v);
      return "vertex count -> '" + v + "'";
    case 1:
      ReplaceAfter(s, "face", v);
      return "face count -> '" + v + "'";
    case 2: {
      const char* const types[] = {"char",  "uchar",  "short", "ushort", "int",  "uint",
                                   "float", "double", "int8",  "uint64", "list", "float128"};
      const std::string type = m->Pick(types);
      ReplaceAfter(s, "property", type);
      return "first property type -> '" + type + "'";
    }
    default: {
      const char* const types[] = {"uchar", "int", "uint", "char", "float", "double", "short"};
      const std::string a = m->Pick(types), b = m->Pick(types);
      ReplaceAfter(s, "list", a);
      ReplaceAfter(s, "list", b, 2);
      return "list types -> '" + a + " " + b + "'";
    }
  }
}

std::string StlBinarySpecial(std::string* s, Mutator* m) {
  if (s->size() < 84) return "short";
  if (m->Below(2)) {
    const uint32_t values[] = {0, 1, 3, 5, 0x7fffffffu, 0xffffffffu, 100000000u, 0x55555555u};
    const uint32_t v = values[m->Below(8)];
    std::memcpy(&(*s)[80], &v, 4);
    return "triangle count -> " + std::to_string(v);
  }
  const float values[] = {std::nanf(""), INFINITY, -INFINITY, 1e30f, -1e30f, 6e14f, 1e-40f, -0.f};
  const float v = values[m->Below(8)];
  const size_t facet = m->Below((s->size() - 84) / 50 + 1);
  const size_t at = 84 + facet * 50 + 4 * m->Below(12);
  if (at + 4 <= s->size()) std::memcpy(&(*s)[at], &v, 4);
  return "float at " + std::to_string(at) + " -> " + std::to_string(v);
}

std::string StlTextSpecial(std::string* s, Mutator* m) {
  const char* const words[] = {"facet",    "endfacet", "outer",  "loop",  "endloop",     "vertex",
                               "endsolid", "solid",    "normal", "SOLID", "vertex 1 2 3"};
  const auto tokens = Tokens(*s);
  if (tokens.empty()) return "no token";
  const Token t = tokens[m->Below(tokens.size())];
  const std::string w = m->Pick(words);
  s->replace(t.at, t.size, w);
  return "token at " + std::to_string(t.at) + " -> '" + w + "'";
}

std::string AscSpecial(std::string* s, Mutator* m) {
  const char* const keys[] = {"ncols", "nrows", "cellsize", "NODATA_value", "xllcorner",
                              "NCOLS", "NROWS", "CELLSIZE", "XLLCENTER"};
  const std::string key = m->Pick(keys);
  const std::string v = m->Below(2) ? m->Pick(kCounts) : m->Pick(kSpecialTokens);
  if (!ReplaceAfter(s, key, v)) return "no key " + key;
  return key + " -> '" + v + "'";
}

std::string PgmSpecial(std::string* s, Mutator* m) {
  const char* const values[] = {"0",     "1",     "2",   "255",    "256",
                                "65535", "65536", "-1",  "100000", "100000001",
                                "1e3",   "nan",   "4.5", "10001",  "99999999999999999999",
                                "+3",    "0x10"};
  const std::string v = m->Pick(values);
  // The header's tokens: magic, width, height, maxval (comments aside).
  const size_t field = 1 + m->Below(3);
  size_t count = 0;
  const auto tokens = Tokens(*s);
  for (const Token& t : tokens) {
    if ((*s)[t.at] == '#') continue;
    if (count++ == field) {
      s->replace(t.at, t.size, v);
      return "PGM header field " + std::to_string(field) + " -> '" + v + "'";
    }
  }
  return "no header field";
}

std::string JsonSpecial(std::string* s, Mutator* m) {
  // A value replaced: numbers by huge, tiny or non-finite ones, anything by another type.
  const char* const values[] = {"1e308",
                                "-1e308",
                                "1e999",
                                "-0",
                                "0",
                                "-1",
                                "1e-320",
                                "2147483648",
                                "null",
                                "true",
                                "\"\"",
                                "[]",
                                "{}",
                                "[1, 2]",
                                "[1e300, 0, 0]",
                                "\"\\u0000\"",
                                "\"\\ud800\"",
                                "\"\xff\"",
                                "[0, 0, 0, 0]",
                                "\"L\"",
                                "18446744073709551616",
                                "-9223372036854775809",
                                "1.0",
                                "NaN"};
  const std::string v = m->Pick(values);
  size_t colon = s->find(':', m->Below(s->size() + 1));
  if (colon == std::string::npos) colon = s->find(':');
  if (colon == std::string::npos) return "no value";
  // The value runs to the next ',' or '}' at the same level, or is a bracketed array.
  size_t start = s->find_first_not_of(" \t\r\n", colon + 1);
  if (start == std::string::npos) return "no value";
  size_t end = start;
  int depth = 0;
  bool in_string = false;
  for (; end < s->size(); ++end) {
    const char c = (*s)[end];
    if (in_string) {
      if (c == '\\')
        ++end;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      ++depth;
    } else if (c == ']' || c == '}') {
      if (depth-- == 0) break;
    } else if (c == ',' && depth == 0) {
      break;
    }
  }
  s->replace(start, end - start, v);
  return "value at " + std::to_string(start) + " -> '" + v + "'";
}

// ---------------------------------------------------------------------------------------------
// Checks.

using Read = std::function<Status(const std::string& path, std::string* error, std::string* bad)>;

bool Finite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
bool InRange(const Vec3& v, double limit) {
  return std::fabs(v.x) <= limit && std::fabs(v.y) <= limit && std::fabs(v.z) <= limit;
}
bool Unit(const Vec3& n) { return Finite(n) && std::fabs(Length(n) - 1) < 1e-6; }

std::string CheckSamples(const RawSamples& s) {
  if (s.points.empty()) return "success without samples";
  if (s.points.size() != s.normals.size()) return "points and normals differ in count";
  for (size_t i = 0; i < s.size(); ++i) {
    if (!Finite(s.points[i]) || !InRange(s.points[i], terrain::kMaxCoordinate))
      return "sample " + std::to_string(i) + " is not finite or out of range";
    if (!Unit(s.normals[i])) return "normal " + std::to_string(i) + " is not a unit vector";
  }
  return "";
}

std::string CheckMesh(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) return "success without triangles";
  for (size_t i = 0; i < mesh.vertices.size(); ++i)
    if (!Finite(mesh.vertices[i]) || !InRange(mesh.vertices[i], terrain::kMaxCoordinate))
      return "vertex " + std::to_string(i) + " is not finite or out of range";
  for (const auto& t : mesh.triangles) {
    for (uint32_t v : t)
      if (v >= mesh.vertices.size()) return "triangle index out of range";
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return "triangle repeats a vertex";
  }
  return "";
}

std::string CheckHeightMap(const HeightMap& map, double maxval) {
  if (map.cols < 1 || map.rows < 1) return "empty grid";
  const size_t cells = size_t(map.cols) * size_t(map.rows);
  if (cells > kMaxHeightMapCells) return "more cells than kMaxHeightMapCells";
  if (map.heights.size() != cells || map.valid.size() != cells) return "wrong cell count";
  if (!(std::isfinite(map.cell_size) && map.cell_size > 0)) return "bad cell size";
  for (size_t i = 0; i < cells; ++i) {
    if (!map.valid[i]) continue;
    const double h = map.heights[i];
    if (!std::isfinite(h)) return "height " + std::to_string(i) + " is not finite";
    if (maxval > 0 && !(h >= 0 && h <= maxval && h == std::floor(h)))
      return "grey level " + std::to_string(h) + " is not a whole number in [0, 65535]";
  }
  return "";
}

std::string CheckCharacter(const Character& c) {
  if (c.feet.empty()) return "no feet";
  for (const FootSpec& f : c.feet)
    if (!Finite(f.rest)) return "foot rest not finite";
  auto every_foot_once = [&](const std::vector<std::vector<int>>& groups) {
    std::vector<int> seen(c.feet.size(), 0);
    for (const auto& g : groups)
      for (int i : g) {
        if (i < 0 || size_t(i) >= c.feet.size()) return false;
        ++seen[size_t(i)];
      }
    return std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; });
  };
  if (!every_foot_once(c.gait)) return "gait does not list every foot once";
  if (!every_foot_once(c.pairs)) return "pairs do not list every foot once";
  const double positive[] = {c.step_length,      c.step_height,   c.max_rise,    c.reach,
                             c.slope_step_scale, c.max_slope_deg, c.max_turn_deg};
  for (double v : positive)
    if (!(std::isfinite(v) && v > 0)) return "a length or angle is not finite and positive";
  if (!(std::isfinite(c.body_height) && c.body_height >= 0)) return "bad body height";
  if (!(std::isfinite(c.slope_threshold_deg) && c.slope_threshold_deg >= 0 &&
        c.slope_threshold_deg <= 90))
    return "bad slope threshold";
  if (c.slope_step_scale > 1 || c.max_slope_deg >= 180 || c.max_turn_deg > 180)
    return "an angle or scale beyond its limit";
  if (c.frames_per_step < 2) return "frames_per_step below 2";
  return "";
}

std::string CheckWalk(const Walk& w) {
  if (!(std::isfinite(w.fps) && w.fps > 0)) return "fps not finite and positive";
  for (const WalkTrack& t : w.tracks) {
    for (size_t i = 0; i < t.keys.size(); ++i) {
      const WalkKey& k = t.keys[i];
      if (!std::isfinite(k.frame)) return "frame not finite";
      if (i > 0 && !(k.frame > t.keys[i - 1].frame)) return "frames do not increase";
      if (!Finite(k.position) || !InRange(k.position, kMaxKeyCoordinate))
        return "position not finite or out of range";
      if (!Finite(k.normal)) return "normal not finite";
    }
    if (t.kind == TrackKind::kBody) {
      if (t.rotations.size() != t.keys.size()) return "rotations and keys differ in count";
      for (const Quat& q : t.rotations)
        if (!(std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
              std::isfinite(q.w)) ||
            (q.x == 0 && q.y == 0 && q.z == 0 && q.w == 0))
          return "rotation not finite or zero";
    }
  }
  return "";
}

// Lines of `content`, as a reader counts them (the last without its newline included), at most:
// the height-map readers also end a line at a CR alone (readers refusing those count one line).
size_t LineCount(const std::string& content) {
  size_t breaks = 0;
  for (size_t i = 0; i < content.size(); ++i)
    breaks += content[i] == '\n' ||
              (content[i] == '\r' && (i + 1 == content.size() || content[i + 1] != '\n'));
  return breaks + 1;
}

// What is wrong with a failure's message, or "". `lines_promised`: every parse error is
// "FILE:LINE: ..." (the point file's promise).
std::string CheckMessage(const std::string& path, const std::string& content, Status status,
                         const std::string& error, bool lines_promised) {
  if (status != Status::kParseError && status != Status::kInvalidArgument &&
      status != Status::kLimitExceeded)
    return "unexpected status " + std::to_string(int(status));
  if (error.empty()) return "failure with an empty message";
  const std::string name = path.substr(path.rfind('/') + 1);
  if (error.find(name) == std::string::npos) return "message does not name the file";
  // "FILE:LINE:" or "FILE:LINE:COLUMN:": the line must be one the file has.
  const size_t at = error.find(path + ":");
  if (at == std::string::npos) return "";
  const char* p = error.c_str() + at + path.size() + 1;
  // Text that is not JSON is located: "FILE:LINE:COLUMN: malformed JSON: ...".
  const bool malformed_json = error.find(": malformed JSON: ") != std::string::npos;
  if (!std::isdigit(static_cast<unsigned char>(*p))) {
    if (lines_promised && status == Status::kParseError) return "message names no line";
    if (malformed_json) return "malformed JSON without its line and column";
    return "";
  }
  const unsigned long long line = std::strtoull(p, nullptr, 10);
  if (line < 1 || line > LineCount(content)) return "message names line " + std::to_string(line);
  return "";
}

struct Format {
  std::string name;       // for messages
  std::string extension;  // of the files written
  Kind kind;
  std::vector<std::string> seeds;
  std::function<std::string(std::string*, Mutator*)> special;
  Read read;
  bool lines_promised = false;
};

Read PointReader() {
  return [](const std::string& path, std::string* error, std::string* bad) {
    RawSamples samples;
    const Status status = ReadPointFile(path, &samples, error);
    // A file of comments reads as no samples: LoadTerrain refuses it, ReadPointFile need not.
    if (status == Status::kOk && !samples.points.empty())
      *bad = CheckSamples(samples);
    else if (!samples.points.empty())
      *bad = "failure left samples behind";
    return status;
  };
}

Read MeshReader() {
  return [](const std::string& path, std::string* error, std::string* bad) {
    TriangleMesh mesh;
    MeshReadReport report;
    const Status status = ReadMesh(path, &mesh, error, &report);
    if (status == Status::kOk) *bad = CheckMesh(mesh);
    return status;
  };
}

Read AscReader() {
  return [](const std::string& path, std::string* error, std::string* bad) {
    HeightMap map;
    const Status status = ReadAscGrid(path, &map, error);
    if (status == Status::kOk) *bad = CheckHeightMap(map, 0);
    return status;
  };
}

Read PgmReader() {
  return [](const std::string& path, std::string* error, std::string* bad) {
    HeightMap map;
    const Status status = ReadPgm(path, &map, error);
    if (status == Status::kOk) *bad = CheckHeightMap(map, 65535);
    return status;
  };
}

Read CharacterReader() {
  return [](const std::string& path, std::string* error, std::string* bad) {
    Character c;
    const Status status = LoadCharacter(path, &c, error);
    if (status == Status::kOk) *bad = CheckCharacter(c);
    return status;
  };
}

std::string CheckScene(const std::vector<SceneCharacter>& scene) {
  if (scene.empty()) return "no characters";
  std::set<std::string> names;
  for (const SceneCharacter& c : scene) {
    if (c.name.empty() || c.name.find('/') != std::string::npos) return "bad name";
    if (!names.insert(c.name).second) return "two characters of one name";
    const std::string character = CheckCharacter(c.character);
    if (!character.empty()) return character;
    const GenerateOptions& o = c.options;
    if (!Finite(o.start) || !Finite(o.heading) || !Finite(o.up) || !std::isfinite(o.start_frame))
      return "a start, heading, up or start frame not finite";
    for (const Vec3& p : o.path)
      if (!Finite(p)) return "a waypoint not finite";
    if (o.steps > 1000000 || o.crowd < 1 || o.crowd > 1000000) return "steps or crowd out of range";
    if (!(std::isfinite(o.crowd_spacing) && o.crowd_spacing >= 0)) return "bad crowd spacing";
  }
  return "";
}

Read SceneReader() {
  return [](const std::string& path, std::string* error, std::string* bad) {
    std::vector<SceneCharacter> scene;
    const Status status = LoadScene(path, &scene, error);
    if (status == Status::kOk) *bad = CheckScene(scene);
    return status;
  };
}

Read WalkReader() {
  return [](const std::string& path, std::string* error, std::string* bad) {
    Walk w;
    const Status status = ReadWalkJson(path, &w, error);
    if (status == Status::kOk) *bad = CheckWalk(w);
    return status;
  };
}

// The terrain loader, resampling meshes and height maps coarsely (few samples, fast).
Status LoadCoarsely(const std::string& path, std::string* error, std::string* bad) {
  TerrainLoadOptions options;
  options.max_samples = 4000;
  RawSamples samples;
  TerrainLoadReport report;
  const Status status = LoadTerrain(path, options, &samples, error, &report);
  if (status == Status::kOk) *bad = CheckSamples(samples);
  return status;
}

// Reads `content` as `path` and returns what is wrong, or "".
std::string RunCase(const test::TempDir& dir, const std::string& file, const std::string& content,
                    const Read& read, bool lines_promised, std::string* message = nullptr,
                    Status* result = nullptr) {
  const std::string path = dir.Write(file, content);
  std::string local, bad;
  std::string& error = message ? *message : local;
  Status status;
  const auto start = std::chrono::steady_clock::now();
  try {
    status = read(path, &error, &bad);
  } catch (const std::exception& e) {
    return std::string("exception: ") + e.what();
  } catch (...) {
    return "unknown exception";
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (seconds > 2) return "took " + std::to_string(seconds) + " s";
  if (result) *result = status;
  if (status == Status::kOk) return bad;
  return CheckMessage(path, content, status, error, lines_promised);
}

// Shows a mutated file's start, for a failure's report.
std::string Shown(const std::string& content) {
  std::string out;
  for (char c : content.substr(0, 160)) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u == '\n')
      out += "\\n";
    else if (u < 0x20 || u >= 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", u);
      out += hex;
    } else {
      out += c;
    }
  }
  return out + (content.size() > 160 ? "..." : "");
}

void Sweep(const Format& format, uint32_t seed) {
  test::TempDir dir;
  Mutator m(seed);
  std::vector<std::string> failures;
  // The seeds themselves read.
  for (size_t s = 0; s < format.seeds.size(); ++s) {
    const std::string what = RunCase(dir, "seed." + format.extension, format.seeds[s], format.read,
                                     format.lines_promised);
    std::string error, bad;
    const std::string path = dir.Write("seed." + format.extension, format.seeds[s]);
    INFO(format.name << " seed " << s);
    REQUIRE(format.read(path, &error, &bad) == Status::kOk);
    REQUIRE(bad.empty());
    REQUIRE(what.empty());
  }
  const int cases = CasesPerFormat();
  for (int i = 0; i < cases; ++i) {
    std::string content = format.seeds[m.Below(format.seeds.size())];
    std::string how;
    for (size_t n = 0, count = 1 + m.Below(4); n < count; ++n)
      how += (n ? ", " : "") + m.Mutate(&content, format.kind, format.special);
    const std::string file = "case" + std::to_string(i) + "." + format.extension;
    std::string error;
    std::string what = RunCase(dir, file, content, format.read, format.lines_promised, &error);
    // Every fifth case goes through the terrain loader too (terrain files only).
    if (what.empty() && format.kind != Kind::kJson && i % 5 == 0) {
      error.clear();
      what = RunCase(dir, file, content, LoadCoarsely, false, &error);
      if (!what.empty()) what = "LoadTerrain: " + what;
    }
    if (!what.empty()) {
      failures.push_back(format.name + " case " + std::to_string(i) + " (" + how + "): " + what +
                         "\n    message: " + error + "\n    file: " + Shown(content));
    }
  }
  std::string all;
  for (size_t i = 0; i < failures.size() && i < 10; ++i) all += failures[i] + "\n";
  INFO(failures.size() << " of " << cases << " cases failed:\n" << all);
  CHECK(failures.empty());
}

std::vector<Format> Formats() {
  const Read mesh = MeshReader();
  return {
      {"points", "pts", Kind::kText, {kPoints, kPointsCrlf}, nullptr, PointReader(), true},
      {"OBJ", "obj", Kind::kText, {kCubeObj, kTetraObj, GridObj()}, ObjSpecial, mesh},
      {"OFF", "off", Kind::kText, {kCubeOff}, OffSpecial, mesh},
      {"text PLY", "ply", Kind::kText, {kTetraPly}, PlySpecial, mesh},
      {"binary PLY", "ply", Kind::kBinary, {BinaryPly(false), BinaryPly(true)}, PlySpecial, mesh},
      {"text STL", "stl", Kind::kText, {kTetraStl}, StlTextSpecial, mesh},
      {"binary STL", "stl", Kind::kBinary, {BinaryStl()}, StlBinarySpecial, mesh},
      {"ASC", "asc", Kind::kText, {kAsc, kAscCenter}, AscSpecial, AscReader()},
      {"P2 PGM", "pgm", Kind::kText, {kPgmAscii}, PgmSpecial, PgmReader()},
      {"P5 PGM",
       "pgm",
       Kind::kBinary,
       {BinaryPgm(false), BinaryPgm(true)},
       PgmSpecial,
       PgmReader()},
      {"character", "json", Kind::kJson, {kBiped, kQuadruped}, JsonSpecial, CharacterReader()},
      {"walk", "json", Kind::kJson, {SeedWalk()}, JsonSpecial, WalkReader()},
      {"scene", "json", Kind::kJson, {SeedScene()}, JsonSpecial, SceneReader()},
  };
}

}  // namespace

TEST_CASE("Reader fuzz: damaged files of every format fail cleanly or read valid data",
          "[import][fuzz]") {
  const std::vector<Format> formats = Formats();
  for (size_t f = 0; f < formats.size(); ++f) {
    SECTION(formats[f].name) { Sweep(formats[f], 20261204u + uint32_t(f)); }
  }
}

TEST_CASE("Reader fuzz: a file cut short never reads as a valid file", "[import][fuzz]") {
  // Where each seed may end early and still be a whole file: files with counts, an end marker
  // or closing brackets must fail when cut before it; point files and OBJ may end at any line.
  auto last_token = [](const std::string& s) { return Tokens(s).back().at; };
  auto all = [](const std::string& s) { return s.size(); };
  const std::vector<std::pair<std::string, std::function<size_t(const std::string&)>>> bounds = {
      {"OFF", [](const std::string& s) { return s.rfind(" 255 0 0"); }},  // the colour is optional
      {"text PLY", last_token},
      {"binary PLY", all},
      {"text STL", [](const std::string& s) { return s.rfind("endsolid"); }},
      {"binary STL", all},
      {"ASC", last_token},
      {"P2 PGM", last_token},
      {"P5 PGM", all},
      {"character", [](const std::string& s) { return s.rfind('}'); }},
      {"walk", [](const std::string& s) { return s.rfind('}'); }},
      {"scene", [](const std::string& s) { return s.rfind('}'); }},
  };
  test::TempDir dir;
  std::vector<std::string> failures;
  size_t cases = 0;
  for (const Format& format : Formats()) {
    for (const auto& [name, bound] : bounds) {
      if (name != format.name) continue;
      for (const std::string& seed : format.seeds) {
        const size_t end = bound(seed);
        REQUIRE(end <= seed.size());
        for (size_t cut = 0; cut < end; ++cut) {
          ++cases;
          const std::string content = seed.substr(0, cut);
          std::string error;
          Status status = Status::kOk;
          std::string what =
              RunCase(dir, "cut." + format.extension, content, format.read, false, &error, &status);
          if (what.empty() && status == Status::kOk) what = "read as a valid file";
          if (!what.empty())
            failures.push_back(format.name + " cut at " + std::to_string(cut) + " of " +
                               std::to_string(seed.size()) + ": " + what);
        }
      }
    }
  }
  std::string shown;
  for (size_t i = 0; i < failures.size() && i < 10; ++i) shown += failures[i] + "\n";
  INFO(failures.size() << " of " << cases << " cuts failed:\n" << shown);
  CHECK(failures.empty());
}

TEST_CASE("Reader fuzz: every terrain file under every other extension fails cleanly",
          "[import][fuzz]") {
  const std::vector<Format> formats = Formats();
  const char* const extensions[] = {"pts", "xyz", "txt", "obj", "off", "ply", "stl", "asc", "pgm"};
  test::TempDir dir;
  std::vector<std::string> failures;
  for (const Format& format : formats) {
    for (const std::string& seed : format.seeds) {
      for (const char* ext : extensions) {
        const std::string what = RunCase(dir, std::string("as.") + ext, seed, LoadCoarsely, false);
        if (!what.empty()) failures.push_back(format.name + " as ." + ext + ": " + what);
      }
    }
  }
  std::string all;
  for (const std::string& f : failures) all += f + "\n";
  INFO(all);
  CHECK(failures.empty());
}

}  // namespace footfall

// Cases the sweep found, kept by name.
namespace footfall {

TEST_CASE("Reader fuzz: a binary PLY element without properties is skipped at once",
          "[import][fuzz]") {
  // Its records hold no bytes: 2^63 - 1 of them were counted through one by one (a hang).
  test::TempDir dir;
  std::string error;
  for (const char* count : {"9223372036854775807", "4294967296"}) {
    std::string ply = BinaryPly(false);
    ply.insert(ply.find("element face"), std::string("element junk ") + count + "\n");
    TriangleMesh mesh;
    const auto start = std::chrono::steady_clock::now();
    CHECK(ReadMesh(dir.Write("junk.ply", ply), &mesh, &error) == Status::kOk);
    CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(2));
    CHECK(mesh.triangles.size() == 4);
  }
}

}  // namespace footfall

namespace footfall {

TEST_CASE("Reader fuzz: height map header values out of range are named at their line",
          "[import][fuzz]") {
  // The message named the file only ("header needs whole ncols and nrows >= 1", "PGM maxval
  // above 65535"), though both readers promise "FILE:LINE: what was expected".
  test::TempDir dir;
  HeightMap map;
  std::string error;
  const std::string asc = "ncols 2\nnrows 2\ncellsize 1\n1 2\n3 4\n";
  const std::pair<std::string, std::string> cases[] = {
      {"ncols 2.5", "a.asc:1: ncols 2.5 (expected a whole number >= 1)"},
      {"ncols -1", "a.asc:1: ncols -1 (expected a whole number >= 1)"},
      {"nrows 0", "a.asc:2: nrows 0 (expected a whole number >= 1)"},
  };
  for (const auto& [replace, expected] : cases) {
    std::string text = asc;
    text.replace(text.find(replace.substr(0, 5)), 7, replace);
    CHECK(ReadAscGrid(dir.Write("a.asc", text), &map, &error) == Status::kParseError);
    CHECK(error.find(expected) != std::string::npos);
  }
  CHECK(ReadAscGrid(dir.Write("a.asc", "ncols 2\ncellsize 1\n1 2\n"), &map, &error) ==
        Status::kParseError);
  CHECK(error.find("a.asc: header needs nrows (a whole number >= 1)") != std::string::npos);
  for (const char* magic : {"P2", "P5"}) {
    CHECK(ReadPgm(dir.Write("p.pgm", std::string(magic) + "\n# c\n2 1\n70000\n0 0\n"), &map,
                  &error) == Status::kParseError);
    CHECK(error.find("p.pgm:4: PGM maxval above 65535") != std::string::npos);
  }
}

}  // namespace footfall

namespace footfall {

TEST_CASE("Reader fuzz: OFF and PLY counts beyond 2^63 are refused as written", "[import][fuzz]") {
  // strtoll held them at 2^63 - 1, and the message named that count, not the file's.
  test::TempDir dir;
  TriangleMesh mesh;
  std::string error;
  const std::string big = "99999999999999999999";
  const std::string tri = "0 0 0\n1 0 0\n0 1 0\n";
  const std::string ply_end =
      "\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list "
      "uchar int vertex_indices\nend_header\n" +
      tri + "3 0 1 2\n";
  const std::pair<std::string, std::string> cases[] = {
      {"OFF\n" + big + " 1 0\n" + tri + "3 0 1 2\n", "m.off:2: expected counts"},
      {"OFF\n3 " + big + " 0\n" + tri + "3 0 1 2\n", "m.off:2: expected counts"},
      {"OFF\n3 1 0\n" + tri + big + " 0 1 2\n", "m.off:6: face must start with its vertex count"},
      {"ply\nformat ascii 1.0\nelement vertex " + big + ply_end,
       "m.ply:3: element 'vertex' count '" + big + "' is not a whole number >= 0"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string name = text[0] == 'O' ? "m.off" : "m.ply";
    CHECK(ReadMesh(dir.Write(name, text), &mesh, &error) == Status::kParseError);
    CHECK(error.find(expected) != std::string::npos);
    CHECK(error.find("9223372036854775807") == std::string::npos);
  }
}

}  // namespace footfall

namespace footfall {

TEST_CASE("Reader fuzz: numbers are decimal with one sign in every text terrain format",
          "[import][fuzz]") {
  // strtod read "0x10" as 16 in meshes and height maps, and the point file's reader, skipping a
  // '+' before from_chars, read "+-1" as -1.
  test::TempDir dir;
  std::string error;
  TriangleMesh mesh;
  HeightMap map;
  RawSamples samples;
  for (const std::string token : {"0x10", "0X1p3", "-0x1", "0x"}) {
    INFO(token);
    CHECK(ReadMesh(dir.Write("h.obj", "v " + token + " 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), &mesh,
                   &error) == Status::kParseError);
    CHECK(error.find("h.obj:1: vertex coordinate") != std::string::npos);
    CHECK(ReadMesh(dir.Write("h.off", "OFF\n3 1 0\n0 0 0\n1 " + token + " 0\n0 1 0\n3 0 1 2\n"),
                   &mesh, &error) == Status::kParseError);
    CHECK(error.find("h.off:4: vertex coordinate") != std::string::npos);
    CHECK(ReadAscGrid(dir.Write("h.asc", "ncols 2\nnrows 1\ncellsize 1\n1 " + token + "\n"), &map,
                      &error) == Status::kParseError);
    CHECK(error.find("h.asc:4: value") != std::string::npos);
    CHECK(ReadPgm(dir.Write("h.pgm", "P2\n2 1\n255\n1 " + token + "\n"), &map, &error) ==
          Status::kParseError);
    CHECK(error.find("h.pgm:4: grey level") != std::string::npos);
  }
  for (const std::string token : {"+-1", "+-0", "-+1", "++1"}) {
    INFO(token);
    CHECK(ReadPointFile(dir.Write("s.pts", "0 0 0 0 1 0\n" + token + " 0 0 0 1 0\n"), &samples,
                        &error) == Status::kParseError);
    CHECK(error.find("s.pts:2: column 1: '" + token + "' is not a number") != std::string::npos);
  }
  // One sign is a number, in every reader.
  REQUIRE(ReadPointFile(dir.Write("s.pts", "+1 -1 +.5 0 +1 0\n"), &samples, &error) == Status::kOk);
  CHECK(samples.points[0] == Vec3{1, -1, 0.5});
  REQUIRE(ReadMesh(dir.Write("s.obj", "v +1 -0 +.5\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), &mesh, &error) ==
          Status::kOk);
  CHECK(mesh.vertices[0] == Vec3{1, 0, 0.5});
  REQUIRE(ReadAscGrid(dir.Write("s.asc", "ncols 2\nnrows 1\ncellsize +1\n+1 -2.5e0\n"), &map,
                      &error) == Status::kOk);
  CHECK(map.heights[1] == -2.5);
}

}  // namespace footfall

namespace footfall {

TEST_CASE("Reader fuzz: a directory or FIFO named as a mesh or height map is refused",
          "[import][fuzz]") {
  // ReadAscGrid and ReadPgm threw std::ios_base::failure reading a directory, ReadMesh called it
  // an empty file, and all three waited on a FIFO for a writer.
  test::TempDir dir;
  std::string error;
  TriangleMesh mesh;
  HeightMap map;
  for (const char* name : {"d.obj", "d.ply", "d.stl", "d.off", "d.asc", "d.pgm"}) {
    INFO(name);
    const std::string path = dir.File(name);
    REQUIRE(mkdir(path.c_str(), 0700) == 0);
    const std::string ext = path.substr(path.size() - 3);
    Status status = Status::kOk;
    REQUIRE_NOTHROW(status = ext == "asc"   ? ReadAscGrid(path, &map, &error)
                             : ext == "pgm" ? ReadPgm(path, &map, &error)
                                            : ReadMesh(path, &mesh, &error));
    CHECK(status == Status::kInvalidArgument);
    CHECK(error == path + ": cannot open " +
                       (ext == "asc" || ext == "pgm" ? "height map" : "mesh") + ": a directory");
    const std::string fifo = dir.File(std::string("f.") + ext);
    REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
    status = ext == "asc"   ? ReadAscGrid(fifo, &map, &error)
             : ext == "pgm" ? ReadPgm(fifo, &map, &error)
                            : ReadMesh(fifo, &mesh, &error);
    CHECK(status == Status::kInvalidArgument);
    CHECK(error.find("a FIFO, not a regular file") != std::string::npos);
  }
}

}  // namespace footfall
