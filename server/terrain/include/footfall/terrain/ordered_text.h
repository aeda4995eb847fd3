// Text written in numbered pieces, formatted on several threads at once and handed over in order
// (numbers to text is most of the work of writing a large point file or walk).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

namespace footfall {

// Calls format(i, &text) for each piece i in [0, count), with `text` empty, on up to `threads`
// threads at a time (0: one per core), and sink(text) for each piece in order, from the calling
// thread. The text is the same on any number of threads. Stops, returning false, as soon as sink
// returns false (pieces formatted meanwhile are dropped). An exception thrown by format is
// rethrown once every thread has ended.
bool FormatInOrder(size_t count, int threads,
                   const std::function<void(size_t piece, std::string* text)>& format,
                   const std::function<bool(std::string_view text)>& sink);

}  // namespace footfall
