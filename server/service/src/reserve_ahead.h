// Room reserved ahead in the lists footfalld's loop refills at every turn (internal to
// footfall::service): once grown, a turn allocates nothing, so that while memory runs out
// requests are still read and answered (with errors), rather than every turn failing.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace footfall {

// [Units: entries] The least room reserved: the sockets of a few hundred connections.
constexpr size_t kLeastReserved = 256;

// Makes room in `list` for `needed` entries, reserving twice that (and at least
// kLeastReserved) when it grows. Throws std::bad_alloc, the list unchanged, when memory runs
// out.
template <typename T>
void ReserveAhead(std::vector<T>* list, size_t needed) {
  if (list->capacity() < needed) list->reserve(std::max(kLeastReserved, 2 * needed));
}

// Grows `by_socket`, a list indexed by socket number, so that `fd` is an index in it (new
// entries zero), ahead as ReserveAhead does.
template <typename T>
void GrowForSocket(std::vector<T>* by_socket, int fd) {
  const size_t needed = static_cast<size_t>(fd) + 1;
  if (by_socket->size() >= needed) return;
  ReserveAhead(by_socket, needed);
  by_socket->resize(needed, T{});
}

}  // namespace footfall
