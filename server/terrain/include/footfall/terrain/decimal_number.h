// Decimal numbers in text terrain files and command-line flags, read alike in every locale
// (std::from_chars; strtod follows LC_NUMERIC, and reads hexadecimal).
#pragma once

#include <string>
#include <string_view>

namespace footfall {

enum class DecimalRead {
  kNumber,      // *value holds it (possibly infinite or NaN for "inf", "nan": check it)
  kNotANumber,  // not wholly a decimal number: hexadecimal, a second sign, trailing characters
  kTooLarge,    // a decimal number beyond a double's range
};

// Reads all of `token` as a decimal number: an optional sign ('+' or '-', one), digits with an
// optional point and exponent. A value too small for a double reads as zero of its sign.
DecimalRead ReadDecimal(std::string_view token, double* value);

// True when `token` is wholly a finite decimal number; *value is set only then.
bool ParseFiniteDecimal(std::string_view token, double* value);

// Checks that `token` is a whole number written in decimal digits alone, from lo to hi
// (0 <= lo <= hi < 10^18): "" when it is, else "'TOKEN' is not a whole number from LO to HI"
// ("1.5", "-1", "1e3" and "+5" are refused). The wording every count flag uses.
std::string WholeNumberProblem(std::string_view token, long long lo, long long hi);

}  // namespace footfall
