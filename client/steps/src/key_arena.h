// KeyArena: the memory of a generated walk's keys, shared by its tracks.
#pragma once

#include <cstddef>
#include <memory_resource>
#include <mutex>
#include <vector>

namespace footfall {

// Hands out memory from large blocks and frees it all at once when destroyed: a crowd's keys
// are written once, in millions, and fault in far fewer pages than from the default heap.
// Thread-safe. Memory given back is not reused (tracks are reserved to their expected length,
// so little is).
class KeyArena : public std::pmr::memory_resource {
 public:
  // Blocks are in huge pages when the reservations are exact and hold from one huge page (2 MiB)
  // to this many bytes; else in ordinary pages: a huge page is backed whole once touched, and
  // reservations that are only a bound (a path walk's, for its longest) may far exceed the keys
  // written, while a small walk would leave most of its page untouched.
  static constexpr size_t kHugePagesUpTo = size_t{1} << 30;
  // Blocks hold at most this many bytes (more only for a single larger request): no single
  // mapping asks for all of a large reservation at once.
  static constexpr size_t kMaxBlock = size_t{256} << 20;

  // Sized for `expected` bytes in all, allocated as they are asked for. `exact`: they are what a
  // walk of every step writes (so touching them all costs no more than such a walk).
  KeyArena(size_t expected, bool exact);
  ~KeyArena() override;
  KeyArena(const KeyArena&) = delete;
  KeyArena& operator=(const KeyArena&) = delete;

 private:
  void* do_allocate(size_t bytes, size_t alignment) override;
  void do_deallocate(void*, size_t, size_t) override {}
  bool do_is_equal(const std::pmr::memory_resource& other) const noexcept override {
    return this == &other;
  }
  // Starts a block of at least `bytes`. Called with mutex_ held.
  void AddBlock(size_t bytes);

  const bool huge_pages_;
  const size_t block_;  // bytes per block
  std::mutex mutex_;
  std::vector<void*> blocks_;
  unsigned char* next_ = nullptr;  // free space of the last block: [next_, end_)
  unsigned char* end_ = nullptr;
};

}  // namespace footfall
