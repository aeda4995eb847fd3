// TerrainGrid's queries: nearest sample (snap, normal) and foothold (next), single and in
// batches. Build is in grid_build.cpp.
#include "footfall/terrain/grid.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "cell_scan.h"
#include "footfall/terrain/batch_pool.h"
#include "grid_layout.h"
#include "query_math.h"

namespace footfall {
namespace {

using detail::kBlockCells;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kNoIndex = std::numeric_limits<uint32_t>::max();
// Batches start loading a query's cell offsets this many queries ahead, then its samples half
// as far ahead.
constexpr size_t kPrefetchDistance = 6;
// Batches find the answers of this many queries before reading their normals and indices, which
// were prefetched meanwhile.
constexpr size_t kAnswerLag = 8;

// The 26 neighbours of a cell as offsets: faces, then edges, then corners.
constexpr int kNeighbourOrder[26][3] = {
    {-1, 0, 0},  {1, 0, 0},   {0, -1, 0}, {0, 1, 0},   {0, 0, -1},   {0, 0, 1},   {-1, -1, 0},
    {1, -1, 0},  {-1, 1, 0},  {1, 1, 0},  {-1, 0, -1}, {1, 0, -1},   {-1, 0, 1},  {1, 0, 1},
    {0, -1, -1}, {0, 1, -1},  {0, -1, 1}, {0, 1, 1},   {-1, -1, -1}, {1, -1, -1}, {-1, 1, -1},
    {1, 1, -1},  {-1, -1, 1}, {1, -1, 1}, {-1, 1, 1},  {1, 1, 1}};

}  // namespace

// Cell boxes, in local coordinates. Border cells reach the sample bounds, where they hold
// samples outside the grid box.
double TerrainGrid::CellLo(uint32_t i, int axis) const {
  const double lo = grid_lo_[axis] + i * cell_size_;
  return i == 0 ? std::min(lo, bounds_lo_[axis]) : lo;
}

double TerrainGrid::CellHi(uint32_t i, int axis) const {
  const double hi = grid_lo_[axis] + (i + 1.0) * cell_size_;
  return i + 1 == dims_[axis] ? std::max(hi, bounds_hi_[axis]) : hi;
}

template <typename Scanner>
void TerrainGrid::Search(const double c[3], Scanner& scanner) const {
  if (count_ == 0) return;
  // The cell-box pad (see Build), plus rounding in the distance arithmetic (~1e-15 of the
  // query's distance).
  const double pad = pad_ + 1e-13 * (std::fabs(c[0]) + std::fabs(c[1]) + std::fabs(c[2]));
  auto gap2 = [pad](double v, double lo, double hi) {
    const double d = v < lo - pad ? lo - pad - v : v > hi + pad ? v - hi - pad : 0.0;
    return d * d;
  };
  const int64_t n[3] = {dims_[0], dims_[1], dims_[2]};
  const int64_t ci[3] = {CellCoord(c[0], 0), CellCoord(c[1], 1), CellCoord(c[2], 2)};
  // Visits one cell; lo/hi are its padded box, needed only by scanners that test boxes.
  auto visit_cell = [&](int64_t i, int64_t j, int64_t k, const double* lo, const double* hi) {
    const size_t cell = (static_cast<size_t>(k) * n[1] + j) * n[0] + i;
    const uint32_t b = cell_start_[cell], e = cell_start_[cell + 1];
    if (b == e) return;
    if (Scanner::kUsesBox && !scanner.KeepCell(lo, hi)) return;
    scanner.Scan(static_cast<uint32_t>(cell), b, e);
  };
  auto visit = [&](int64_t i, int64_t j, int64_t k) {
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    if (Scanner::kUsesBox) {
      const int64_t idx[3] = {i, j, k};
      for (int a = 0; a < 3; ++a) {
        lo[a] = CellLo(static_cast<uint32_t>(idx[a]), a) - pad;
        hi[a] = CellHi(static_cast<uint32_t>(idx[a]), a) + pad;
      }
    }
    visit_cell(i, j, k, lo, hi);
  };

  // 1. The query's own cell.
  visit(ci[0], ci[1], ci[2]);

  // 2. When the ball of the best distance so far (or the candidate radius) reaches few cells,
  //    visit exactly those: the cells overlapping the ball's bounding box, pruned by distance.
  //    If it reaches beyond the 26 neighbours, visit those first: they usually shrink the ball.
  constexpr int64_t kMaxAxisCells = 16, kMaxBoxCells = 343;
  double gap[3][kMaxAxisCells], box_lo[3][kMaxAxisCells], box_hi[3][kMaxAxisCells];
  int64_t lo[3], hi[3];
  // Fills lo/hi with the cell range the ball reaches; returns its cell count (capped).
  auto ball_box = [&]() -> int64_t {
    if (!(scanner.limit2() < kInf)) return kMaxBoxCells + 1;
    const double reach = std::sqrt(scanner.limit2()) + pad;
    int64_t cells = 1;
    for (int a = 0; a < 3; ++a) {
      lo[a] = CellCoord(c[a] - reach, a), hi[a] = CellCoord(c[a] + reach, a);
      if (hi[a] - lo[a] + 1 > kMaxAxisCells) return kMaxBoxCells + 1;
      cells *= hi[a] - lo[a] + 1;
    }
    return cells;
  };
  // Visits the box's cells farther than `skip` (Chebyshev) from the query's cell.
  auto visit_box = [&](int64_t skip) {
    for (int a = 0; a < 3; ++a) {
      for (int64_t t = lo[a]; t <= hi[a]; ++t) {
        const double cl = CellLo(static_cast<uint32_t>(t), a);
        const double ch = CellHi(static_cast<uint32_t>(t), a);
        gap[a][t - lo[a]] = gap2(c[a], cl, ch);
        box_lo[a][t - lo[a]] = cl - pad, box_hi[a][t - lo[a]] = ch + pad;
      }
    }
    for (int64_t k = lo[2]; k <= hi[2]; ++k) {
      const double gk = gap[2][k - lo[2]];
      if (gk > scanner.limit2()) continue;
      for (int64_t j = lo[1]; j <= hi[1]; ++j) {
        const double gjk = gk + gap[1][j - lo[1]];
        if (gjk > scanner.limit2()) continue;
        const bool inner = std::abs(k - ci[2]) <= skip && std::abs(j - ci[1]) <= skip;
        for (int64_t i = lo[0]; i <= hi[0]; ++i) {
          if (inner && std::abs(i - ci[0]) <= skip) continue;
          if (gjk + gap[0][i - lo[0]] > scanner.limit2()) continue;
          const double cell_lo[3] = {box_lo[0][i - lo[0]], box_lo[1][j - lo[1]],
                                     box_lo[2][k - lo[2]]};
          const double cell_hi[3] = {box_hi[0][i - lo[0]], box_hi[1][j - lo[1]],
                                     box_hi[2][k - lo[2]]};
          visit_cell(i, j, k, cell_lo, cell_hi);
        }
      }
    }
  };
  // The 26 neighbours, the 6 sharing a face first, then the 12 sharing an edge, then the 8
  // corners: the nearer classes usually shrink the ball enough to skip most of the others.
  auto visit_neighbours = [&]() {
    double g[3][3], box_lo[3][3], box_hi[3][3];
    bool has[3][3];
    for (int a = 0; a < 3; ++a) {
      for (int d = 0; d < 3; ++d) {
        const int64_t t = ci[a] + d - 1;
        has[a][d] = t >= 0 && t < n[a];
        if (!has[a][d]) continue;
        const double cl = CellLo(static_cast<uint32_t>(t), a);
        const double ch = CellHi(static_cast<uint32_t>(t), a);
        g[a][d] = gap2(c[a], cl, ch);
        box_lo[a][d] = cl - pad, box_hi[a][d] = ch + pad;
      }
    }
    for (const auto& o : kNeighbourOrder) {
      const int i = o[0] + 1, j = o[1] + 1, k = o[2] + 1;
      if (!has[0][i] || !has[1][j] || !has[2][k]) continue;
      if (g[0][i] + g[1][j] + g[2][k] > scanner.limit2()) continue;
      const double cell_lo[3] = {box_lo[0][i], box_lo[1][j], box_lo[2][k]};
      const double cell_hi[3] = {box_hi[0][i], box_hi[1][j], box_hi[2][k]};
      visit_cell(ci[0] + o[0], ci[1] + o[1], ci[2] + o[2], cell_lo, cell_hi);
    }
  };
  int64_t done = 0;  // cells within this Chebyshev radius of ci are visited
  int64_t cells = ball_box();
  if (cells > 27) {
    visit_neighbours();
    done = 1;
    cells = ball_box();
  }
  if (cells <= kMaxBoxCells) {
    visit_box(done);
    return;
  }

  double whole_lo[3], whole_hi[3];
  double outside2 = 0;
  for (int a = 0; a < 3; ++a) {
    whole_lo[a] = CellLo(0, a), whole_hi[a] = CellHi(dims_[a] - 1, a);
    outside2 += gap2(c[a], whole_lo[a], whole_hi[a]);
  }

  // 3. Far from the grid, shells would sweep every cell: visit blocks of cells instead, nearest
  //    first by the tight bounds of their samples, until the next block is farther than the best.
  //    Scanners that test boxes (next's candidates) always take this path for large balls: a
  //    block lying wholly behind the foot is skipped whole, so a large tolerance with no
  //    candidate costs a pass over the blocks, not over every cell.
  if (Scanner::kUsesBox || outside2 > 16 * cell_size_ * cell_size_) {
    thread_local std::vector<std::pair<double, uint32_t>> order;
    order.clear();
    const size_t blocks = size_t{block_dims_[0]} * block_dims_[1] * block_dims_[2];
    for (size_t b = 0; b < blocks; ++b) {
      const float* bb = &block_bounds_[6 * b];
      if (!(bb[0] <= bb[3])) continue;  // empty
      const double d2 =
          gap2(c[0], bb[0], bb[3]) + gap2(c[1], bb[1], bb[4]) + gap2(c[2], bb[2], bb[5]);
      if (d2 > scanner.limit2()) continue;
      if (Scanner::kUsesBox) {
        if (!scanner.KeepBlock(bb)) continue;
        const double lo[3] = {bb[0] - pad, bb[1] - pad, bb[2] - pad};
        const double hi[3] = {bb[3] + pad, bb[4] + pad, bb[5] + pad};
        if (!scanner.KeepCell(lo, hi)) continue;
      }
      order.emplace_back(d2, static_cast<uint32_t>(b));
    }
    std::sort(order.begin(), order.end());
    for (const auto& [d2, b] : order) {
      if (d2 > scanner.limit2()) break;
      const int64_t bi = b % block_dims_[0], bj = (b / block_dims_[0]) % block_dims_[1],
                    bk = b / (size_t{block_dims_[0]} * block_dims_[1]);
      for (int64_t k = bk * kBlockCells; k < std::min<int64_t>(n[2], (bk + 1) * kBlockCells); ++k) {
        const double gk =
            gap2(c[2], CellLo(static_cast<uint32_t>(k), 2), CellHi(static_cast<uint32_t>(k), 2));
        if (gk > scanner.limit2()) continue;
        for (int64_t j = bj * kBlockCells; j < std::min<int64_t>(n[1], (bj + 1) * kBlockCells);
             ++j) {
          const double gjk = gk + gap2(c[1], CellLo(static_cast<uint32_t>(j), 1),
                                       CellHi(static_cast<uint32_t>(j), 1));
          if (gjk > scanner.limit2()) continue;
          for (int64_t i = bi * kBlockCells; i < std::min<int64_t>(n[0], (bi + 1) * kBlockCells);
               ++i) {
            if (gjk + gap2(c[0], CellLo(static_cast<uint32_t>(i), 0),
                           CellHi(static_cast<uint32_t>(i), 0)) >
                scanner.limit2())
              continue;
            visit(i, j, k);  // a cell visited before is scanned again: harmless, never better
          }
        }
      }
    }
    return;
  }

  // 4. Otherwise, shells of growing Chebyshev radius until no unvisited cell can matter.
  thread_local std::vector<double> axis_gap[3];
  for (int64_t r = done + 1;; ++r) {
    // Lower bound on the distance to any cell at radius >= r: the nearest of the slabs beyond
    // the shell on each side of each axis, within the whole grid box.
    double bound2 = kInf;
    bool any = false;
    for (int a = 0; a < 3; ++a) {
      double rest = 0;
      for (int b = 0; b < 3; ++b)
        if (b != a) rest += gap2(c[b], whole_lo[b], whole_hi[b]);
      if (ci[a] + r <= n[a] - 1) {
        any = true;
        bound2 = std::min(
            bound2, rest + gap2(c[a], CellLo(static_cast<uint32_t>(ci[a] + r), a), whole_hi[a]));
      }
      if (ci[a] - r >= 0) {
        any = true;
        bound2 = std::min(
            bound2, rest + gap2(c[a], whole_lo[a], CellHi(static_cast<uint32_t>(ci[a] - r), a)));
      }
    }
    // Done when no cell is left, or none can hold a better sample. (Squared distances of
    // queries near the limits of double overflow to infinity: then only running out of cells
    // ends the search, and every sample ties.)
    if (!any || bound2 > scanner.limit2()) return;
    int64_t lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max<int64_t>(0, ci[a] - r), hi[a] = std::min(n[a] - 1, ci[a] + r);
      axis_gap[a].resize(static_cast<size_t>(hi[a] - lo[a] + 1));
      for (int64_t t = lo[a]; t <= hi[a]; ++t) {
        axis_gap[a][t - lo[a]] =
            gap2(c[a], CellLo(static_cast<uint32_t>(t), a), CellHi(static_cast<uint32_t>(t), a));
      }
    }
    for (int64_t k = lo[2]; k <= hi[2]; ++k) {
      const bool kface = k == ci[2] - r || k == ci[2] + r;
      const double gk = axis_gap[2][k - lo[2]];
      if (gk > scanner.limit2()) continue;
      for (int64_t j = lo[1]; j <= hi[1]; ++j) {
        const bool jface = j == ci[1] - r || j == ci[1] + r;
        const double gjk = gk + axis_gap[1][j - lo[1]];
        if (gjk > scanner.limit2()) continue;
        // Off the y and z faces, only the two x faces belong to the shell.
        const int64_t step = (kface || jface) ? 1 : 2 * r;
        for (int64_t i = (kface || jface) ? lo[0] : ci[0] - r; i <= hi[0]; i += step) {
          if (i < lo[0]) continue;
          if (gjk + axis_gap[0][i - lo[0]] > scanner.limit2()) continue;
          visit(i, j, k);
        }
      }
    }
  }
}

