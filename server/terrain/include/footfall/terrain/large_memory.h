// Large allocations that random access reads or writes: a terrain grid, a crowd's keys.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

namespace footfall {

// Allocates `bytes` (at least 1). From 2 MiB on, the block is aligned to 2 MiB and, with
// `huge_pages`, marked for transparent huge pages where the system offers them (Linux, madvise
// mode): random access over tens of megabytes otherwise spends much of its time in TLB misses,
// and first touches of a fresh block fault 512 times less often. A huge page is backed whole
// on its first touch: leave `huge_pages` off for blocks that may be touched sparsely. Throws
// std::bad_alloc. Free with FreeLargeMemory.
void* AllocateLargeMemory(size_t bytes, bool huge_pages = true);
void FreeLargeMemory(void* p);

// The allocator of LargeVector: blocks from AllocateLargeMemory, in huge pages from 2 MiB on.
template <typename T>
struct LargeAllocator {
  using value_type = T;
  LargeAllocator() = default;
  template <typename U>
  LargeAllocator(const LargeAllocator<U>&) {}
  T* allocate(size_t n) {
    if (n > SIZE_MAX / sizeof(T)) throw std::bad_alloc();
    return static_cast<T*>(AllocateLargeMemory(n * sizeof(T)));
  }
  void deallocate(T* p, size_t) { FreeLargeMemory(p); }
  template <typename U>
  bool operator==(const LargeAllocator<U>&) const {
    return true;
  }
  template <typename U>
  bool operator!=(const LargeAllocator<U>&) const {
    return false;
  }
};

// A vector for tens of megabytes filled densely (a mesh sampler's candidates): its first
// touches fault once per huge page instead of once per 4 KiB page.
template <typename T>
using LargeVector = std::vector<T, LargeAllocator<T>>;

// [Units: bytes] The memory this process may still take: the system's available memory
// (MemAvailable), or what its address-space limit (RLIMIT_AS) leaves when that is less. 0 when
// unknown. For refusing work that would run out of memory half-way with a message up front.
double AvailableMemoryBytes();

// [Units: bytes] The memory this process may use at most: physical memory, or its address-space
// limit when lower. 0 when unknown.
double UsableMemoryBytes();

}  // namespace footfall
