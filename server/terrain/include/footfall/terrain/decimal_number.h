// Decimal numbers in text terrain files and command-line flags, read alike in every locale
// (std::from_chars; strtod follows LC_NUMERIC, and reads hexadecimal).
#pragma once

#include <cstddef>
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

// `token` without the leading zeros of a number written in decimal digits alone ("0" for zero);
// any other text as it is. For flags: CLI11 converts integers with strtoll in base 0, which read
// "010" as octal 8 and refused "08".
std::string WithoutLeadingZeros(std::string_view token);

// Whether `token` is how Microsoft's C library writes NaN or infinity: "1.#QNAN", "-1.#IND",
// "1.#INF00", "1.#SNAN0e+000" (letters in either case), or those words rounded at a low
// precision ("1.#J", "-1.#IO", "1.#R", "1.#QO", "1.#": "DIGITS.#" and up to four letters or
// digits). In text that takes '#' for a comment, the '#' of such a token starts none.
bool IsMicrosoftNonFinite(std::string_view token);
// Whether `token` is one of those that spells NaN ("1.#QNAN", "-1.#IND", "1.#SNAN"), not infinity.
bool IsMicrosoftNaN(std::string_view token);
// " (Microsoft C's NaN or infinity)" for such a token, else "": for "is not a finite number".
std::string NotFiniteNote(std::string_view token);
// For a token holding a comma: " (a decimal comma: write a decimal point, as in 1.5)" when it
// reads as a number written with one ("1,5", "-0,25e3"), else " (values are separated by
// spaces or tabs, not commas)"; "" for a token without a comma. For "is not a number".
std::string CommaNote(std::string_view token);
// Where the '#' comment of `line` starts (npos for none): at its first '#' but those inside a
// token IsMicrosoftNonFinite accepts.
size_t CommentStart(std::string_view line);

}  // namespace footfall
