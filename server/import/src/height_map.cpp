#include "footfall/import/height_map.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include "footfall/terrain/ascii.h"
#include "footfall/terrain/decimal_number.h"
#include "footfall/terrain/input_file.h"
#include "footfall/terrain/large_memory.h"
#include "footfall/terrain/samples.h"
#include "footfall/terrain/shown_text.h"
#include "footfall/terrain/text_stream.h"

namespace footfall {
namespace {

Status Fail(const std::string& where, const std::string& what, std::string* error) {
  if (error) *error = where + ": " + what;
  return Status::kParseError;
}

std::string Lower(std::string s) {
  for (char& c : s) c = AsciiLower(c);
  return s;
}

// A number as people write it: "5e+14", "0.25".
std::string Number(double v) {
  TextStream out;
  out << v;
  return out.str();
}

// Whitespace-separated tokens with their line numbers (lines end at LF, CR LF or CR); '#'
// comments optional.
class TokenReader {
 public:
  TokenReader(const std::string& text, bool comments) : text_(&text), comments_(comments) {}
  // Next without the token: false at the end of the text.
  bool Skip() {
    for (;;) {
      while (pos_ < text_->size() && std::isspace(static_cast<unsigned char>((*text_)[pos_]))) {
        // LF, CR LF, and a CR alone (old Mac files: their errors were all named at line 1).
        const char c = (*text_)[pos_];
        if (c == '\n' || (c == '\r' && (pos_ + 1 == text_->size() || (*text_)[pos_ + 1] != '\n')))
          ++line_;
        ++pos_;
      }
      if (comments_ && pos_ < text_->size() && (*text_)[pos_] == '#') {
        while (pos_ < text_->size() && (*text_)[pos_] != '\n') ++pos_;
        continue;
      }
      break;
    }
    if (pos_ >= text_->size()) return false;
    start_ = pos_;
    while (pos_ < text_->size() && !std::isspace(static_cast<unsigned char>((*text_)[pos_])))
      ++pos_;
    return true;
  }
  bool Next(std::string* token) {
    if (!Skip()) return false;
    *token = text_->substr(start_, pos_ - start_);
    return true;
  }
  size_t line() const { return line_; }
  size_t pos() const { return pos_; }
  // The first character of the token last read.
  char first() const { return (*text_)[start_]; }

