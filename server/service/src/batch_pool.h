// BatchPool: persistent threads that share a batch query with the thread that asks for it.
// Internal to footfall::service.
//
// The batch is cut into chunks that the caller and the workers take in turn, so a worker that
// wakes late (its core busy elsewhere) takes fewer chunks instead of holding the caller up, and
// no thread is created per batch.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace footfall {

class BatchPool {
 public:
  // `threads` counts the caller: threads - 1 workers are started (none for 1 or less).
  explicit BatchPool(int threads);
  ~BatchPool();
  BatchPool(const BatchPool&) = delete;
  BatchPool& operator=(const BatchPool&) = delete;

  // Calls fn(begin, end) on disjoint ranges of at most `chunk` items covering [0, count), on
  // the calling thread and the workers, and returns when every call has returned. Batches of
  // at most `chunk` items run on the caller alone. The first exception fn throws is rethrown
  // here once all calls are over. One Run at a time.
  void Run(size_t count, size_t chunk, const std::function<void(size_t, size_t)>& fn);

 private:
  void Work();
  // Takes and runs chunks until none are left; `lock` is held on entry and on return.
  void Drain(std::unique_lock<std::mutex>& lock);

  std::mutex mutex_;
  std::condition_variable work_, done_;
  const std::function<void(size_t, size_t)>* fn_ = nullptr;
  size_t count_ = 0, chunk_ = 1, next_ = 0, finished_ = 0;
  std::exception_ptr error_;
  bool stop_ = false;
  std::vector<std::thread> workers_;
};

}  // namespace footfall
