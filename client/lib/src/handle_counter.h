// Terrain handles of a session: 1 to 2^32 - 1 in turn, wrapping past the top, skipping 0 and
// every handle still in use. Internal to client/lib.
#pragma once

#include "footfall/client/terrain_session.h"

namespace footfall {

class HandleCounter {
 public:
  // `first`: the first handle tried (1 unless a test starts it near the wrap).
  explicit HandleCounter(TerrainHandle first = 1) : next_(first) {}

  // The next handle h, from where the last one stopped, with h != 0 and !in_use(h). A session
  // holds far fewer than 2^32 - 1 terrains (each takes memory), so one is always found.
  template <typename InUse>
  TerrainHandle Next(const InUse& in_use) {
    TerrainHandle h = next_++;
    while (h == 0 || in_use(h)) h = next_++;
    return h;
  }

 private:
  TerrainHandle next_;
};

}  // namespace footfall