// Scanners come in a traced and an untraced flavour, so the untraced scan loop has no test.
template <bool kTraced>
struct TerrainGrid::SnapScanner {
  const TerrainGrid& grid;
  const double* q;
  QueryTrace* trace;
  double best_d2 = kInf;
  uint32_t best_cell = kNoIndex;
  uint32_t best_slot = kNoIndex;

  static constexpr bool kUsesBox = false;
  double limit2() const { return best_d2; }
  bool KeepCell(const double*, const double*) const { return true; }
  bool KeepBlock(const float*) const { return true; }
  void Scan(uint32_t cell, uint32_t b, uint32_t e) {
    if (kTraced) {
      trace->cells.push_back(cell);
      for (uint32_t s = b; s < e; ++s) trace->examined_samples.push_back(grid.answers_[s].index);
    }
    const uint32_t before = best_slot;
    detail::ScanCellNearest(
        grid.positions_ + 3 * size_t{b}, b, e - b, q,
        [this](uint32_t s) { return grid.answers_[s].index; }, &best_d2, &best_slot);
    // The answer's normal and index are stored apart: start loading them while the search goes
    // on (usually the first cell's best is the answer).
    if (best_slot != before) best_cell = cell, __builtin_prefetch(&grid.answers_[best_slot]);
  }
};

