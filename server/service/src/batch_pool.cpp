#include "batch_pool.h"

#include <algorithm>

namespace footfall {

BatchPool::BatchPool(int threads) {
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { Work(); });
}

BatchPool::~BatchPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  work_.notify_all();
  for (auto& t : workers_) t.join();
}

void BatchPool::Drain(std::unique_lock<std::mutex>& lock) {
  while (next_ < count_) {
    const size_t begin = next_, end = std::min(count_, begin + chunk_);
    next_ = end;
    const auto* fn = fn_;
    lock.unlock();
    std::exception_ptr error;
    try {
      (*fn)(begin, end);
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    if (error && !error_) error_ = error;
    finished_ += end - begin;
    if (finished_ == count_) done_.notify_all();
  }
}

void BatchPool::Work() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    work_.wait(lock, [this] { return stop_ || next_ < count_; });
    if (stop_) return;
    Drain(lock);
  }
}

void BatchPool::Run(size_t count, size_t chunk, const std::function<void(size_t, size_t)>& fn) {
  chunk = std::max<size_t>(1, chunk);
  if (workers_.empty() || count <= chunk) {
    if (count > 0) fn(0, count);
    return;
  }
  std::unique_lock<std::mutex> lock(mutex_);
  fn_ = &fn;
  count_ = count, chunk_ = chunk, next_ = 0, finished_ = 0;
  error_ = nullptr;
  lock.unlock();
  work_.notify_all();
  lock.lock();
  Drain(lock);
  done_.wait(lock, [this] { return finished_ == count_; });
  // Nothing left to take: workers go back to sleep.
  count_ = next_ = finished_ = 0;
  fn_ = nullptr;
  std::exception_ptr error = error_;
  error_ = nullptr;
  lock.unlock();
  if (error) std::rethrow_exception(error);
}

}  // namespace footfall
