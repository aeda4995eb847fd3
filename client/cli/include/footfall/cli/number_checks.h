// CLI11 checks for the flags of every `footfall` command and of footfall-view. The number checks
// refuse NaN, infinities and text that is not a number, and name their bounds as plain numbers
// ("0 to 1e+06", not CLI11's 309-digit limits of double).
#pragma once

#include <CLI/CLI.hpp>

namespace footfall::cli {

// Any finite number.
CLI::Validator Finite();
// A finite number >= lo.
CLI::Validator FiniteAtLeast(double lo);
// A finite number > lo.
CLI::Validator FiniteAbove(double lo);
// A finite number in [lo, hi].
CLI::Validator FiniteRange(double lo, double hi);
// A finite number in (lo, hi].
CLI::Validator FiniteAboveUpTo(double lo, double hi);
// The whole-number checks are transforms (Option::transform, not check): they drop the leading
// zeros of a number they accept, which CLI11 would read as octal ("010" as 8, "08" refused).
// A whole number from 0 to 2^64 - 1, written in decimal digits only (CLI11 alone read "-1" as
// 2^64 - 1 and clamped larger numbers to it).
CLI::Validator Seed();
// A whole number written in digits alone, from 0 to hi (hi < 10^18): "1.5", "-1" and "1e3" are
// refused as not whole numbers, where a range check alone said "not in range".
CLI::Validator WholeUpTo(long long hi);
// A whole number written in digits alone, from lo to hi (0 <= lo <= hi < 10^18), refused as
// "'1.5' is not a whole number from LO to HI" (CLI11's range check said "not in range", and its
// integer conversion "Could not convert").
CLI::Validator WholeRange(long long lo, long long hi);
// Text that is not empty or blank ("expected EXPECTED" otherwise): a flag given an unset shell
// variable.
CLI::Validator NotBlank(const std::string& expected);

}  // namespace footfall::cli