template <bool kTraced>
struct TerrainGrid::NextScanner {
  const TerrainGrid& grid;
  const detail::NextFrame* f;
  QueryTrace* trace;
  double best_d2;
  uint32_t best_cell = kNoIndex;
  uint32_t best_slot = kNoIndex;

  static constexpr bool kUsesBox = true;
  double limit2() const { return best_d2; }
  // Skips a cell lying wholly behind the foot: its farthest corner along dir is not ahead
  // (exact, as AheadBy is monotonic; the padded box holds every sample of the cell).
  bool KeepCell(const double* lo, const double* hi) const {
    double corner[3];
    for (int a = 0; a < 3; ++a) corner[a] = f->dir[a] > 0 ? hi[a] : lo[a];
    return detail::AheadBy(corner, *f) > 0;
  }
  // Skips a block whose samples all lie behind the foot or level with it, from the tight bounds
  // of its samples: the corner farthest along dir, computed as Ahead computes a sample's, is
  // not ahead. (Rounding is monotonic, so no sample of the block computes farther ahead than
  // that corner: exact, with no pad. A foot on flat ground stepping straight up with a large
  // tolerance skips every block instead of scanning every sample.)
  bool KeepBlock(const float* bb) const {
    float corner[3];
    for (int a = 0; a < 3; ++a) corner[a] = f->dir[a] > 0 ? bb[3 + a] : bb[a];
    return detail::Ahead(corner, *f);
  }
  void Scan(uint32_t cell, uint32_t b, uint32_t e) {
    if (kTraced) trace->cells.push_back(cell);
    const float* x = grid.positions_ + 3 * size_t{b};
    const uint32_t count = e - b;
    for (uint32_t i = 0; i < count; ++i) {
      const float p[3] = {x[i], x[count + i], x[2 * size_t{count} + i]};
      const uint32_t slot = b + i;
      const double d2 = detail::Dist2(p, f->ideal);
      if (kTraced) trace->examined_samples.push_back(grid.answers_[slot].index);
      if (d2 > f->radius2 || !detail::Ahead(p, *f)) continue;
      if (kTraced) trace->candidates.push_back(grid.answers_[slot].index);
      // Source indices are read only on an exact tie.
      if (d2 < best_d2 ||
          (d2 == best_d2 &&
           (best_slot == kNoIndex || grid.answers_[slot].index < grid.answers_[best_slot].index)))
        best_d2 = d2, best_cell = cell, best_slot = slot;
    }
  }
};

