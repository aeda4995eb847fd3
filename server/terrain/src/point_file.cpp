#include "footfall/terrain/point_file.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <istream>
#include <new>
#include <string_view>

#include "footfall/terrain/decimal_number.h"
#include "footfall/terrain/input_file.h"
#include "footfall/terrain/ordered_text.h"
#include "footfall/terrain/output_file.h"
#include "footfall/terrain/shown_text.h"
#include "footfall/terrain/text_stream.h"

namespace footfall {
namespace {

// Whether a CR stands before the line's end: a classic Mac OS line end (CRs ending a line,
// before its LF or the file's end, are part of the line end).
bool HasLoneCr(std::string_view line) {
  const size_t cr = line.find('\r');
  return cr != std::string_view::npos && line.find_first_not_of('\r', cr) != std::string_view::npos;
}

constexpr const char* kLoneCr =
    "line ends in CR alone (classic Mac OS): convert line ends to LF or CR LF";

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

Status Fail(const std::string& name, size_t line, const std::string& what, RawSamples* out,
            std::string* error) {
  *out = RawSamples{};  // its reserved room too
  if (error) *error = name + ":" + std::to_string(line) + ": " + what;
  return Status::kParseError;
}

// The samples a point file of `bytes` is likely to hold, for reserving room before reading it
// (grown one push at a time, the arrays were copied and first touched twice over: about 40% of
// reading a 2M-sample file). The count footfall's own header gives ("# footfall terrain points:
// ... (N samples)" on the first line), when the file has room for that many; else one per 48
// bytes, the length of a line of short numbers (the arrays grow as usual beyond it).
size_t ExpectedSamples(std::istream& in, uint64_t bytes) {
  constexpr uint64_t kShortestLine = 12;  // "0 0 0 0 0 1\n"
  const uint64_t most = bytes / kShortestLine + 1;
  char first[128] = "";
  in.getline(first, sizeof first);
  in.clear();
  in.seekg(0);
  const std::string_view line(first);
  const size_t open = line.rfind('(');
  if (line.rfind("# footfall terrain points:", 0) == 0 && open != std::string_view::npos) {
    uint64_t n = 0;
    const char* begin = line.data() + open + 1;
    const auto [end, ec] = std::from_chars(begin, line.data() + line.size(), n);
    if (ec == std::errc() && std::string_view(end).rfind(" sample", 0) == 0 && n <= most)
      return static_cast<size_t>(n);
  }
  return static_cast<size_t>(std::min<uint64_t>(bytes / 48, most));
}

}  // namespace

Status ReadPointStream(std::istream& in, const std::string& name, RawSamples* out,
                       std::string* error) {
  out->clear();
  std::string text;
  size_t line_no = 0;
  LineReader lines(in);
  while (lines.Next(&text)) {
    ++line_no;
    std::string_view line(text);
    if (line_no == 1 && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);  // UTF-8 BOM
    if (line_no == 1) {
      // The first line holds the file's first bytes, up to its first '\n' byte (in UTF-16 and
      // UTF-32 text too).
      const std::string wide = WideTextProblem(text + '\n');
      if (!wide.empty()) return Fail(name, line_no, wide, out, error);
    }
    // A CR read as a space joined lines, and a comment on the first one hid all the others.
    if (HasLoneCr(line)) return Fail(name, line_no, kLoneCr, out, error);
    // A comment starts at '#', but not within Microsoft C's "1.#INF" or "1.#QNAN".
    const size_t hash = CommentStart(line);
    if (hash != std::string_view::npos) line = line.substr(0, hash);
    double v[6];
    int count = 0;
    size_t pos = 0;
    while (true) {
      while (pos < line.size() && IsSpace(line[pos])) ++pos;
      if (pos >= line.size()) break;
      size_t end = pos;
      while (end < line.size() && !IsSpace(line[end])) ++end;
      const std::string_view token = line.substr(pos, end - pos);
      if (count < 6) {
        double value = 0;
        const DecimalRead read = ReadDecimal(token, &value);
        if (read == DecimalRead::kTooLarge) {
          return Fail(name, line_no,
                      "column " + std::to_string(count + 1) + ": '" + ShownText(token) +
                          "' is out of range (expected a finite number)",
                      out, error);
        }
        if (read == DecimalRead::kNotANumber && IsMicrosoftNonFinite(token)) {
          return Fail(name, line_no,
                      "column " + std::to_string(count + 1) + ": '" + ShownText(token) +
                          "' is NaN or infinite" + NotFiniteNote(token) +
                          " (expected a finite number)",
                      out, error);
        }
        if (read == DecimalRead::kNotANumber) {
          return Fail(name, line_no,
                      "column " + std::to_string(count + 1) + ": '" + ShownText(token) + "'" +
                          HiddenBytesNote(token) + " is not a number" + CommaNote(token) +
                          " (expected x y z nx ny nz)",
                      out, error);
        }
        if (!std::isfinite(value)) {
          return Fail(name, line_no,
                      "column " + std::to_string(count + 1) + ": '" + ShownText(token) +
                          "' is NaN or infinite (expected a finite number)",
                      out, error);
        }
        if (count < 3 && std::fabs(value) > terrain::kMaxCoordinate) {
          TextStream m;
          m << "column " << count + 1 << ": " << ShownText(token) << " is out of range (expected |"
            << "xyz"[count] << "| <= " << terrain::kMaxCoordinate << ")";
          return Fail(name, line_no, m.str(), out, error);
        }
        v[count] = value;
      }
      ++count;
      pos = end;
    }
    if (count == 0) continue;
    if (count != 6) {
      return Fail(name, line_no,
                  "expected 6 numbers (x y z nx ny nz), found " + std::to_string(count), out,
                  error);
    }
    const Vec3 normal = UnitNormal({v[3], v[4], v[5]});
    if (normal == Vec3{}) {
      return Fail(name, line_no, "normal has zero length (expected a non-zero nx ny nz)", out,
                  error);
    }
    out->push_back({v[0], v[1], v[2]}, normal);
  }
  if (lines.too_long()) {
    return Fail(name, line_no + 1,
                HasLoneCr(lines.too_long_start()) ? std::string(kLoneCr)
                                                  : LineReader::TooLongMessage("x y z nx ny nz"),
                out, error);
  }
  if (in.bad()) {
    out->clear();
    if (error) *error = name + ": read error";
    return Status::kIoError;
  }
  return Status::kOk;
}

Status ReadPointFile(const std::string& path, RawSamples* out, std::string* error) {
  out->clear();
  const Status status = CheckInputFile(path, "file", error);
  if (status != Status::kOk) return status;
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    out->clear();
    if (error) *error = path + ": cannot open file: " + std::strerror(errno ? errno : EIO);
    return Status::kIoError;
  }
  in.seekg(0, std::ios::end);
  const std::streamoff bytes = in.tellg();
  in.seekg(0);
  if (bytes > 0 && in) {
    const size_t expected = ExpectedSamples(in, static_cast<uint64_t>(bytes));
    try {
      out->points.reserve(expected);
      out->normals.reserve(expected);
    } catch (const std::bad_alloc&) {
      *out = RawSamples{};  // no room to reserve (a memory limit): grown as it is read
    }
  }
  in.clear();
  in.seekg(0);
  return ReadPointStream(in, path, out, error);
}

