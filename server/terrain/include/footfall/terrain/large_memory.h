// Large allocations that random access reads or writes: a terrain grid, a crowd's keys.
#pragma once

#include <cstddef>

namespace footfall {

// Allocates `bytes` (at least 1). From 2 MiB on, the block is aligned to 2 MiB and, with
// `huge_pages`, marked for transparent huge pages where the system offers them (Linux, madvise
// mode): random access over tens of megabytes otherwise spends much of its time in TLB misses,
// and first touches of a fresh block fault 512 times less often. A huge page is backed whole
// on its first touch: leave `huge_pages` off for blocks that may be touched sparsely. Throws
// std::bad_alloc. Free with FreeLargeMemory.
void* AllocateLargeMemory(size_t bytes, bool huge_pages = true);
void FreeLargeMemory(void* p);

// [Units: bytes] The memory this process may still take: the system's available memory
// (MemAvailable), or what its address-space limit (RLIMIT_AS) leaves when that is less. 0 when
// unknown. For refusing work that would run out of memory half-way with a message up front.
double AvailableMemoryBytes();

// [Units: bytes] The memory this process may use at most: physical memory, or its address-space
// limit when lower. 0 when unknown.
double UsableMemoryBytes();

}  // namespace footfall
