// WorkerPool: a fixed set of threads for the step generator's per-character loops, started once
// per walk instead of once per loop. Private to footfall::steps.
#pragma once

#include <algorithm>
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
    for (int i = 1; i < threads; ++i) workers_.emplace_back([this, i] { Work(i); });
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

  // fn(begin, end) over [0, count) in threads() contiguous chunks, the first on the calling
  // thread; returns when every chunk is done. fn must not throw. Not reentrant.
  template <typename Fn>
  void Run(size_t count, Fn& fn) {
    const size_t chunk = (count + threads() - 1) / threads();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      call_ = [](void* f, size_t b, size_t e) { (*static_cast<Fn*>(f))(b, e); };
      fn_ = &fn;
      count_ = count, chunk_ = chunk;
      running_ = workers_.size();
      ++generation_;
    }
    start_.notify_all();
    fn(size_t{0}, std::min(count, chunk));
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return running_ == 0; });
  }

 private:
  void Work(int index) {
    size_t seen = 0;
    for (;;) {
      void (*call)(void*, size_t, size_t);
      void* fn;
      size_t b, e;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        start_.wait(lock, [&] { return quit_ || generation_ != seen; });
        if (quit_) return;
        seen = generation_;
        call = call_, fn = fn_;
        b = std::min(count_, static_cast<size_t>(index) * chunk_), e = std::min(count_, b + chunk_);
      }
      if (b < e) call(fn, b, e);
      std::lock_guard<std::mutex> lock(mutex_);
      if (--running_ == 0) done_.notify_one();
    }
  }

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  void (*call_)(void*, size_t, size_t) = nullptr;
  void* fn_ = nullptr;
  size_t count_ = 0, chunk_ = 0, running_ = 0, generation_ = 0;
  bool quit_ = false;
};

}  // namespace footfall::steps_detail