Foothold TerrainGrid::MakeFoothold(uint32_t cell, uint32_t slot) const {
  Foothold f;
  f.status = Status::kOk;
  f.index = answers_[slot].index;
  float p[3];
  LocalPoint(cell, slot, p);
  const float* nv = answers_[slot].normal;
  f.point = {origin_[0] + p[0], origin_[1] + p[1], origin_[2] + p[2]};
  f.normal = {nv[0], nv[1], nv[2]};
  return f;
}

inline void TerrainGrid::PrefetchRow(int64_t cell, const int64_t ci[3]) const {
  const int64_t row = cell - ci[0];
  const uint32_t b = cell_start_[std::max<int64_t>(cell - 1, row)];
  const uint32_t e = cell_start_[std::min<int64_t>(cell + 1, row + dims_[0] - 1) + 1];
  for (size_t f = 3 * size_t{b} & ~size_t{15}; f < 3 * size_t{e}; f += 16)
    __builtin_prefetch(positions_ + f);
  const uint32_t own_e = cell_start_[cell + 1];
  for (size_t s = cell_start_[cell] & ~size_t{3}; s < own_e; s += 4)
    __builtin_prefetch(&answers_[s]);
}

// The body of TerrainGrid::NearestNearby, compiled twice: portable, and for AVX2 where the
// compiler offers it (the cell scans then take four samples per instruction).
struct NearbySearch {
#if defined(__GNUC__)
  __attribute__((always_inline))
#endif
  static inline bool
  Run(const TerrainGrid& g, const double c[3], bool prefetched, uint32_t* cell_out,
      uint32_t* slot_out) {
    if (g.count_ == 0) return false;
    int64_t ci[3];
    const int64_t cell = g.ClampedCell(c, ci);
    const int64_t stride[3] = {1, g.dims_[0], int64_t{g.dims_[0]} * g.dims_[1]};
    double best = kInf;
    uint32_t best_slot = kNoIndex;
    int64_t best_cell = cell;
    auto index_of = [&g](uint32_t s) { return g.answers_[s].index; };
    auto scan = [&](int64_t at) {
      const uint32_t b = g.cell_start_[at], e = g.cell_start_[at + 1];
      const uint32_t before = best_slot;
      detail::ScanCellNearest(g.positions_ + 3 * size_t{b}, b, e - b, c, index_of, &best,
                              &best_slot);
      if (best_slot != before) best_cell = at, __builtin_prefetch(&g.answers_[best_slot]);
    };
    // Before the first scan, start loading the row around the query's cell and the cell's
    // answers, so that the misses of the neighbours the ball reaches and of the answer overlap
    // instead of following one another (terrain not in cache: single snaps and steps 15-25%
    // faster; queries on cells already in cache pay ~90 instructions, ~10%). A batch has
    // started that already.
    if (!prefetched) g.PrefetchRow(cell, ci);
    scan(cell);
    // An empty own cell: every neighbour is visited, and the ball is checked afterwards.
    const bool own_empty = best_slot == kNoIndex;
    if (!own_empty && !(best < kInf)) return false;
    // Per axis, the squared gaps to the lower and upper neighbours the ball reaches (padded as in
    // Search). A ball reaching two cells away is left to Search.
    const double pad = g.pad_ + 1e-13 * (std::fabs(c[0]) + std::fabs(c[1]) + std::fabs(c[2]));
    double gap[3][2], far[3][2];
    int64_t step[3][2];
    int sides[3];
    auto reaches_two_away = [&]() {
      for (int a = 0; a < 3; ++a) {
        if (ci[a] >= 2 && (far[a][0] <= 0 || far[a][0] * far[a][0] <= best)) return true;
        if (ci[a] + 2 < g.dims_[a] && (far[a][1] <= 0 || far[a][1] * far[a][1] <= best))
          return true;
      }
      return false;
    };
    // Per axis, the padded distances to the own cell's lower and upper faces. Most often the
    // ball stays within the own cell: then no neighbour (nor any cell two away) can hold a
    // nearer sample, and the answer is known.
    double to_lo[3], to_hi[3];
    bool inside = !own_empty;
    for (int a = 0; a < 3; ++a) {
      const double face = g.grid_lo_[a] + static_cast<double>(ci[a]) * g.cell_size_;
      to_lo[a] = c[a] - face - pad, to_hi[a] = face + g.cell_size_ - c[a] - pad;
      inside &= std::min(to_lo[a], to_hi[a]) > 0 &&
                std::min(to_lo[a] * to_lo[a], to_hi[a] * to_hi[a]) > best;
    }
    if (inside) {
      *cell_out = static_cast<uint32_t>(best_cell);
      *slot_out = best_slot;
      return true;
    }
    for (int a = 0; a < 3; ++a) {
      const double dlo = to_lo[a], dhi = to_hi[a];
      far[a][0] = dlo + g.cell_size_, far[a][1] = dhi + g.cell_size_;
      sides[a] = 0;
      const double glo = dlo > 0 ? dlo * dlo : 0, ghi = dhi > 0 ? dhi * dhi : 0;
      if (ci[a] >= 1 && glo <= best) gap[a][sides[a]] = glo, step[a][sides[a]++] = -stride[a];
      if (ci[a] + 1 < g.dims_[a] && ghi <= best)
        gap[a][sides[a]] = ghi, step[a][sides[a]++] = stride[a];
    }
    // The ball of the own cell's nearest bounds the search: when it reaches two cells away, so
    // might the answer.
    if (!own_empty) {
      // No neighbour within the ball (at the grid's border): none two away either.
      if (sides[0] + sides[1] + sides[2] == 0) {
        *cell_out = static_cast<uint32_t>(best_cell);
        *slot_out = best_slot;
        return true;
      }
      if (reaches_two_away()) return false;
    }
    // Faces, then edges, then corners: the nearer neighbours usually shrink the ball first.
    for (int a = 0; a < 3; ++a)
      for (int s = 0; s < sides[a]; ++s)
        if (gap[a][s] <= best) scan(cell + step[a][s]);
    for (int a = 0; a < 3; ++a) {
      const int b = a == 2 ? 0 : a + 1;
      for (int s = 0; s < sides[a]; ++s)
        for (int t = 0; t < sides[b]; ++t)
          if (gap[a][s] + gap[b][t] <= best) scan(cell + step[a][s] + step[b][t]);
    }
    for (int s = 0; s < sides[0]; ++s)
      for (int t = 0; t < sides[1]; ++t)
        for (int u = 0; u < sides[2]; ++u)
          if (gap[0][s] + gap[1][t] + gap[2][u] <= best)
            scan(cell + step[0][s] + step[1][t] + step[2][u]);
    if (own_empty && (best_slot == kNoIndex || !(best < kInf) || reaches_two_away())) return false;
    *cell_out = static_cast<uint32_t>(best_cell);
    *slot_out = best_slot;
    return true;
  }
};

