// FormatInOrder: pieces formatted on several threads come out in order, the same text on any
// number of threads; a refusing sink stops it, and an exception reaches the caller.
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

#include <catch2/catch.hpp>

#include "footfall/terrain/ordered_text.h"

using namespace footfall;

TEST_CASE("FormatInOrder hands the pieces over in order whatever the threads",
          "[terrain][ordered_text]") {
  // Pieces of uneven work (a later piece often done first), and a piece count that is not a
  // multiple of the threads.
  auto format = [](size_t i, std::string* text) {
    if (i % 3 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));
    *text += "piece " + std::to_string(i) + std::string(i % 5, '.') + "\n";
  };
  auto run = [&](int threads, size_t* calls) {
    std::string all;
    *calls = 0;
    CHECK(FormatInOrder(101, threads, format, [&](std::string_view t) {
      all += t;
      ++*calls;
      return true;
    }));
    return all;
  };
  std::string expected;
  for (size_t i = 0; i < 101; ++i) format(i, &expected);
  for (const int threads : {1, 2, 3, 8, 0}) {
    INFO(threads << " threads");
    size_t calls = 0;
    CHECK(run(threads, &calls) == expected);
    CHECK(calls == 101);
  }
  SECTION("a refusing sink stops it at once") {
    size_t calls = 0;
    CHECK_FALSE(FormatInOrder(101, 3, format, [&calls](std::string_view) { return ++calls < 5; }));
    CHECK(calls == 5);
  }
  SECTION("an exception thrown by a piece reaches the caller") {
    auto throwing = [](size_t i, std::string* text) {
      if (i == 7) throw std::runtime_error("piece 7");
      *text += "x";
    };
    CHECK_THROWS_WITH(FormatInOrder(20, 3, throwing, [](std::string_view) { return true; }),
                      "piece 7");
  }
  SECTION("no pieces: nothing handed over") {
    size_t calls = 0;
    CHECK(FormatInOrder(0, 2, format, [&calls](std::string_view) { return ++calls > 0; }));
    CHECK(calls == 0);
  }
}
