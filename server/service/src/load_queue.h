// LoadQueue: runs footfalld's server-side loads and upload grids on threads of their own
// (internal to footfall::service).
//
// Reading and resampling a large mesh or height map takes seconds; done on the RPC thread, it
// would hold up every other client meanwhile. The RPC thread submits a prepared load
// (TerrainRegistry::PrepareLoad), polls wake_fd() beside its sockets, and takes the finished
// loads back to add them to the registry and reply. Loads start in the order submitted, as many
// at once as there are workers.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "footfall/service/terrain_registry.h"

namespace footfall {

class LoadQueue {
 public:
  // At most `capacity` loads waiting or running at once, on `workers` threads.
  LoadQueue(size_t capacity, int workers);
  // Waits for the loads running, if any (unless abandoned).
  ~LoadQueue();
  LoadQueue(const LoadQueue&) = delete;
  LoadQueue& operator=(const LoadQueue&) = delete;

  // Queues a load; false (the load untouched) when `capacity` loads are already in the queue.
  bool Submit(std::unique_ptr<PendingLoad>* load);
  // The loads finished since the last call, in the order they finished; clears wake_fd().
  std::vector<std::unique_ptr<PendingLoad>> TakeFinished();
  // Readable (POLLIN) while finished loads wait to be taken.
  int wake_fd() const;
  // Drops the waiting loads and leaves those running to finish on their own (they hold what
  // they use): the process must then end with _exit, as the loaders use static data. Returns
  // whether any was running.
  bool Abandon();

 private:
  // Shared with the worker, which may outlive the queue once abandoned.
  struct State {
    ~State();
    int wake_fd = -1;
    std::mutex mutex;
    std::condition_variable wake_worker;
    std::deque<std::unique_ptr<PendingLoad>> waiting, finished;
    int running = 0;  // loads the workers hold
    bool stop = false;
  };
  static void Work(const std::shared_ptr<State>& state);

  size_t capacity_;
  std::shared_ptr<State> state_;
  std::vector<std::thread> workers_;
};

}  // namespace footfall