namespace {

#if defined(__x86_64__) && defined(__GNUC__)
#define FOOTFALL_AVX2_SCAN 1
__attribute__((target("avx2"))) bool NearbyAvx2(const TerrainGrid& g, const double c[3],
                                                bool prefetched, uint32_t* cell, uint32_t* slot) {
  return NearbySearch::Run(g, c, prefetched, cell, slot);
}
#endif

bool NearbyPortable(const TerrainGrid& g, const double c[3], bool prefetched, uint32_t* cell,
                    uint32_t* slot) {
  return NearbySearch::Run(g, c, prefetched, cell, slot);
}

}  // namespace

bool CpuHasAvx2() {
#ifdef FOOTFALL_AVX2_SCAN
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

bool TerrainGrid::NearestNearby(const double c[3], bool prefetched, uint32_t* cell,
                                uint32_t* slot) const {
#ifdef FOOTFALL_AVX2_SCAN
  if (avx2_) return NearbyAvx2(*this, c, prefetched, cell, slot);
#endif
  return NearbyPortable(*this, c, prefetched, cell, slot);
}

TerrainGrid::Located TerrainGrid::LocateSnap(const Vec3& q, bool prefetched,
                                             QueryTrace* trace) const {
  Located found;  // kInvalidArgument
  const double c[3] = {q.x - origin_[0], q.y - origin_[1], q.z - origin_[2]};
  if (!detail::InQueryRange(c)) return found;  // NaN and infinities too
  found.status = Status::kNoFoothold;
  if (trace) {
    *trace = QueryTrace{}, trace->ideal = q;
    SnapScanner<true> s{*this, c, trace};
    Search(c, s);
    found.cell = s.best_cell, found.slot = s.best_slot;
  } else if (!NearestNearby(c, prefetched, &found.cell, &found.slot)) {
    SnapScanner<false> s{*this, c, nullptr};
    Search(c, s);
    found.cell = s.best_cell, found.slot = s.best_slot;
  }
  if (found.slot != kNoIndex) found.status = Status::kOk;
  return found;
}

TerrainGrid::Located TerrainGrid::LocateNext(const StepQuery& q, double tolerance, bool prefetched,
                                             QueryTrace* trace) const {
  Located found;  // kInvalidArgument
  detail::NextFrame f;
  if (!detail::MakeNextFrame(origin_, q, tolerance, &f)) return found;
  found.status = Status::kNoFoothold;
  if (trace) {
    *trace = QueryTrace{};
    trace->ideal = q.foot + q.direction;
    trace->radius = std::sqrt(f.radius2);
    NextScanner<true> s{*this, &f, trace, f.radius2};
    Search(f.ideal, s);
    found.cell = s.best_cell, found.slot = s.best_slot;
  } else {
    // The sample nearest the ideal point, if it is a candidate, is the nearest candidate (same
    // distances, same tie order); if it is beyond the radius, no sample is a candidate. Only
    // when it lies behind the foot does the candidate search run.
    if (!NearestNearby(f.ideal, prefetched, &found.cell, &found.slot)) {
      SnapScanner<false> s{*this, f.ideal, nullptr};
      Search(f.ideal, s);
      found.cell = s.best_cell, found.slot = s.best_slot;
    }
    if (found.slot == kNoIndex) return found;
    float p[3];
    LocalPoint(found.cell, found.slot, p);
    if (detail::Dist2(p, f.ideal) > f.radius2) {
      found.slot = kNoIndex;
      return found;
    }
    if (!detail::Ahead(p, f)) {
      NextScanner<false> s{*this, &f, nullptr, f.radius2};
      Search(f.ideal, s);
      found.cell = s.best_cell, found.slot = s.best_slot;
    }
  }
  if (found.slot != kNoIndex) found.status = Status::kOk;
  return found;
}

Foothold TerrainGrid::Answer(const Located& found) const {
  if (found.status != Status::kOk) {
    Foothold none;
    none.status = found.status;
    return none;
  }
  return MakeFoothold(found.cell, found.slot);
}

Foothold TerrainGrid::Snap(const Vec3& q, QueryTrace* trace) const {
  return Answer(LocateSnap(q, false, trace));
}

Foothold TerrainGrid::Next(const StepQuery& q, double tolerance, QueryTrace* trace) const {
  return Answer(LocateNext(q, tolerance, false, trace));
}

void TerrainGrid::Prefetch(const Vec3& q, bool samples) const {
  const double c[3] = {q.x - origin_[0], q.y - origin_[1], q.z - origin_[2]};
  int64_t ci[3];
  const int64_t cell = ClampedCell(c, ci);
  if (!samples) {
    __builtin_prefetch(&cell_start_[cell]);
    return;
  }
  const size_t b = cell_start_[cell], e = cell_start_[cell + 1];
  __builtin_prefetch(positions_ + 3 * b);
  if (e > b) __builtin_prefetch(positions_ + 3 * e - 1);  // the run's last line
}

template <typename Ideal, typename Locate>
void TerrainGrid::AnswerBatch(size_t count, Foothold* out, BatchPool* pool, const Ideal& ideal,
                              const Locate& locate) const {
  auto answer = [&](size_t b, size_t e) {
    Located found[kAnswerLag];
    for (size_t g = b; g < e; g += kAnswerLag) {
      const size_t n = std::min(kAnswerLag, e - g);
      for (size_t i = g; i < g + n; ++i) {
        if (i + 2 * kPrefetchDistance < e) Prefetch(ideal(i + 2 * kPrefetchDistance), false);
        if (i + kPrefetchDistance < e) Prefetch(ideal(i + kPrefetchDistance), true);
        found[i - g] = locate(i);
      }
      for (size_t i = 0; i < n; ++i) out[g + i] = Answer(found[i]);
    }
  };
  if (pool)
    pool->Run(count, BatchPool::kQueryChunk, answer);
  else
    answer(0, count);
}

void TerrainGrid::SnapBatch(const Vec3* queries, size_t count, Foothold* out,
                            BatchPool* pool) const {
  AnswerBatch(
      count, out, pool, [&](size_t i) { return queries[i]; },
      [&](size_t i) { return LocateSnap(queries[i], true, nullptr); });
}

void TerrainGrid::NextBatch(const StepQuery* queries, size_t count, double tolerance, Foothold* out,
                            BatchPool* pool) const {
  AnswerBatch(
      count, out, pool, [&](size_t i) { return queries[i].foot + queries[i].direction; },
      [&](size_t i) { return LocateNext(queries[i], tolerance, true, nullptr); });
}

void TerrainGrid::CellBox(uint32_t cell, Vec3* lo, Vec3* hi) const {
  const uint32_t i = cell % dims_[0], j = (cell / dims_[0]) % dims_[1],
                 k = cell / (dims_[0] * dims_[1]);
  *lo = {origin_[0] + CellLo(i, 0), origin_[1] + CellLo(j, 1), origin_[2] + CellLo(k, 2)};
  *hi = {origin_[0] + CellHi(i, 0), origin_[1] + CellHi(j, 1), origin_[2] + CellHi(k, 2)};
}

std::vector<uint32_t> TerrainGrid::OccupiedCells() const {
  std::vector<uint32_t> cells;
  if (count_ == 0) return cells;
  const size_t total = size_t{dims_[0]} * dims_[1] * dims_[2];
  for (size_t c = 0; c < total; ++c)
    if (cell_start_[c + 1] > cell_start_[c]) cells.push_back(static_cast<uint32_t>(c));
  return cells;
}

}  // namespace footfall
