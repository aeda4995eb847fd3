#include "footfall/cli/number_checks.h"

#include <string>

#include "footfall/client/query_text.h"
#include "footfall/terrain/decimal_number.h"
#include "footfall/terrain/shown_text.h"
#include "footfall/terrain/text_stream.h"

namespace footfall::cli {
namespace {

std::string Text(double v) {
  TextStream out;
  out << v;
  return out.str();
}

// A validator accepting finite numbers x with ok(x); `expected` describes them.
template <typename Ok>
CLI::Validator Make(const std::string& expected, Ok ok) {
  return CLI::Validator(
      [expected, ok](std::string& input) -> std::string {
        double x;
        if (!ParseFiniteNumber(input, &x) || !ok(x))
          return "'" + ShownText(input) + "'" + HiddenBytesNote(input) + " is not " + expected;
        return "";
      },
      expected);
}

}  // namespace

CLI::Validator Finite() {
  return Make("a finite number", [](double) { return true; });
}

CLI::Validator FiniteAtLeast(double lo) {
  return Make("a finite number >= " + Text(lo), [lo](double x) { return x >= lo; });
}

CLI::Validator FiniteAbove(double lo) {
  return Make("a finite number > " + Text(lo), [lo](double x) { return x > lo; });
}

CLI::Validator FiniteRange(double lo, double hi) {
  return Make("a finite number from " + Text(lo) + " to " + Text(hi),
              [lo, hi](double x) { return x >= lo && x <= hi; });
}

CLI::Validator NotBlank(const std::string& expected) {
  return CLI::Validator(
      [expected](std::string& value) {
        return value.find_first_not_of(" \t") == std::string::npos ? "expected " + expected
                                                                   : std::string();
      },
      "");
}

CLI::Validator FiniteAboveUpTo(double lo, double hi) {
  return Make("a finite number > " + Text(lo) + " and <= " + Text(hi),
              [lo, hi](double x) { return x > lo && x <= hi; });
}

CLI::Validator Seed() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        const std::string digits = WithoutLeadingZeros(input);
        if (!digits.empty() && digits.size() <= 20 &&
            digits.find_first_not_of("0123456789") == std::string::npos &&
            (digits.size() < 20 || digits <= "18446744073709551615")) {
          input = digits;
          return std::string();
        }
        return "'" + input + "' is not a whole number from 0 to 18446744073709551615";
      },
      "SEED");
}

CLI::Validator WholeRange(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& input) {
        const std::string digits = WithoutLeadingZeros(input);
        if (!WholeNumberProblem(digits, lo, hi).empty()) return WholeNumberProblem(input, lo, hi);
        input = digits;
        return std::string();
      },
      "INT in [" + std::to_string(lo) + " - " + std::to_string(hi) + "]");
}

CLI::Validator WholeUpTo(long long hi) { return WholeRange(0, hi); }

}  // namespace footfall::cli
