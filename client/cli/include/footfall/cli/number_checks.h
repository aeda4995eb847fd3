// CLI11 checks for the floating-point flags of every `footfall` command: each refuses NaN,
// infinities and text that is not a number, and names its bounds as plain numbers ("0 to 1e+06",
// not CLI11's 309-digit limits of double).
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

}  // namespace footfall::cli
