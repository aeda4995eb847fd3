#include "footfall/terrain/point_file.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <istream>
#include <sstream>
#include <string_view>
#include <system_error>

#include "footfall/terrain/input_file.h"
#include "footfall/terrain/output_file.h"
#include "footfall/terrain/shown_text.h"

namespace footfall {
namespace {

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// For a number out of a double's range: true when it is too small (a negative exponent, or no
// exponent and no whole part, as 0.000...1), false when too large.
bool Underflows(std::string_view number) {
  const size_t e = number.find_first_of("eE");
  if (e != std::string_view::npos) return e + 1 < number.size() && number[e + 1] == '-';
  if (!number.empty() && (number[0] == '-' || number[0] == '+')) number.remove_prefix(1);
  return number.substr(0, 2) == "0." || number.substr(0, 1) == ".";
}

Status Fail(const std::string& name, size_t line, const std::string& what, RawSamples* out,
            std::string* error) {
  out->clear();
  if (error) *error = name + ":" + std::to_string(line) + ": " + what;
  return Status::kParseError;
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
    const size_t hash = line.find('#');
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
        const char* first = token.data();
        const char* last = first + token.size();
        // from_chars rejects a leading '+' (but reads "+-1" as -1 once it is skipped).
        if (*first == '+' && token.size() > 1 && first[1] != '-') ++first;
        double value = 0;
        const auto [ptr, ec] = std::from_chars(first, last, value);
        // Too small for a double (1e-400, 0.000...) reads as 0, as other readers have it; too
        // large is refused.
        const bool tiny = ec == std::errc::result_out_of_range && ptr == last && Underflows(token);
        if (tiny) value = token[0] == '-' ? -0.0 : 0.0;
        if (ec == std::errc::result_out_of_range && ptr == last && !tiny) {
          return Fail(name, line_no,
                      "column " + std::to_string(count + 1) + ": '" + ShownText(token) +
                          "' is out of range (expected a finite number)",
                      out, error);
        }
        if (!tiny && (ec != std::errc() || ptr != last)) {
          return Fail(name, line_no,
                      "column " + std::to_string(count + 1) + ": '" + ShownText(token) +
                          "' is not a number (expected x y z nx ny nz)",
                      out, error);
        }
        if (!std::isfinite(value)) {
          return Fail(name, line_no,
                      "column " + std::to_string(count + 1) + ": '" + ShownText(token) +
                          "' is NaN or infinite (expected a finite number)",
                      out, error);
        }
        if (count < 3 && std::fabs(value) > terrain::kMaxCoordinate) {
          std::ostringstream m;
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
    const Vec3 normal = SafeNormalize({v[3], v[4], v[5]});
    if (normal == Vec3{}) {
      return Fail(name, line_no, "normal has zero length (expected a non-zero nx ny nz)", out,
                  error);
    }
    out->push_back({v[0], v[1], v[2]}, normal);
  }
  if (lines.too_long()) {
    return Fail(name, line_no + 1, LineReader::TooLongMessage("x y z nx ny nz"), out, error);
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
  return ReadPointStream(in, path, out, error);
}

Status WritePointFile(const std::string& path, const RawSamples& samples, std::string* error) {
  return ReplaceFile(
      path,
      [&samples](FILE* f) {
        std::fprintf(f, "# footfall terrain points: x y z nx ny nz (%zu samples)\n",
                     samples.size());
        // Each number as the shortest text that reads back as the same double: the file holds
        // the samples exactly (12 digits moved samples 1e10 from the origin by up to 0.05).
        char line[6 * 32];
        for (size_t i = 0; i < samples.size(); ++i) {
          const Vec3& p = samples.points[i];
          const Vec3& n = samples.normals[i];
          char* at = line;
          for (double v : {p.x, p.y, p.z, n.x, n.y, n.z}) {
            at = std::to_chars(at, line + sizeof line - 1, v).ptr;
            *at++ = ' ';
          }
          at[-1] = '\n';
          if (std::fwrite(line, 1, static_cast<size_t>(at - line), f) !=
              static_cast<size_t>(at - line))
            return false;
        }
        return true;
      },
      error);
}

}  // namespace footfall
