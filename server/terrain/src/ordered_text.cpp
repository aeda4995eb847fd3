#include "footfall/terrain/ordered_text.h"

#include <algorithm>
#include <exception>
#include <new>
#include <system_error>
#include <thread>
#include <vector>

namespace footfall {

bool FormatInOrder(size_t count, int threads,
                   const std::function<void(size_t piece, std::string* text)>& format,
                   const std::function<bool(std::string_view text)>& sink) {
  size_t parallel =
      threads > 0 ? static_cast<size_t>(threads) : std::thread::hardware_concurrency();
  parallel = std::clamp<size_t>(parallel, 1, 16);
  parallel = std::min(parallel, std::max<size_t>(count, 1));
  // Each thread's text on cache lines of its own: a string's size changes with every append
  // (side by side, two threads' strings made two threads 1.5x slower than one).
  struct alignas(64) Text {
    std::string text;
  };
  std::vector<Text> texts(parallel);
  std::vector<std::thread> helpers;
  std::vector<std::exception_ptr> failed(parallel);
  for (size_t first = 0; first < count; first += parallel) {
    const size_t group = std::min(parallel, count - first);
    auto run = [&](size_t k) {
      try {
        texts[k].text.clear();
        format(first + k, &texts[k].text);
      } catch (...) {
        failed[k] = std::current_exception();
      }
    };
    helpers.clear();
    // Parts no thread could be started for (a memory or process limit) run on this one.
    size_t started = 1;
    try {
      for (; started < group; ++started) helpers.emplace_back(run, started);
    } catch (const std::system_error&) {
    } catch (const std::bad_alloc&) {
    }
    run(0);
    for (size_t k = started; k < group; ++k) run(k);
    for (std::thread& h : helpers) h.join();
    // An exception (std::bad_alloc) reaches the caller once every thread has ended.
    for (std::exception_ptr& e : failed)
      if (e) std::rethrow_exception(e);
    for (size_t k = 0; k < group; ++k)
      if (!sink(texts[k].text)) return false;
  }
  return true;
}

}  // namespace footfall
