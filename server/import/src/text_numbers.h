// Numbers as text terrain files spell them, beyond what ParseFiniteDecimal reads: Microsoft C's
// NaN and infinity. Private to footfall::import.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace footfall::detail {

// Whether `token` is how Microsoft's C library writes NaN or infinity: "1.#QNAN", "-1.#IND",
// "1.#INF00", "1.#SNAN0e+000" (letters in either case). In text that takes '#' for a comment,
// the '#' of such a token starts none.
bool IsMicrosoftNonFinite(std::string_view token);
// " (Microsoft C's NaN or infinity)" for such a token, else "": for "is not a finite number".
std::string NotFiniteNote(std::string_view token);
// Where the '#' comment of `line` starts (npos for none): at its first '#' but those inside a
// token IsMicrosoftNonFinite accepts.
size_t CommentStart(std::string_view line);
// Whether `token` is one of those that spells NaN ("1.#QNAN", "-1.#IND", "1.#SNAN"), not infinity.
bool IsMicrosoftNaN(std::string_view token);

}  // namespace footfall::detail
