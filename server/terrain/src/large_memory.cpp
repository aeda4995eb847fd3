#include "footfall/terrain/large_memory.h"

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include <algorithm>
#include <cstdlib>
#include <new>

namespace footfall {

void* AllocateLargeMemory(size_t bytes, bool huge_pages) {
  constexpr size_t kHugePage = size_t{2} << 20;
  bytes = std::max<size_t>(bytes, 1);
  void* p = nullptr;
  if (bytes < kHugePage) {
    p = std::malloc(bytes);
  } else {
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    if (rounded < bytes) throw std::bad_alloc();  // overflow
    p = std::aligned_alloc(kHugePage, rounded);
#ifdef MADV_HUGEPAGE
    if (p && huge_pages) madvise(p, rounded, MADV_HUGEPAGE);
#endif
  }
  if (!p) throw std::bad_alloc();
  return p;
}

void FreeLargeMemory(void* p) { std::free(p); }

}  // namespace footfall
