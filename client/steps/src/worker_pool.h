// WorkerPool: a fixed set of threads for the step generator's per-character loops, started once
// per walk instead of once per loop. Private to footfall::steps.
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <thread>
#include <vector>

namespace footfall::steps_detail {

class WorkerPool {
 public:
  // Starts threads - 1 workers (none for threads <= 1); the caller is the remaining one.
  explicit WorkerPool(int threads) {
    for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { Work(); });
  }
  ~WorkerPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      quit_ = true;
    }
    start_.notify_all();
    for (std::thread& t : workers_) t.join();
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // fn(begin, end) over [0, count) in contiguous chunks of about count / (8 * threads())
  // items, which the calling thread and the workers take in turn until none is left (so a thread
  // the system holds up delays the others little); returns when every chunk is done. fn must not
  // throw, and each item's result must not depend on the chunks. Not reentrant.
  template <typename Fn>
  void Run(size_t count, Fn& fn) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      call_ = [](void* f, size_t b, size_t e) { (*static_cast<Fn*>(f))(b, e); };
      fn_ = &fn;
      count_ = count;
      grain_ = std::max<size_t>(1, count / (8 * static_cast<size_t>(threads())));
      next_.store(0, std::memory_order_relaxed);
      running_ = workers_.size();
      ++generation_;
    }
    start_.notify_all();
    Chunks(call_, fn_, count, grain_);
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return running_ == 0; });
  }

 private:
  // Takes chunks of [0, count) until none is left.
  void Chunks(void (*call)(void*, size_t, size_t), void* fn, size_t count, size_t grain) {
    for (;;) {
      const size_t b = next_.fetch_add(grain, std::memory_order_relaxed);
      if (b >= count) return;
      call(fn, b, std::min(count, b + grain));
    }
  }

  void Work() {
    size_t seen = 0;
    for (;;) {
      void (*call)(void*, size_t, size_t);
      void* fn;
      size_t count, grain;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        start_.wait(lock, [&] { return quit_ || generation_ != seen; });
        if (quit_) return;
        seen = generation_;
        call = call_, fn = fn_, count = count_, grain = grain_;
      }
      Chunks(call, fn, count, grain);
      std::lock_guard<std::mutex> lock(mutex_);
      if (--running_ == 0) done_.notify_one();
    }
  }

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  void (*call_)(void*, size_t, size_t) = nullptr;
  void* fn_ = nullptr;
  size_t count_ = 0, grain_ = 1, running_ = 0, generation_ = 0;
  std::atomic<size_t> next_{0};  // start of the next chunk to take
  bool quit_ = false;
};

}  // namespace footfall::steps_detail
