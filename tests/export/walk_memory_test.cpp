// The heap a walk's reading takes at its peak, counted by this executable's own operator new:
// keys read as they are parsed hold little more than the walk itself, where the whole document
// held several times the text.
#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

#include <catch2/catch.hpp>

#include "footfall/steps/walk_json.h"
#include "walk_fixtures.h"

namespace {

std::atomic<size_t> g_in_use{0};
std::atomic<size_t> g_peak{0};

void* Counted(void* p) {
  if (p == nullptr) throw std::bad_alloc();
  const size_t now = g_in_use += malloc_usable_size(p);
  size_t peak = g_peak.load();
  while (now > peak && !g_peak.compare_exchange_weak(peak, now)) {
  }
  return p;
}

void Uncounted(void* p) {
  if (p == nullptr) return;
  g_in_use -= malloc_usable_size(p);
  std::free(p);
}

void* Aligned(size_t n, std::align_val_t a) {
  void* p = nullptr;
  if (posix_memalign(&p, std::max(sizeof(void*), static_cast<size_t>(a)), n ? n : 1) != 0)
    p = nullptr;
  return Counted(p);
}

}  // namespace

void* operator new(size_t n) { return Counted(std::malloc(n ? n : 1)); }
void* operator new[](size_t n) { return Counted(std::malloc(n ? n : 1)); }
void* operator new(size_t n, std::align_val_t a) { return Aligned(n, a); }
void* operator new[](size_t n, std::align_val_t a) { return Aligned(n, a); }
void operator delete(void* p) noexcept { Uncounted(p); }
void operator delete[](void* p) noexcept { Uncounted(p); }
void operator delete(void* p, size_t) noexcept { Uncounted(p); }
void operator delete[](void* p, size_t) noexcept { Uncounted(p); }
void operator delete(void* p, std::align_val_t) noexcept { Uncounted(p); }
void operator delete[](void* p, std::align_val_t) noexcept { Uncounted(p); }
void operator delete(void* p, size_t, std::align_val_t) noexcept { Uncounted(p); }
void operator delete[](void* p, size_t, std::align_val_t) noexcept { Uncounted(p); }

using namespace footfall;

TEST_CASE("Reading a walk of many keys takes little more heap than the walk",
          "[export][walk_json]") {
  // 120,000 keys, about 11 MB of text.
  const std::string text = WalkToJson(test::LongCrowdWalk(20000));
  size_t keys = 0, rotations = 0;
  // The heap each reading adds, at its peak, to what is in use before it.
  auto peak_of = [&text](bool whole) {
    const size_t before = g_in_use.load();
    g_peak = before;
    Walk walk;
    std::string error;
    const Status status = whole ? detail::ParseWalkJsonWhole(text, "w.json", &walk, &error)
                                : ParseWalkJson(text, "w.json", &walk, &error);
    REQUIRE(status == Status::kOk);
    return g_peak.load() - before;
  };
  {
    Walk walk;
    std::string error;
    REQUIRE(ParseWalkJson(text, "w.json", &walk, &error) == Status::kOk);
    for (const WalkTrack& t : walk.tracks) keys += t.keys.size(), rotations += t.rotations.size();
  }
  const double walk_bytes = static_cast<double>(keys * sizeof(WalkKey) + rotations * sizeof(Quat));
  const double streamed = static_cast<double>(peak_of(false));
  const double whole = static_cast<double>(peak_of(true));
  INFO("text " << text.size() << " B, walk " << walk_bytes << " B, streamed peak " << streamed
               << " B, whole-document peak " << whole << " B");
  // A track's keys grow by doubling: up to three times their size while they move.
  CHECK(streamed < 3.2 * walk_bytes);
  CHECK(whole > 3 * streamed);
}
