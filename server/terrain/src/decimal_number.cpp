#include "footfall/terrain/decimal_number.h"

#include <charconv>
#include <cmath>
#include <system_error>

namespace footfall {
namespace {

// For a number out of a double's range: true when it is too small (a negative exponent, or no
// exponent and no whole part, as 0.000...1), false when too large.
bool Underflows(std::string_view number) {
  const size_t e = number.find_first_of("eE");
  if (e != std::string_view::npos) return e + 1 < number.size() && number[e + 1] == '-';
  if (!number.empty() && (number[0] == '-' || number[0] == '+')) number.remove_prefix(1);
  return number.substr(0, 2) == "0." || number.substr(0, 1) == ".";
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

}  // namespace footfall
