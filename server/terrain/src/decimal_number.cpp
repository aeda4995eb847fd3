#include "footfall/terrain/decimal_number.h"

#include "footfall/terrain/ascii.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <system_error>

namespace footfall {
namespace {

// For a number out of a double's range: true when it is too small, false when too large. Its
// decimal magnitude (the power of ten of its first non-zero digit: -3 for "0.00125e0", 2 for
// "00125") is below -300 or above 300 then, so its sign decides ("00.000...1" and
// "0.000...1e+5" are too small, "0.1e400" too large).
bool Underflows(std::string_view number) {
  if (!number.empty() && (number[0] == '-' || number[0] == '+')) number.remove_prefix(1);
  const size_t e = number.find_first_of("eE");
  const std::string_view mantissa = number.substr(0, e);
  const size_t point = std::min(mantissa.find('.'), mantissa.size());
  const size_t first = mantissa.find_first_of("123456789");
  if (first == std::string_view::npos) return true;  // zero
  long long magnitude = first < point ? static_cast<long long>(point - first) - 1
                                      : -static_cast<long long>(first - point);
  if (e != std::string_view::npos) {
    std::string_view exponent = number.substr(e + 1);
    const bool negative = !exponent.empty() && exponent[0] == '-';
    if (!exponent.empty() && (exponent[0] == '-' || exponent[0] == '+')) exponent.remove_prefix(1);
    long long value = 0;  // saturated: 1e9 is as far beyond range as any larger exponent
    for (char c : exponent) value = std::min<long long>(value * 10 + (c - '0'), 1000000000);
    magnitude += negative ? -value : value;
  }
  return magnitude < 0;
}

}  // namespace

DecimalRead ReadDecimal(std::string_view token, double* value) {
  const char* first = token.data();
  const char* last = first + token.size();
  // from_chars refuses a leading '+' (but reads "+-1" as -1 once it is skipped).
  if (first != last && *first == '+' && token.size() > 1 && first[1] != '-') ++first;
  double v = 0;
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if (ptr != last || first == last) return DecimalRead::kNotANumber;
  if (ec == std::errc::result_out_of_range) {
    if (!Underflows(token)) return DecimalRead::kTooLarge;
    v = token[0] == '-' ? -0.0 : 0.0;
  } else if (ec != std::errc()) {
    return DecimalRead::kNotANumber;
  }
  *value = v;
  return DecimalRead::kNumber;
}

bool ParseFiniteDecimal(std::string_view token, double* value) {
  double v = 0;
  if (ReadDecimal(token, &v) != DecimalRead::kNumber || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

std::string WholeNumberProblem(std::string_view token, long long lo, long long hi) {
  if (!token.empty() && token.size() <= 18 &&
      token.find_first_not_of("0123456789") == std::string_view::npos) {
    long long v = 0;
    std::from_chars(token.data(), token.data() + token.size(), v);
    if (v >= lo && v <= hi) return std::string();
  }
  return "'" + std::string(token) + "' is not a whole number from " + std::to_string(lo) + " to " +
         std::to_string(hi);
}

std::string WithoutLeadingZeros(std::string_view token) {
  if (token.empty() || token.find_first_not_of("0123456789") != std::string_view::npos)
    return std::string(token);
  const size_t first = token.find_first_not_of('0');
  return std::string(token.substr(first == std::string_view::npos ? token.size() - 1 : first));
}

bool IsMicrosoftNonFinite(std::string_view token) {
  size_t i = 0;
  auto digits = [&] {
    const size_t from = i;
    while (i < token.size() && std::isdigit(static_cast<unsigned char>(token[i]))) ++i;
    return i > from;
  };
  if (i < token.size() && (token[i] == '+' || token[i] == '-')) ++i;
  if (!digits()) return false;
  const bool point = i < token.size() && token[i] == '.';
  if (point) ++i, digits();
  if (i >= token.size() || token[i++] != '#') return false;
  // Printed with few digits the word itself is rounded ("1.#J", "1.#IO", "1.#R", "1.#QO",
  // "1.#"): after "DIGITS.#", up to four letters and digits are taken for one.
  if (point && token.size() - i <= 4 && std::all_of(token.begin() + i, token.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c));
      }))
    return true;
  size_t word = 0;
  for (const char* name : {"QNAN", "SNAN", "IND", "INF"}) {
    const size_t n = std::strlen(name);
    if (token.size() - i >= n && std::equal(name, name + n, token.begin() + i,
                                            [](char a, char b) { return a == AsciiUpper(b); })) {
      word = n;
      break;
    }
  }
  if (word == 0) return false;
  i += word;
  digits();
  if (i < token.size() && (token[i] == 'e' || token[i] == 'E')) {
    ++i;
    if (i < token.size() && (token[i] == '+' || token[i] == '-')) ++i;
    if (!digits()) return false;
  }
  return i == token.size();
}

std::string NotFiniteNote(std::string_view token) {
  return IsMicrosoftNonFinite(token) ? " (Microsoft C's NaN or infinity)" : "";
}

std::string CommaNote(std::string_view token) {
  const size_t comma = token.find(',');
  if (comma == std::string_view::npos) return "";
  std::string point(token);
  point[comma] = '.';
  double value = 0;
  return point.find(',') == std::string::npos && ParseFiniteDecimal(point, &value)
             ? " (a decimal comma: write a decimal point, as in 1.5)"
             : " (values are separated by spaces or tabs, not commas)";
}

size_t CommentStart(std::string_view line) {
  for (size_t at = line.find('#'); at != std::string_view::npos; at = line.find('#', at + 1)) {
    const size_t begin = line.find_last_of(" \t\r\n\f\v", at);
    const size_t start = begin == std::string_view::npos ? 0 : begin + 1;
    const size_t end = std::min(line.find_first_of(" \t\r\n\f\v", at), line.size());
    if (start == at || !IsMicrosoftNonFinite(line.substr(start, end - start))) return at;
    at = end == 0 ? at : end - 1;
  }
  return std::string_view::npos;
}

bool IsMicrosoftNaN(std::string_view token) {
  if (!IsMicrosoftNonFinite(token)) return false;
  // Spelled out after the '#': QNAN, SNAN or IND (a rounded word tells nothing).
  std::string word;
  for (size_t i = token.find('#') + 1; i < token.size() && word.size() < 4; ++i)
    word += AsciiUpper(token[i]);
  return word == "QNAN" || word == "SNAN" || word.compare(0, 3, "IND") == 0;
}

}  // namespace footfall
