// Decimal numbers in text terrain files, read alike in every locale (std::from_chars; strtod
// follows LC_NUMERIC, and reads hexadecimal).
#pragma once

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

}  // namespace footfall
