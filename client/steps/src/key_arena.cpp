#include "key_arena.h"

#include <algorithm>
#include <cstdint>
#include <new>

#include "footfall/terrain/large_memory.h"

namespace footfall {
namespace {

// [Units: bytes] One huge page: blocks in huge pages hold at least this much, and only walks
// expected to fill one are given them (a huge page is backed whole once touched: a scene of
// 2,000 one-step characters took 2 MiB each, 4 GB for a 1.8 MB walk).
constexpr size_t kHugePage = size_t{2} << 20;
// [Units: bytes] Blocks in ordinary pages hold at least this much.
constexpr size_t kMinBlock = size_t{64} << 10;

}  // namespace

KeyArena::KeyArena(size_t expected, bool exact)
    : huge_pages_(exact && expected >= kHugePage && expected <= kHugePagesUpTo),
      block_(std::clamp(expected, huge_pages_ ? kHugePage : kMinBlock, kMaxBlock)) {}

KeyArena::~KeyArena() {
  for (void* p : blocks_) FreeLargeMemory(p);
}

void KeyArena::AddBlock(size_t bytes) {
  bytes = std::max(bytes, block_);
  blocks_.reserve(blocks_.size() + 1);
  void* p = AllocateLargeMemory(bytes, huge_pages_);
  blocks_.push_back(p);
  next_ = static_cast<unsigned char*>(p);
  end_ = next_ + bytes;
}

void* KeyArena::do_allocate(size_t bytes, size_t alignment) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto aligned = [&]() {
    const uintptr_t at = reinterpret_cast<uintptr_t>(next_);
    return next_ + ((alignment - at % alignment) % alignment);
  };
  unsigned char* p = next_ ? aligned() : nullptr;
  // (Padding past the block's end leaves no room: end_ - p would be negative.)
  if (!p || p > end_ || static_cast<size_t>(end_ - p) < bytes) {
    if (bytes > SIZE_MAX - alignment) throw std::bad_alloc();
    AddBlock(bytes + alignment);
    p = aligned();
  }
  next_ = p + bytes;
  return p;
}

}  // namespace footfall
