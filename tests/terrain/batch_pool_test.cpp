// The batch threads (footfall/terrain/batch_pool.h): every query of a batch answered
// exactly once whatever the threads and chunk sizes, exceptions carried back to the caller, the
// pool still serving after one, a pool shared by callers on several threads, and batches run
// from inside a batch.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/terrain/batch_pool.h"

using footfall::BatchPool;
using footfall::SharedBatchPool;

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

TEST_CASE("a shared pool serves callers on several threads at once", "[pool]") {
  CHECK(SharedBatchPool(1) == nullptr);
  const std::shared_ptr<BatchPool> pool = SharedBatchPool(2);
  REQUIRE(pool != nullptr);
  CHECK(SharedBatchPool(2) == pool);  // one pool per thread count while it is held
  CHECK(SharedBatchPool(3) != pool);
  // Three callers, each running batches on the same pool: a caller that finds the pool busy runs
  // its batch on its own thread. Every item of every batch is answered exactly once.
  std::atomic<size_t> wrong{0};
  std::vector<std::thread> callers;
  for (int t = 0; t < 3; ++t) {
    callers.emplace_back([&pool, &wrong, t] {
      for (int round = 0; round < 300; ++round) {
        const size_t count = 100 + static_cast<size_t>((round * 37 + t * 11) % 900);
        std::vector<std::atomic<int>> hits(count);
        for (auto& h : hits) h = 0;
        pool->Run(count, 16, [&](size_t b, size_t e) {
          for (size_t i = b; i < e; ++i) ++hits[i];
        });
        for (auto& h : hits) wrong += h.load() != 1;
      }
    });
  }
  for (auto& c : callers) c.join();
  CHECK(wrong.load() == 0);
}

TEST_CASE("a batch run from inside a batch runs on the thread that asks", "[pool]") {
  // Each outer item runs a whole inner batch on the same pool (a generator's pass asking the
  // embedded engine): the inner batch is one call on the asking thread, whichever thread
  // (caller or worker) that is, and every inner item is answered exactly once.
  BatchPool pool(2, 100, 200);
  for (int round = 0; round < 50; ++round) {
    constexpr size_t kOuter = 4, kInner = 500;
    std::vector<std::atomic<int>> hits(kOuter * kInner);
    for (auto& h : hits) h = 0;
    std::atomic<size_t> inner_calls{0}, off_thread{0};
    pool.Run(kOuter, 1, [&](size_t b, size_t e) {
      for (size_t o = b; o < e; ++o) {
        const std::thread::id asking = std::this_thread::get_id();
        pool.Run(kInner, 16, [&](size_t ib, size_t ie) {
          ++inner_calls;
          off_thread += std::this_thread::get_id() != asking;
          for (size_t i = ib; i < ie; ++i) ++hits[o * kInner + i];
        });
      }
    });
    size_t wrong = 0;
    for (auto& h : hits) wrong += h.load() != 1;
    REQUIRE(wrong == 0);
    REQUIRE(inner_calls.load() == kOuter);
    REQUIRE(off_thread.load() == 0);
  }
}

TEST_CASE("a pool whose threads cannot all start serves on those that did", "[pool]") {
  // Under a memory limit (ulimit -v) the workers' stacks ran out, and the half-made pool ended
  // the process (std::terminate), whatever the caller caught. Tried in a child process with
  // little address space left: 64 workers of 8 MiB stacks cannot all start.
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    rlimit limit{};
    getrlimit(RLIMIT_AS, &limit);
    std::ifstream status("/proc/self/statm");
    size_t pages = 0;
    status >> pages;
    limit.rlim_cur = pages * static_cast<size_t>(sysconf(_SC_PAGESIZE)) + (64u << 20);
    if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(3);
    int code = 0;
    {
      BatchPool pool(64);
      std::vector<int> seen(10000, 0);
      pool.Run(seen.size(), 16, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) ++seen[i];
      });
      for (const int n : seen)
        if (n != 1) code = 2;
    }
    _exit(code);
  }
  int status = 0;
  REQUIRE(waitpid(child, &status, 0) == child);
  INFO("child status " << status);
  REQUIRE(WIFEXITED(status));  // not ended by a signal (SIGABRT)
  CHECK(WEXITSTATUS(status) == 0);
}
