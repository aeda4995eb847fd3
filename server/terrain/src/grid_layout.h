// Layout constants shared by the grid's build and its queries.
#pragma once

#include <cstdint>

namespace footfall {
namespace detail {

// Cells per axis of a block, the coarse level used for queries far from the grid.
constexpr uint32_t kBlockCells = 8;

}  // namespace detail
}  // namespace footfall