 private:
  const std::string* text_;
  bool comments_;
  size_t pos_ = 0, line_ = 1;
  size_t start_ = 0;  // where the token last read starts
};

// Whether an ASCII grid's token spells NaN ("nan", "NaN", "-nan": a NODATA_value of NaN and its
// cells).
bool IsNanText(const std::string& token) {
  const std::string t = Lower(token);
  return t == "nan" || t == "-nan" || t == "+nan" || IsMicrosoftNaN(token);
}

// "value 'T' is not a finite number", with what it looks like: Microsoft C's NaN or infinity,
// a decimal comma, or values separated by commas.
std::string NotAValue(const std::string& token) {
  return "value '" + ShownText(token) + "' is not a finite number" + NotFiniteNote(token) +
         CommaNote(token);
}

// Whether an ASCII grid's token is meant as a value, not a header key: it starts like a number
// or spells NaN or infinity (a bad first value is then named as a value, not as a header).
bool IsValueText(const std::string& token) {
  const char c = token.empty() ? ' ' : token[0];
  if (std::isdigit(static_cast<unsigned char>(c)) || c == '+' || c == '-' || c == '.') return true;
  const std::string t = Lower(token);
  return t == "nan" || t == "inf" || t == "infinity";
}

// The first word of a text file (after a byte order mark and white space), if it ends within
// its first 256 bytes; else "".
std::string FirstWord(std::istream& in) {
  char start[256];
  in.read(start, sizeof start);
  std::string head(start, static_cast<size_t>(in.gcount()));
  in.clear();
  in.seekg(0);
  if (head.compare(0, 3, "\xEF\xBB\xBF") == 0) head.erase(0, 3);
  const size_t begin = head.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  const size_t end = head.find_first_of(" \t\r\n", begin);
  if (end == std::string::npos && head.size() == sizeof start) return "";
  return head.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

// The first bytes of a file a header must lie within: a head check reads no further.
constexpr size_t kHeadBytes = 65536;

// Reads the file whole, once its first word is one `starts_ok` accepts (a file of NUL bytes or
// without line breaks is refused before it is read; `expected` says what should start it) and,
// for a file longer than kHeadBytes, once `head_ok` accepts its head (up to its last white space
// within kHeadBytes, byte order mark removed): a header declaring a grid too large is refused
// before the file is read (a 3 GB image took 29 s and 6 GB to be refused). Out of memory is
// kLimitExceeded naming the file.
// The most bytes a text height map's value takes with its white space, for CheckFileSize: a
// double written in full ("-1.2345678901234567e+300") is 24, columns padded wide a few more.
constexpr double kMostBytesPerTextValue = 64;

// kParseError, naming `path`, when a file of `size` bytes is far larger than its header's
// `declared` grid of `values` values could be at `most_per_value` bytes each (text values and
// their white space; binary pixels exactly), with a megabyte to spare: data past the grid,
// refused before it is read whole (a 2 x 2 grid followed by 3 GB took 30 s and 6 GB).
Status CheckFileSize(const std::string& path, double size, double values, double most_per_value,
                     const std::string& declared, std::string* error) {
  const double most = values * most_per_value + 1048576;
  if (size <= most) return Status::kOk;
  TextStream m;
  m.precision(15);
  m << size << " bytes, far more than " << declared << " needs (at most " << most
    << " bytes: " << most_per_value << (most_per_value == 1 ? " byte" : " bytes")
    << " a value, and a "
    << "megabyte to spare): data past the grid (check the header's size)";
  return Fail(path, m.str(), error);
}

template <typename StartsOk, typename HeadOk>
Status ReadWhole(const std::string& path, std::string* text, std::string* error,
                 const StartsOk& starts_ok, const char* expected, const HeadOk& head_ok) {
  // A directory opened as a file threw out of the read below (EISDIR); a FIFO waited.
  const Status input = CheckInputFile(path, "height map", error);
  if (input != Status::kOk) return input;
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    if (error) *error = path + ": cannot open: " + std::strerror(errno ? errno : EIO);
    return Status::kIoError;
  }
  char mark[8] = {};
  in.read(mark, sizeof mark);
  const std::string wide = WideTextProblem({mark, static_cast<size_t>(in.gcount())});
  if (!wide.empty()) return Fail(path + ":1", wide, error);
  in.clear();
  in.seekg(0);
  const std::string word = FirstWord(in);
  if (in.peek() != std::char_traits<char>::eof() && !starts_ok(word)) {
    const std::string found =
        word.empty() ? "no word within its first 256 bytes" : "'" + ShownText(word) + "'";
    return Fail(path + ":1", std::string("expected ") + expected + ", found " + found, error);
  }
  in.clear();
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0);
  if (size > static_cast<std::streamoff>(kHeadBytes)) {
    std::string head(kHeadBytes, '\0');
    in.read(&head[0], static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<size_t>(in.gcount()));
    const size_t last_space = head.find_last_of(" \t\r\n");  // no word cut in two
    if (last_space != std::string::npos) head.resize(last_space + 1);
    if (head.compare(0, 3, "\xEF\xBB\xBF") == 0) head.erase(0, 3);
    const Status status = head_ok(head, static_cast<double>(size));
    if (status != Status::kOk) return status;
    in.clear();
    in.seekg(0);
  }
  try {
    text->clear();
    if (size > 0) {
      text->resize(static_cast<size_t>(size));
      in.read(&(*text)[0], static_cast<std::streamsize>(size));
      text->resize(static_cast<size_t>(in.gcount()));
    }
    // A file that grew since its size was taken (or one without a size): the rest too.
    text->append(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } catch (const std::bad_alloc&) {
    std::string().swap(*text);
    if (error) {
      *error = path + ": out of memory reading the file whole (" + std::to_string(size) +
               " bytes; crop or downsample the grid)";
    }
    return Status::kLimitExceeded;
  }
  if (text->compare(0, 3, "\xEF\xBB\xBF") == 0) text->erase(0, 3);  // UTF-8 byte order mark
  if (text->empty()) return Fail(path, "the file is empty, expected a height map", error);
  return Status::kOk;
}

// A whole number of the header as text ("1000000000", not "1e+09"; beyond 1e18, as "1e+30":
// the conversion to an integer overflowed to -9223372036854775808).
std::string Count(double n) {
  if (std::fabs(n) < 1e18) return std::to_string(static_cast<long long>(n));
  TextStream out;
  out << n;
  return out.str();
}

// Counts the tokens `reader` has left, up to one more than a height map may have, and the line
// of the last one counted.
size_t CountValues(TokenReader reader, double declared, size_t* last_line) {
  const double limit = std::min(declared, static_cast<double>(kMaxHeightMapCells) + 1);
  size_t count = 0;
  *last_line = reader.line();
  while (static_cast<double>(count) < limit && reader.Skip()) {
    ++count, *last_line = reader.line();
  }
  return count;
}

// Checks a header's grid of `cells` cells before anything is allocated for it: against the data
// the file holds (`present` values, the last on `last_line`; see CountValues) and against
// kMaxHeightMapCells. `declared` says what the header asked for ("6 values (2 rows of 3)"),
// `header` where ("FILE:2").
Status CheckGridSize(const std::string& path, const std::string& header, double cells,
                     const std::string& declared, size_t present, size_t last_line,
                     std::string* error) {
  if (static_cast<double>(present) < cells && present <= kMaxHeightMapCells) {
    return Fail(path + ":" + std::to_string(last_line),
                "truncated: expected " + declared + ", found " + std::to_string(present), error);
  }
  if (cells > static_cast<double>(kMaxHeightMapCells)) {
    return Fail(header,
                "the header declares " + declared + ", more than the " +
                    std::to_string(kMaxHeightMapCells) + " cells a height map may have",
                error);
  }
  // Reading, meshing and resampling take about 130 bytes a cell (measured: 1.1 GB for 3000 x
  // 3000): a grid this machine cannot hold is refused now, not after a minute of work.
  constexpr double kBytesPerCell = 130;
  const double memory = UsableMemoryBytes();
  if (memory > 0 && cells * kBytesPerCell > memory) {
    TextStream m;
    m.precision(3);
    m << "the header declares " << declared << ": reading it needs about "
      << cells * kBytesPerCell / 1e9 << " GB, more than the " << memory / 1e9
      << " GB of memory this process may use (crop or downsample the grid)";
    return Fail(header, m.str(), error);
  }
  return Status::kOk;
}

// The error for a '#' comment in an ASCII grid (read as a header or a value).
Status CommentInGrid(const std::string& path, size_t line, std::string* error) {
  return Fail(path + ":" + std::to_string(line),
              "'#' starts a comment, which ESRI ASCII grids do not have (expected header keys, "
              "then the values): remove it",
              error);
}

// "1 value", "2 values".
std::string Values(size_t n) { return std::to_string(n) + (n == 1 ? " value" : " values"); }

// Whether the values from `reader` on run on over rows, the same number to every line but a
// last shorter one (all on one line, or wrapped at a fixed width whatever the rows), and are
// exactly `cells` of them: such a grid's rows cannot be told apart, only counted.
bool RunsOnOverRows(TokenReader reader, size_t cells) {
  size_t width = 0, total = 0, line = 0, n = 0;
  bool last_shorter = false;  // a line shorter than the width was seen: it must be the last
  auto end_line = [&] {
    if (width == 0) width = n;
    if (n > width || last_shorter) return false;
    last_shorter = n < width;
    return true;
  };
  while (reader.Skip()) {
    if (reader.line() != line && n > 0) {
      if (!end_line()) return false;
      n = 0;
    }
    line = reader.line(), ++n, ++total;
    if (total > cells) return false;
  }
  return n > 0 && end_line() && total == cells;
}

// Checks that an ASCII grid's rows (`rows` of `cols` values, from `reader` on) lie on whole
// lines, each as the first row does: one row per line, or wrapped over lines alike. A short row
// and a long one added up to the header's count, and the grid loaded shifted. Data that ends
// within a row is left to the truncation check, and values after the last row to the check for
// values too many.
Status CheckAscRows(const std::string& path, TokenReader reader, size_t cols, size_t rows,
                    std::string* error) {
  std::vector<size_t> pattern;  // the values on each line of the first row
  size_t first_row = 0;         // the first row's values so far
  size_t row = 0, line_in_row = 0;
  auto layout = [&] {
    std::string text = "ncols " + std::to_string(cols) + ", ";
    if (pattern.size() == 1) return text + "one row per line";
    if (pattern.size() > 4)
      return text + "each row on " + std::to_string(pattern.size()) + " lines as the first row";
    text += "each row on lines of ";
    for (size_t i = 0; i < pattern.size(); ++i) {
      text += (i == 0 ? "" : i + 1 == pattern.size() ? " and " : ", ") + std::to_string(pattern[i]);
    }
    return text + " values as the first row";
  };
  const TokenReader start = reader;
  bool more = reader.Skip();
  while (more && row < rows) {
    const size_t line = reader.line();
    size_t n = 0;  // the values on `line`
    do {
      if (reader.first() == '#') return CommentInGrid(path, line, error);
      ++n;
    } while ((more = reader.Skip()) && reader.line() == line);
    if (row == 0) {
      pattern.push_back(n);
      first_row += n;
      if (first_row < cols) continue;
      if (first_row > cols) {
        if (RunsOnOverRows(start, cols * rows)) return Status::kOk;  // only counted
        return Fail(path + ":" + std::to_string(line),
                    pattern.size() == 1
                        ? Values(n) + ", expected " + std::to_string(cols) + " (" + layout() + ")"
                        : Values(n) + ", past the end of the first row (ncols " +
                              std::to_string(cols) + ": expected each row to end its line)",
                    error);
      }
      row = 1;
      continue;
    }
    const size_t want = pattern[line_in_row];
    if (n != want) {
      if (!more && n < want) return Status::kOk;  // cut short: truncated
      return Fail(path + ":" + std::to_string(line),
                  Values(n) + ", expected " + std::to_string(want) + " (" + layout() + ")", error);
    }
    if (++line_in_row == pattern.size()) ++row, line_in_row = 0;
  }
  return Status::kOk;
}

// An ESRI ASCII grid's header, as ParseAscHeader reads it.
struct AscHeader {
  double ncols = -1, nrows = -1, cellsize = -1, nodata = NAN;
  bool has_nodata = false, nodata_is_nan = false;
  size_t size_line = 1;  // the line of ncols or nrows, whichever comes last
};

// Reads an ASCII grid's header from `reader` (KEY VALUE lines until the first token that is a
// number), leaving `reader` before the first value. *ended (if not null) is set when the text
// ends within the header.
Status ParseAscHeader(const std::string& path, TokenReader* reader, bool cell_size_given,
                      AscHeader* h, std::string* error, bool* ended = nullptr) {
  std::string key, value;
  double& ncols = h->ncols;
  double& nrows = h->nrows;
  double& cellsize = h->cellsize;
  size_t ncols_line = 0, nrows_line = 0;  // 0: not given
  size_t cellsize_line = 0;               // 0: no cellsize
  // GDAL's DX and DY (its cell width and height, written for cells that are not square).
  double dx = -1, dy = -1;
  size_t dx_line = 0, dy_line = 0;                   // 0: not given
  std::vector<std::pair<std::string, size_t>> seen;  // header keys (lower case) and their lines
  for (;;) {
    const TokenReader before = *reader;
    if (!reader->Next(&key)) {
      if (ended) *ended = true;
      return Fail(path, "truncated: the grid header has no data", error);
    }
    const size_t line = reader->line();
    if (key[0] == '#') return CommentInGrid(path, line, error);
    double number;
    if (ParseFiniteDecimal(key, &number) || IsValueText(key)) {
      *reader = before;  // the first data value
      break;
    }
    // The value on the key's own line: a key alone is not given the first data value. Only
    // NODATA_value may be NaN (GDAL and R's terra write NaN for float grids).
    const bool value_on_line = reader->Next(&value) && reader->line() == line;
    const bool nan_nodata = value_on_line && Lower(key) == "nodata_value" && IsNanText(value);
    if (nan_nodata) {
      number = NAN;
    } else if (!value_on_line) {
      return Fail(path + ":" + std::to_string(line),
                  "header '" + ShownText(key) + "' needs a number on its line", error);
    } else if (!ParseFiniteDecimal(value, &number)) {
      // (Said to need a number, with one there: "NODATA_value 1.#INF".)
      return Fail(
          path + ":" + std::to_string(line),
          "header '" + ShownText(key) + "': '" + ShownText(value) + "' is not a finite number" +
              NotFiniteNote(value) + CommaNote(value) +
              (Lower(key) == "nodata_value" ? " (NODATA_value may be a number or NaN)" : ""),
          error);
    }
    // One value a line: more after it ("cellsize 1 7 8") were read as the grid's first row.
    TokenReader after = *reader;
    if (after.Skip() && after.line() == line) {
      if (after.first() == '#') return CommentInGrid(path, line, error);
      return Fail(path + ":" + std::to_string(line),
                  "header '" + ShownText(key) +
                      "' has more than one value on its line (expected one KEY VALUE pair a "
                      "line, the grid's values after the header)",
                  error);
    }
    const std::string k = Lower(key);
    for (const auto& [earlier, at] : seen) {
      if (earlier == k) {
        return Fail(path + ":" + std::to_string(line),
                    "header '" + ShownText(key) + "' given again (first on line " +
                        std::to_string(at) + ")",
                    error);
      }
    }
    seen.emplace_back(k, line);
    if (k == "ncols") {
      ncols = number, h->size_line = ncols_line = line;
    } else if (k == "nrows") {
      nrows = number, h->size_line = nrows_line = line;
    } else if (k == "cellsize") {
      cellsize = number, cellsize_line = line;
    } else if (k == "nodata_value") {
      h->nodata = number, h->has_nodata = true, h->nodata_is_nan = nan_nodata;
    } else if (k == "dx") {
      dx = number, dx_line = line;
    } else if (k == "dy") {
      dy = number, dy_line = line;
    } else if (k != "xllcorner" && k != "yllcorner" && k != "xllcenter" && k != "yllcenter") {
      return Fail(path + ":" + std::to_string(line),
                  "unknown header '" + ShownText(key) +
                      "' (expected ncols, nrows, xllcorner, yllcorner, cellsize, NODATA_value; or "
                      "DX and DY for "
                      "cellsize)",
                  error);
    }
  }
  // A count given but not a whole number >= 1 is named at its line; a missing one in the file.
  auto bad_count = [](double n) { return !(n >= 1 && n == std::floor(n)); };
  for (const auto& [count, at, name] :
       {std::make_tuple(ncols, ncols_line, "ncols"), std::make_tuple(nrows, nrows_line, "nrows")}) {
    if (at != 0 && bad_count(count)) {
      return Fail(path + ":" + std::to_string(at),
                  std::string(name) + " " + NumberText(count) + " (expected a whole number >= 1)",
                  error);
    }
  }
  if (ncols_line == 0 || nrows_line == 0) {
    return Fail(path,
                std::string("header needs ") + (ncols_line == 0 ? "ncols" : "nrows") +
                    " (a whole number >= 1)",
                error);
  }
  if (cell_size_given) {  // the caller's own: cellsize, DX and DY as they are
    cellsize = 0;
    return Status::kOk;
  }
  if (dx_line != 0 || dy_line != 0) {
    const size_t at = std::max(dx_line, dy_line);
    const char* why = cellsize_line != 0             ? "cellsize and DX/DY both given"
                      : dx_line == 0 || dy_line == 0 ? "DX and DY come together"
                      : dx != dy                     ? "DX and DY differ"
                                                     : nullptr;
    if (why) {
      return Fail(path + ":" + std::to_string(at),
                  std::string(why) +
                      " (expected cellsize, or DX and DY equal: cells that are not square are "
                      "not read; resample the grid to square cells, for example with gdalwarp "
                      "-tr; or give a cell size of your own, --cell-size)",
                  error);
    }
    cellsize = dx, cellsize_line = dx_line;
  }
  if (cellsize_line == 0) {
    return Fail(path, "header needs cellsize (a number > 0; or give one, --cell-size)", error);
  }
  if (!(cellsize > 0)) {
    return Fail(path + ":" + std::to_string(cellsize_line),
                "cellsize " + NumberText(cellsize) +
                    " (expected a number > 0; or give a cell size of your own, --cell-size)",
                error);
  }
  return Status::kOk;
}

// "R values (N rows of C)" for a header's grid.
std::string AscDeclared(const AscHeader& h) {
  return Count(h.ncols * h.nrows) + " values (" + Count(h.nrows) + " rows of " + Count(h.ncols) +
         ")";
}

}  // namespace

size_t HeightMap::ValidCount() const {
  return static_cast<size_t>(std::count(valid.begin(), valid.end(), uint8_t{1}));
}

Status ReadAscGrid(const std::string& path, HeightMap* out, std::string* error,
                   bool cell_size_given) {
  *out = HeightMap{};
  std::string text;
  auto header_word = [](const std::string& word) {
    return !word.empty() && std::isalpha(static_cast<unsigned char>(word[0])) != 0;
  };
  // The header alone first: a grid too large is refused before the file is read whole.
  auto header_ok = [&](const std::string& head, double size) {
    TokenReader reader(head, false);
    AscHeader h;
    bool ended = false;
    Status status = ParseAscHeader(path, &reader, cell_size_given, &h, error, &ended);
    if (ended) return Status::kOk;  // a header longer than the head: judged whole
    if (status != Status::kOk) return status;
    status = CheckGridSize(path, path + ":" + std::to_string(h.size_line), h.ncols * h.nrows,
                           AscDeclared(h), kMaxHeightMapCells + 1, 0, error);
    if (status != Status::kOk) return status;
    return CheckFileSize(path, size, h.ncols * h.nrows, kMostBytesPerTextValue, AscDeclared(h),
                         error);
  };
  Status status = ReadWhole(path, &text, error, header_word,
                            "the grid header's first key ('ncols N')", header_ok);
  if (status != Status::kOk) return status;
  TokenReader reader(text, false);
  AscHeader h;
  status = ParseAscHeader(path, &reader, cell_size_given, &h, error);
  if (status != Status::kOk) return status;
  const double ncols = h.ncols, nrows = h.nrows;
  std::string value;
  const double cells = ncols * nrows;
  if (ncols <= static_cast<double>(kMaxHeightMapCells) &&
      nrows <= static_cast<double>(kMaxHeightMapCells)) {
    status =
        CheckAscRows(path, reader, static_cast<size_t>(ncols), static_cast<size_t>(nrows), error);
    if (status != Status::kOk) return status;
  }
  size_t last_line;
  const size_t present = CountValues(reader, cells, &last_line);
  if (static_cast<double>(present) < cells) {
    // Fewer values than declared because some are not values: the first is named (rows of
    // "1,2,3,4" were said to be truncated).
    TokenReader scan = reader;
    for (size_t i = 0; i < present && scan.Next(&value); ++i) {
      double v;
      if (!(h.nodata_is_nan && IsNanText(value)) && !ParseFiniteDecimal(value, &v))
        return Fail(path + ":" + std::to_string(scan.line()), NotAValue(value), error);
    }
  }
  status = CheckGridSize(path, path + ":" + std::to_string(h.size_line), cells, AscDeclared(h),
                         present, last_line, error);
  if (status != Status::kOk) return status;
  out->cols = static_cast<int>(ncols), out->rows = static_cast<int>(nrows);
  out->cell_size = h.cellsize;
  const size_t total = static_cast<size_t>(out->cols) * out->rows;
  out->heights.resize(total);
  out->valid.resize(total);
  for (size_t i = 0; i < total; ++i) {
    if (!reader.Next(&value)) {
      return Fail(path,
                  "truncated: expected " + std::to_string(total) + " values (" +
                      std::to_string(out->rows) + " rows of " + std::to_string(out->cols) +
                      "), found " + std::to_string(i),
                  error);
    }
    double height;
    if (h.nodata_is_nan && IsNanText(value)) {
      out->heights[i] = 0, out->valid[i] = 0;
      continue;
    }
    if (!ParseFiniteDecimal(value, &height))
      return Fail(path + ":" + std::to_string(reader.line()), NotAValue(value), error);
    out->heights[i] = height;
    out->valid[i] = !(h.has_nodata && height == h.nodata);
    if (out->valid[i] && std::fabs(height) > terrain::kMaxCoordinate) {
      return Fail(path + ":" + std::to_string(reader.line()),
                  "value " + ShownText(value) + " is out of range (expected |height| <= " +
                      Number(terrain::kMaxCoordinate) + ")",
                  error);
    }
  }
  if (reader.Next(&value)) {
    if (value[0] == '#') return CommentInGrid(path, reader.line(), error);
    // The first one past them named: an invisible byte (a DOS end-of-file mark, a NUL, a
    // no-break space) read as a value left the user counting the values shown.
    return Fail(path + ":" + std::to_string(reader.line()),
                "more than the " + std::to_string(total) + " values the header declares: '" +
                    ShownText(value) + "'" + HiddenBytesNote(value) + " follows them",
                error);
  }
  return Status::kOk;
}

namespace {

// Reads a PGM header from `reader`: the magic ("P5" or "P2"), then width, height and maxval
// (fields[0..2]); *size_line is the height's line.
Status ParsePgmHeader(const std::string& path, TokenReader* reader, std::string* magic,
                      double fields[3], size_t* size_line, std::string* error) {
  std::string token;
  reader->Next(magic);
  if (*magic != "P5" && *magic != "P2") {
    return Fail(path + ":1", "expected the PGM magic 'P5' (binary) or 'P2' (ASCII)", error);
  }
  const char* names[3] = {"width", "height", "maxval"};
  for (int i = 0; i < 3; ++i) {
    if (!reader->Next(&token) || !ParseFiniteDecimal(token, &fields[i]) || fields[i] < 1 ||
        fields[i] != std::floor(fields[i])) {
      return Fail(path + ":" + std::to_string(reader->line()),
                  std::string("expected the PGM ") + names[i] + " as a whole number >= 1", error);
    }
    if (i == 1) *size_line = reader->line();
  }
  if (fields[2] > 65535) {
    return Fail(path + ":" + std::to_string(reader->line()), "PGM maxval above 65535", error);
  }
  return Status::kOk;
}

// "W x H pixels" (P5), "N grey levels (W x H pixels)" (P2).
std::string PgmDeclared(const std::string& magic, const double fields[3]) {
  const std::string pixels = Count(fields[0]) + " x " + Count(fields[1]) + " pixels";
  return magic == "P5" ? pixels : Count(fields[0] * fields[1]) + " grey levels (" + pixels + ")";
}

}  // namespace

Status ReadPgm(const std::string& path, HeightMap* out, std::string* error) {
  *out = HeightMap{};
  std::string text;
  auto magic_word = [](const std::string& word) {
    return word.compare(0, 2, "P5") == 0 || word.compare(0, 2, "P2") == 0;
  };
  // The header alone first: an image too large is refused before the file is read whole (a
  // header the head does not hold whole is judged once it is).
  auto header_ok = [&](const std::string& head, double size) {
    TokenReader reader(head, true);
    std::string magic;
    double fields[3];
    size_t size_line = 1;
    if (ParsePgmHeader(path, &reader, &magic, fields, &size_line, nullptr) != Status::kOk)
      return Status::kOk;
    const Status status =
        CheckGridSize(path, path + ":" + std::to_string(size_line), fields[0] * fields[1],
                      PgmDeclared(magic, fields), kMaxHeightMapCells + 1, 0, error);
    if (status != Status::kOk) return status;
    const double per_value = magic == "P5" ? (fields[2] < 256 ? 1 : 2) : kMostBytesPerTextValue;
    return CheckFileSize(path, size, fields[0] * fields[1], per_value, PgmDeclared(magic, fields),
                         error);
  };
  Status status = ReadWhole(path, &text, error, magic_word,
                            "the PGM magic 'P5' (binary) or 'P2' (ASCII)", header_ok);
  if (status != Status::kOk) return status;
  TokenReader reader(text, true);
  std::string magic, token;
  double fields[3];
  size_t size_line = 1;
  status = ParsePgmHeader(path, &reader, &magic, fields, &size_line, error);
  if (status != Status::kOk) return status;
  const double cells = fields[0] * fields[1];
  const std::string header = path + ":" + std::to_string(size_line);
  const size_t bytes = fields[2] < 256 ? 1 : 2;  // per P5 pixel
  const size_t start = reader.pos() + 1;         // P5: exactly one whitespace byte after maxval
  if (magic == "P5") {
    const size_t available = text.size() > start ? text.size() - start : 0;
    const std::string declared = PgmDeclared(magic, fields);
    if (static_cast<double>(available) < cells * bytes) {
      return Fail(path,
                  "truncated: " + declared + " of " + std::to_string(bytes) + " bytes need " +
                      Count(cells * bytes) + " bytes of data, the file has " +
                      std::to_string(available),
                  error);
    }
    status = CheckGridSize(path, header, cells, declared, available / bytes, 0, error);
    if (status != Status::kOk) return status;
    // Bytes after the pixels: a header written with CR LF line ends (its LF read as the first
    // pixel, the image shifted by a byte), or a second image; a line break alone is read past.
    const size_t data = static_cast<size_t>(cells) * bytes;
    if (available > data) {
      if (text[start - 1] == '\r' && text[start] == '\n') {
        return Fail(path + ":" + std::to_string(reader.line()),
                    "the maxval is followed by CR LF, and the file holds one byte more than the "
                    "pixels: a P5 header has exactly one white-space byte after the maxval, so "
                    "the LF would be read as the first pixel (save the header with LF line ends)",
                    error);
      }
      const size_t extra = available - data;
      if (text.find_first_not_of(" \t\r\n", start + data) != std::string::npos) {
        return Fail(path,
                    std::to_string(extra) + " bytes after the " + declared + "' " +
                        std::to_string(data) +
                        " bytes of data (expected the end of the file: one image per file)",
                    error);
      }
    }
  } else {
    size_t last_line;
    const size_t present = CountValues(reader, cells, &last_line);
    status =
        CheckGridSize(path, header, cells, PgmDeclared(magic, fields), present, last_line, error);
  }
  if (status != Status::kOk) return status;
  out->cols = static_cast<int>(fields[0]), out->rows = static_cast<int>(fields[1]);
  out->cell_size = 1;
  const size_t total = static_cast<size_t>(out->cols) * out->rows;
  out->heights.resize(total);
  out->valid.assign(total, 1);
  if (magic == "P5") {
    const auto* data = reinterpret_cast<const unsigned char*>(text.data() + start);
    for (size_t i = 0; i < total; ++i) {
      const int grey = bytes == 1 ? data[i] : (data[2 * i] << 8 | data[2 * i + 1]);
      if (grey > fields[2]) {
        return Fail(path,
                    "pixel " + std::to_string(i) + " (row " + std::to_string(i / out->cols) +
                        ", column " + std::to_string(i % out->cols) + ", byte " +
                        std::to_string(start + i * bytes) + ") is " + std::to_string(grey) +
                        ", above the maxval " + std::to_string(static_cast<int>(fields[2])),
                    error);
      }
      out->heights[i] = grey;
    }
    return Status::kOk;
  }
  for (size_t i = 0; i < total; ++i) {
    double h;
    if (!reader.Next(&token)) {
      return Fail(path,
                  "truncated: expected " + std::to_string(total) + " grey levels, found " +
                      std::to_string(i),
                  error);
    }
    if (!ParseFiniteDecimal(token, &h) || h < 0 || h > fields[2] || h != std::floor(h)) {
      return Fail(path + ":" + std::to_string(reader.line()),
                  "grey level '" + ShownText(token) + "' is not a whole number from 0 to maxval",
                  error);
    }
    out->heights[i] = h;
  }
  if (reader.Next(&token)) {
    return Fail(path + ":" + std::to_string(reader.line()),
                "more than the " + std::to_string(total) + " grey levels the header declares",
                error);
  }
  return Status::kOk;
}

Status HeightMapToMesh(const HeightMap& map, const HeightMapFrame& frame, TriangleMesh* out,
                       std::string* error) {
  out->vertices.clear(), out->triangles.clear();
  if (!(std::isfinite(frame.cell_size) && frame.cell_size > 0) ||
      !std::isfinite(frame.height_scale) ||
      (frame.up_axis != 'x' && frame.up_axis != 'y' && frame.up_axis != 'z')) {
    if (error) {
      *error = "height map frame needs cell size > 0, a finite height scale and up axis x, y or z";
    }
    return Status::kInvalidArgument;
  }
  const double extent = std::max(map.cols - 1, map.rows - 1) * frame.cell_size;
  if (extent > terrain::kMaxCoordinate) {
    if (error) {
      *error = "the grid spans " + Number(extent) + " (" + std::to_string(map.cols) + " x " +
               std::to_string(map.rows) + " cells of " + Number(frame.cell_size) +
               "), out of range (expected at most " + Number(terrain::kMaxCoordinate) + ")";
    }
    return Status::kInvalidArgument;
  }
  for (size_t i = 0; i < map.heights.size(); ++i) {
    const double h = map.heights[i] * frame.height_scale;
    if (map.valid[i] && !(std::fabs(h) <= terrain::kMaxCoordinate)) {
      if (error) {
        *error = "cell (row " + std::to_string(i / map.cols) + ", column " +
                 std::to_string(i % map.cols) + "): height " + Number(map.heights[i]) + " x " +
                 Number(frame.height_scale) +
                 " is out of range (expected |height| <= " + Number(terrain::kMaxCoordinate) + ")";
      }
      return Status::kInvalidArgument;
    }
  }
  const uint32_t kNone = 0xffffffffu;
  std::vector<uint32_t> vertex(map.heights.size(), kNone);
  for (int r = 0; r < map.rows; ++r) {
    for (int c = 0; c < map.cols; ++c) {
      const size_t i = static_cast<size_t>(r) * map.cols + c;
      if (!map.valid[i]) continue;
      const double east = c * frame.cell_size, south = r * frame.cell_size;
      const double h = map.heights[i] * frame.height_scale;
      vertex[i] = static_cast<uint32_t>(out->vertices.size());
      if (frame.up_axis == 'y') out->vertices.push_back({east, h, south});
      if (frame.up_axis == 'z') out->vertices.push_back({east, -south, h});
      if (frame.up_axis == 'x') out->vertices.push_back({h, east, -south});
    }
  }
  Vec3 up;
  (frame.up_axis == 'x' ? up.x : frame.up_axis == 'y' ? up.y : up.z) = 1;
  auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
    if (a == kNone || b == kNone || c == kNone) return;
    const Vec3 n = Cross(out->vertices[b] - out->vertices[a], out->vertices[c] - out->vertices[a]);
    if (Dot(n, up) < 0) std::swap(b, c);
    out->triangles.push_back({a, b, c});
  };
  for (int r = 0; r + 1 < map.rows; ++r) {
    for (int c = 0; c + 1 < map.cols; ++c) {
      const size_t i = static_cast<size_t>(r) * map.cols + c;
      const uint32_t nw = vertex[i], ne = vertex[i + 1], sw = vertex[i + map.cols],
                     se = vertex[i + map.cols + 1];
      const int valid = (nw != kNone) + (ne != kNone) + (sw != kNone) + (se != kNone);
      if (valid == 4) {
        add(nw, sw, ne), add(ne, sw, se);
      } else if (valid == 3) {
        uint32_t corner[4] = {nw, ne, se, sw}, kept[3], k = 0;
        for (uint32_t v : corner) {
          if (v != kNone) kept[k++] = v;
        }
        add(kept[0], kept[1], kept[2]);
      }
    }
  }
  return Status::kOk;
}

}  // namespace footfall
