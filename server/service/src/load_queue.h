// LoadQueue: runs footfalld's server-side loads and upload grids on threads of their own
// (internal to footfall::service).
//
// Reading and resampling a large mesh or height map takes seconds; done on the RPC thread, it
// would hold up every other client meanwhile. The RPC thread submits a prepared load
// (TerrainRegistry::PrepareLoad), polls wake_fd() beside its sockets, and takes the finished
// loads back to add them to the registry and reply.
//
// Two lanes, each with threads of its own: meshes and height maps (resampled: seconds each, and
// memory bound) go to the sampling lane; point files and the grids of finished uploads (no
// resampling: a grid of a million samples is a fraction of a second) go to the build lane, so
// that a client's upload is never queued behind other clients' slow mesh loads. Within a lane,
// loads start in the order submitted, as many at once as the lane has workers.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "footfall/service/terrain_registry.h"

namespace footfall {

class LoadQueue {
 public:
  enum Lane { kSampling = 0, kBuilding = 1 };
  static constexpr int kLanes = 2;

  // At most `capacity` loads waiting, running or finished untaken in each lane, which has
  // `workers[lane]` threads.
  LoadQueue(size_t capacity, const int (&workers)[kLanes]);
  // Waits for the loads running, if any (unless abandoned).
  ~LoadQueue();
  LoadQueue(const LoadQueue&) = delete;
  LoadQueue& operator=(const LoadQueue&) = delete;

  // The lane of a prepared load: kBuilding for an upload or a point file, else kSampling.
  static Lane LaneOf(const PendingLoad& load);
  // Whether `lane` holds `capacity` loads (a Submit to it would fail).
  bool Full(Lane lane) const;
  // Queues a load in its lane; false (the load untouched) when that lane is full.
  bool Submit(std::unique_ptr<PendingLoad>* load);
  // Withdraws a load whose client has gone: one still waiting leaves its lane at once and is
  // returned (for its owner to release what it reserved); one running is marked
  // (PendingLoad::cancelled), ends at its next stage and comes back through TakeFinished, as
  // does one already finished (nullptr for both).
  std::unique_ptr<PendingLoad> Cancel(PendingLoad* load);
  // Room for every load the lanes may hold, for the caller's vector that TakeFinished swaps.
  size_t MostFinished() const { return kLanes * capacity_; }
  // Puts the loads finished since the last call into *done (empty, with room for
  // MostFinished(), which it then keeps), in the order they finished; clears wake_fd().
  // Allocates nothing, as a worker handing a load over does not: finished loads are answered
  // even while memory runs out, and stays out.
  void TakeFinished(std::vector<std::unique_ptr<PendingLoad>>* done);
  // Readable (POLLIN) while finished loads wait to be taken.
  int wake_fd() const;
  // Drops the waiting loads and leaves those running to finish on their own (they hold what
  // they use): the process must then end with _exit, as the loaders use static data. Returns
  // whether any was running.
  bool Abandon();

 private:
  // Stops the workers and joins those not abandoned.
  void StopWorkers();
  // Shared with the worker, which may outlive the queue once abandoned.
  struct State {
    ~State();
    int wake_fd = -1;
    mutable std::mutex mutex;
    std::condition_variable wake_worker[kLanes];
    std::deque<std::unique_ptr<PendingLoad>> waiting[kLanes];
    // The finished loads untaken, and the lane of each (apart, so that TakeFinished hands the
    // loads over by a swap, allocating nothing).
    std::vector<std::unique_ptr<PendingLoad>> finished;
    std::vector<Lane> finished_lanes;
    size_t in_lane[kLanes] = {0, 0};  // waiting, running or finished untaken
    int running = 0;                  // loads the workers hold, over both lanes
    bool stop = false;
  };
  static void Work(const std::shared_ptr<State>& state, Lane lane);

  size_t capacity_;
  std::shared_ptr<State> state_;
  std::vector<std::thread> workers_;
};

}  // namespace footfall
