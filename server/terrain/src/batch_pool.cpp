#include "footfall/terrain/batch_pool.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <new>
#include <system_error>

namespace footfall {
namespace {

// The pool whose job the calling thread is running, if any: a Run it makes on that pool runs
// on the calling thread (a nested batch, such as an embedded query inside a generator's pass).
thread_local const BatchPool* running_job = nullptr;

inline void CpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

}  // namespace

BatchPool::BatchPool(int threads, int caller_spin_us, int worker_spin_us)
    : caller_spin_us_(caller_spin_us), worker_spin_us_(worker_spin_us) {
  // As many workers as can start (a memory or process limit may allow fewer, or none): a
  // thread that cannot start ended the process, as a half-made vector of threads may not be
  // destroyed.
  try {
    workers_.reserve(static_cast<size_t>(std::max(threads - 1, 0)));
    for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { Work(); });
  } catch (const std::system_error&) {
  } catch (const std::bad_alloc&) {
  }
}

BatchPool::~BatchPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  work_.notify_all();
  for (auto& t : workers_) t.join();
}

template <typename Done>
bool BatchPool::Spin(int us, Done&& done) {
  if (us <= 0) return done();
  const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(us);
  for (;;) {
    for (int i = 0; i < 64; ++i) {
      if (done()) return true;
      CpuRelax();
    }
    if (std::chrono::steady_clock::now() >= until) return done();
  }
}

void BatchPool::Drain(std::unique_lock<std::mutex>& lock) {
  while (next_ < count_) {
    const size_t begin = next_, end = std::min(count_, begin + chunk_);
    next_ = end;
    const auto* fn = fn_;
    lock.unlock();
    std::exception_ptr error;
    const BatchPool* outer = running_job;
    running_job = this;
    try {
      (*fn)(begin, end);
    } catch (...) {
      error = std::current_exception();
    }
    running_job = outer;
    lock.lock();
    if (error && !error_) error_ = error;
    const size_t finished = finished_.load(std::memory_order_relaxed) + (end - begin);
    finished_.store(finished, std::memory_order_release);
    if (finished == count_ && caller_sleeping_) done_.notify_one();
  }
}

void BatchPool::Work() {
  uint64_t seen = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    if (worker_spin_us_ > 0 && !stop_ && posted_ == seen) {
      lock.unlock();
      Spin(worker_spin_us_, [&] { return posted_.load(std::memory_order_acquire) != seen; });
      lock.lock();
    }
    work_.wait(lock, [&] { return stop_ || posted_ != seen; });
    if (stop_) return;
    seen = posted_;
    Drain(lock);
  }
}

void BatchPool::Run(size_t count, size_t chunk, const std::function<void(size_t, size_t)>& fn) {
  chunk = std::max<size_t>(1, chunk);
  std::unique_lock<std::mutex> run(run_mutex_, std::defer_lock);
  if (workers_.empty() || count <= chunk || running_job == this || !run.try_lock()) {
    if (count > 0) fn(0, count);
    return;
  }
  std::unique_lock<std::mutex> lock(mutex_);
  fn_ = &fn;
  count_ = count, chunk_ = chunk, next_ = 0;
  finished_.store(0);
  error_ = nullptr;
  ++posted_;
  lock.unlock();
  work_.notify_all();
  lock.lock();
  Drain(lock);
  // The workers' last chunks: poll for a while, then sleep until the last one wakes us.
  lock.unlock();
  const bool done =
      Spin(caller_spin_us_, [&] { return finished_.load(std::memory_order_acquire) == count; });
  lock.lock();
  if (!done) {
    caller_sleeping_ = true;
    done_.wait(lock, [&] { return finished_.load() == count_; });
    caller_sleeping_ = false;
  }
  // Nothing left to take: a worker that wakes now finds no chunk.
  count_ = next_ = 0;
  finished_.store(0);
  fn_ = nullptr;
  std::exception_ptr error = error_;
  error_ = nullptr;
  lock.unlock();
  if (error) std::rethrow_exception(error);
}

std::shared_ptr<BatchPool> SharedBatchPool(int threads) {
  if (threads <= 1) return nullptr;
  static std::mutex mutex;
  static std::map<int, std::weak_ptr<BatchPool>> pools;
  std::lock_guard<std::mutex> lock(mutex);
  std::shared_ptr<BatchPool> pool = pools[threads].lock();
  if (!pool) {
    pool = std::make_shared<BatchPool>(threads, 100, 200);
    pools[threads] = pool;
  }
  return pool;
}

}  // namespace footfall
