// BatchPool: persistent threads that share a batch query with the thread that asks for it
// (footfalld's batch procedures, the embedded session's batches).
//
// The batch is cut into chunks that the caller and the workers take in turn, so a worker that
// wakes late (its core busy elsewhere) takes fewer chunks instead of holding the caller up, and
// no thread is created per batch. The caller polls for a short while for the workers' last
// chunks before it sleeps: being woken costs a wake-up latency on the critical path, a large
// part of a batch that is cheap to answer. Idle workers sleep at once by default (in footfalld,
// a polling worker would take the core the client needs between batches); in-process callers
// that ask batch after batch share one pool whose workers poll briefly first (SharedBatchPool).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace footfall {

class BatchPool {
 public:
  // `threads` counts the caller: threads - 1 workers are started (none for 1 or less).
  // [Units: us] `caller_spin_us`: how long Run polls for the workers' last chunks before it
  // sleeps.
  // Queries per chunk for batches of terrain queries (about 50 us of snaps).
  static constexpr size_t kQueryChunk = 128;

  // [Units: us] `worker_spin_us`: how long an idle worker polls for the next job before it
  // sleeps.
  explicit BatchPool(int threads, int caller_spin_us = 100, int worker_spin_us = 0);
  ~BatchPool();
  BatchPool(const BatchPool&) = delete;
  BatchPool& operator=(const BatchPool&) = delete;

  // Calls fn(begin, end) on disjoint ranges of `chunk` items (the last one shorter) covering
  // [0, count), on the calling thread and the workers, and returns when every call has
  // returned. Without workers, or for at most `chunk` items, makes one call fn(0, count) on the
  // caller. The first exception fn throws is rethrown here once all calls are over. Callers on
  // several threads may share a pool: while one Run is under way, another caller's Run makes
  // one call fn(0, count) on its own thread, as does a Run made from inside fn (nested).
  void Run(size_t count, size_t chunk, const std::function<void(size_t, size_t)>& fn);

 private:
  void Work();
  // Takes and runs chunks until none are left; `lock` is held on entry and on return.
  void Drain(std::unique_lock<std::mutex>& lock);
  // Polls `done` for up to `us` microseconds; true when it became true.
  template <typename Done>
  static bool Spin(int us, Done&& done);

  const int caller_spin_us_, worker_spin_us_;
  std::mutex run_mutex_;  // held by the Run under way
  std::mutex mutex_;
  std::condition_variable work_, done_;
  // The job, under mutex_; finished_ is also read without it while polling.
  const std::function<void(size_t, size_t)>* fn_ = nullptr;
  size_t count_ = 0, chunk_ = 1, next_ = 0;
  std::atomic<size_t> finished_{0};
  std::atomic<uint64_t> posted_{0};  // jobs posted so far (written under mutex_)
  bool stop_ = false;
  bool caller_sleeping_ = false;
  std::exception_ptr error_;
  std::vector<std::thread> workers_;
};

// The process's pool for `threads` threads, shared by every in-process caller that asks for it
// (embedded sessions, the step generator), so that they wake the same workers instead of
// keeping one set each; its workers poll 200 us for the next job before sleeping. Null for
// `threads` <= 1. The pool lives while someone holds it.
std::shared_ptr<BatchPool> SharedBatchPool(int threads);

}  // namespace footfall
