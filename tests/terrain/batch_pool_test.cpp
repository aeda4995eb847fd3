// The batch threads (footfall/terrain/batch_pool.h): every query of a batch answered
// exactly once whatever the threads and chunk sizes, exceptions carried back to the caller, and
// the pool still serving after one.
#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/terrain/batch_pool.h"

using footfall::BatchPool;

TEST_CASE("batch threads answer every item exactly once", "[pool]") {
  for (const int threads : {1, 2, 4}) {
    BatchPool pool(threads);
    for (const size_t count : {size_t{0}, size_t{1}, size_t{127}, size_t{128}, size_t{129},
                               size_t{1000}, size_t{4096}}) {
      for (const size_t chunk : {size_t{0}, size_t{1}, size_t{7}, size_t{128}, size_t{5000}}) {
        INFO(threads << " threads, " << count << " items, chunks of " << chunk);
        std::vector<std::atomic<int>> hits(count);
        for (auto& h : hits) h = 0;
        std::atomic<size_t> calls{0};
        pool.Run(count, chunk, [&](size_t b, size_t e) {
          ++calls;
          for (size_t i = b; i < e; ++i) ++hits[i];
        });
        size_t wrong = 0;
        for (auto& h : hits) wrong += h.load() != 1;
        REQUIRE(wrong == 0);
        const size_t c = std::max<size_t>(chunk, 1);
        const size_t expected = count == 0                   ? 0
                                : threads == 1 || count <= c ? 1
                                                             : (count + c - 1) / c;
        REQUIRE(calls.load() == expected);
      }
    }
  }
}

TEST_CASE("batch threads carry an exception back and keep serving", "[pool]") {
  BatchPool pool(2);
  for (int round = 0; round < 20; ++round) {
    std::atomic<size_t> done{0};
    const size_t bad = static_cast<size_t>(round) * 97 % 2048;
    REQUIRE_THROWS_AS(pool.Run(2048, 64,
                               [&](size_t b, size_t e) {
                                 done += e - b;
                                 if (b <= bad && bad < e) throw std::runtime_error("bad item");
                               }),
                      std::runtime_error);
    REQUIRE(done.load() == 2048);  // every chunk ran before Run returned
    std::atomic<size_t> after{0};
    pool.Run(1000, 10, [&](size_t b, size_t e) { after += e - b; });
    REQUIRE(after.load() == 1000);
  }
}
