#include "load_queue.h"

#include <sys/eventfd.h>
#include <unistd.h>

#include <cstdint>
#include <new>
#include <stdexcept>

namespace footfall {

LoadQueue::State::~State() {
  if (wake_fd >= 0) close(wake_fd);
}

LoadQueue::LoadQueue(size_t capacity, int workers)
    : capacity_(capacity), state_(std::make_shared<State>()) {
  state_->wake_fd = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (state_->wake_fd < 0) throw std::runtime_error("cannot create the load queue's eventfd");
  for (int i = 0; i < workers; ++i) workers_.emplace_back([state = state_] { Work(state); });
}

LoadQueue::~LoadQueue() {
  {
    std::lock_guard<std::mutex> lock(state_->mutex);
    state_->stop = true;
    state_->waiting.clear();
  }
  state_->wake_worker.notify_all();
  for (std::thread& worker : workers_)
    if (worker.joinable()) worker.join();
}

int LoadQueue::wake_fd() const { return state_->wake_fd; }

bool LoadQueue::Submit(std::unique_ptr<PendingLoad>* load) {
  State& s = *state_;
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.stop ||
        s.waiting.size() + s.finished.size() + static_cast<size_t>(s.running) >= capacity_)
      return false;
    s.waiting.push_back(std::move(*load));
  }
  s.wake_worker.notify_one();
  return true;
}

std::vector<std::unique_ptr<PendingLoad>> LoadQueue::TakeFinished() {
  State& s = *state_;
  uint64_t count = 0;
  while (read(s.wake_fd, &count, sizeof count) > 0) {
  }
  std::lock_guard<std::mutex> lock(s.mutex);
  std::vector<std::unique_ptr<PendingLoad>> done;
  for (auto& load : s.finished) done.push_back(std::move(load));
  s.finished.clear();
  return done;
}

bool LoadQueue::Abandon() {
  State& s = *state_;
  std::lock_guard<std::mutex> lock(s.mutex);
  s.stop = true;
  s.waiting.clear();
  s.wake_worker.notify_all();
  const bool running = s.running > 0;
  for (std::thread& worker : workers_)
    if (worker.joinable()) worker.detach();  // the idle ones end at once
  return running;
}

void LoadQueue::Work(const std::shared_ptr<State>& state) {
  State& s = *state;
  std::unique_lock<std::mutex> lock(s.mutex);
  for (;;) {
    s.wake_worker.wait(lock, [&s] { return s.stop || !s.waiting.empty(); });
    if (s.stop) return;
    std::unique_ptr<PendingLoad> load = std::move(s.waiting.front());
    s.waiting.pop_front();
    ++s.running;
    lock.unlock();
    try {
      RunLoad(load.get());
    } catch (const std::bad_alloc&) {
      load->status = Status::kLimitExceeded;
      load->message = "out of memory loading '" + load->relative_path + "'";
    } catch (const std::exception& e) {
      load->status = Status::kInternalError;
      load->message = e.what();
    }
    lock.lock();
    --s.running;
    if (s.stop) return;  // abandoned, or the queue is going: nobody takes it back
    s.finished.push_back(std::move(load));
    const uint64_t one = 1;
    if (write(s.wake_fd, &one, sizeof one) < 0) {
      // Only on counter overflow, after 2^64 - 2 loads untaken: the flag is already up.
    }
  }
}

}  // namespace footfall