Status WritePointFile(const std::string& path, const RawSamples& samples, std::string* error) {
  return ReplaceFile(
      path,
      [&samples](FILE* f) {
        std::fprintf(f, "# footfall terrain points: x y z nx ny nz (%zu samples)\n",
                     samples.size());
        // Runs of samples formatted on one thread per core, written in order.
        constexpr size_t kRun = 20000;
        const size_t runs = (samples.size() + kRun - 1) / kRun;
        return FormatInOrder(
            runs, 0,
            [&samples](size_t run, std::string* text) {
              const size_t end = std::min(samples.size(), (run + 1) * kRun);
              text->reserve((end - run * kRun) * 6 * 24);
              // Each number as the shortest text that reads back as the same double: the file
              // holds the samples exactly (12 digits moved samples 1e10 from the origin by up to
              // 0.05).
              char line[6 * 32];
              for (size_t i = run * kRun; i < end; ++i) {
                const Vec3& p = samples.points[i];
                const Vec3& n = samples.normals[i];
                char* at = line;
                for (double v : {p.x, p.y, p.z, n.x, n.y, n.z}) {
                  at = std::to_chars(at, line + sizeof line - 1, v).ptr;
                  *at++ = ' ';
                }
                at[-1] = '\n';
                text->append(line, static_cast<size_t>(at - line));
              }
            },
            [f](std::string_view text) {
              return std::fwrite(text.data(), 1, text.size(), f) == text.size();
            });
      },
      error);
}

}  // namespace footfall
