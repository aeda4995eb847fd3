#include "load_queue.h"

#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>

#include "footfall/import/terrain_loader.h"
#include "footfall/terrain/file_extension.h"

namespace footfall {

LoadQueue::State::~State() {
  if (wake_fd >= 0) close(wake_fd);
}

LoadQueue::LoadQueue(size_t capacity, const int (&workers)[kLanes])
    : capacity_(capacity), state_(std::make_shared<State>()) {
  state_->wake_fd = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (state_->wake_fd < 0) throw std::runtime_error("cannot create the load queue's eventfd");
  // Room for every load the lanes may hold finished: a worker hands one over allocating
  // nothing (it waited, retrying, for memory that might never come back).
  state_->finished.reserve(MostFinished());
  state_->finished_lanes.reserve(MostFinished());
  try {
    for (int lane = 0; lane < kLanes; ++lane)
      for (int i = 0; i < workers[lane]; ++i)
        workers_.emplace_back([state = state_, lane] { Work(state, static_cast<Lane>(lane)); });
  } catch (...) {
    // A thread that could not start (a memory or process limit): the ones started are stopped
    // and joined before the error goes on (left joinable, they ended the process).
    StopWorkers();
    throw;
  }
}

LoadQueue::~LoadQueue() { StopWorkers(); }

void LoadQueue::StopWorkers() {
  {
    std::lock_guard<std::mutex> lock(state_->mutex);
    state_->stop = true;
    for (auto& waiting : state_->waiting) waiting.clear();
  }
  for (auto& wake : state_->wake_worker) wake.notify_all();
  for (std::thread& worker : workers_)
    if (worker.joinable()) worker.join();
}

int LoadQueue::wake_fd() const { return state_->wake_fd; }

LoadQueue::Lane LoadQueue::LaneOf(const PendingLoad& load) {
  if (!load.pinned) return kBuilding;  // an upload's samples
  return IsPointFileExtension(FileExtension(load.pinned->path())) ? kBuilding : kSampling;
}

bool LoadQueue::Full(Lane lane) const {
  std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->stop || state_->in_lane[lane] >= capacity_;
}

bool LoadQueue::Submit(std::unique_ptr<PendingLoad>* load) {
  State& s = *state_;
  const Lane lane = LaneOf(**load);
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.stop || s.in_lane[lane] >= capacity_) return false;
    s.waiting[lane].push_back(std::move(*load));
    ++s.in_lane[lane];
  }
  s.wake_worker[lane].notify_one();
  return true;
}

std::unique_ptr<PendingLoad> LoadQueue::Cancel(PendingLoad* load) {
  State& s = *state_;
  std::lock_guard<std::mutex> lock(s.mutex);
  for (int lane = 0; lane < kLanes; ++lane) {
    auto& waiting = s.waiting[lane];
    const auto it = std::find_if(waiting.begin(), waiting.end(),
                                 [load](const auto& w) { return w.get() == load; });
    if (it == waiting.end()) continue;
    std::unique_ptr<PendingLoad> withdrawn = std::move(*it);
    waiting.erase(it);
    --s.in_lane[lane];
    return withdrawn;
  }
  // Running or finished: the worker or TakeFinished holds it, and it lives until taken.
  load->cancelled = true;
  return nullptr;
}

void LoadQueue::TakeFinished(std::vector<std::unique_ptr<PendingLoad>>* done) {
  State& s = *state_;
  std::lock_guard<std::mutex> lock(s.mutex);
  uint64_t count = 0;
  while (read(s.wake_fd, &count, sizeof count) > 0) {
  }
  for (const Lane lane : s.finished_lanes) --s.in_lane[lane];
  s.finished_lanes.clear();
  done->clear();
  done->swap(s.finished);  // the queue keeps the caller's room
}

bool LoadQueue::Abandon() {
  State& s = *state_;
  std::lock_guard<std::mutex> lock(s.mutex);
  s.stop = true;
  for (auto& waiting : s.waiting) waiting.clear();
  for (auto& wake : s.wake_worker) wake.notify_all();
  const bool running = s.running > 0;
  for (std::thread& worker : workers_)
    if (worker.joinable()) worker.detach();  // the idle ones end at once
  return running;
}

namespace {

// Ends `load` with `status` and the message `text` + `name` (+ "'" when a name is given), or
// with no message when memory for one runs out too.
void Fail(PendingLoad* load, Status status, const char* text, const std::string& name) noexcept {
  load->status = status;
  try {
    load->message = text + name + (name.empty() ? "" : "'");
  } catch (const std::bad_alloc&) {
    load->message.clear();
  }
}

}  // namespace

void LoadQueue::Work(const std::shared_ptr<State>& state, Lane lane) {
  State& s = *state;
  std::unique_lock<std::mutex> lock(s.mutex);
  for (;;) {
    s.wake_worker[lane].wait(lock, [&s, lane] { return s.stop || !s.waiting[lane].empty(); });
    if (s.stop) return;
    std::unique_ptr<PendingLoad> load = std::move(s.waiting[lane].front());
    s.waiting[lane].pop_front();
    ++s.running;
    lock.unlock();
    try {
      RunLoad(load.get());
    } catch (const std::bad_alloc&) {
      Fail(load.get(), Status::kLimitExceeded, "out of memory loading '", load->relative_path);
    } catch (const std::exception& e) {
      Fail(load.get(), Status::kInternalError, e.what(), "");
    }
    lock.lock();
    --s.running;
    if (s.stop) return;  // abandoned, or the queue is going: nobody takes it back
    // Handed back into room reserved for it (it counts in its lane until taken): a load lost
    // here left its client waiting for a reply that never came.
    s.finished.push_back(std::move(load));
    s.finished_lanes.push_back(lane);
    const uint64_t one = 1;
    if (write(s.wake_fd, &one, sizeof one) < 0) {
      // Only on counter overflow, after 2^64 - 2 loads untaken: the flag is already up.
    }
  }
}

}  // namespace footfall
