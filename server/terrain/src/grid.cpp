#include "footfall/terrain/grid.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "cell_scan.h"
#include "footfall/terrain/batch_pool.h"
#include "query_math.h"

namespace footfall {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kNoIndex = std::numeric_limits<uint32_t>::max();
// Batches start loading a query's cell offsets this many queries ahead, then its samples half
// as far ahead.
constexpr size_t kPrefetchDistance = 6;
// Batches find the answers of this many queries before reading their normals and indices, which
// were prefetched meanwhile.
constexpr size_t kAnswerLag = 8;
// Cells per axis of a block, the coarse level used for queries far from the grid.
constexpr uint32_t kBlockCells = 8;

// The 26 neighbours of a cell as offsets: faces, then edges, then corners.
constexpr int kNeighbourOrder[26][3] = {
    {-1, 0, 0},  {1, 0, 0},   {0, -1, 0}, {0, 1, 0},   {0, 0, -1},   {0, 0, 1},   {-1, -1, 0},
    {1, -1, 0},  {-1, 1, 0},  {1, 1, 0},  {-1, 0, -1}, {1, 0, -1},   {-1, 0, 1},  {1, 0, 1},
    {0, -1, -1}, {0, 1, -1},  {0, -1, 1}, {0, 1, 1},   {-1, -1, -1}, {1, -1, -1}, {-1, 1, -1},
    {1, 1, -1},  {-1, -1, 1}, {1, -1, 1}, {-1, 1, 1},  {1, 1, 1}};

// Total cells for a cell size h over local extents e, saturating in double.
double CellCount(const double e[3], double h) {
  double total = 1;
  for (int a = 0; a < 3; ++a) total *= std::max(1.0, std::ceil(e[a] / h));
  return total;
}

uint32_t AxisCells(double extent, double h) {
  return static_cast<uint32_t>(std::max(1.0, std::ceil(extent / h)));
}

// Picks the grid box per axis: the true bounds, unless a few far outliers stretch an axis to
// more than 4 times its bulk (1st to 99th percentile of a subsample), then the bulk plus margin.
void ChooseGridBox(const RawSamples& s, const double lo[3], const double hi[3], double glo[3],
                   double ghi[3]) {
  const size_t n = s.size();
  for (int a = 0; a < 3; ++a) glo[a] = lo[a], ghi[a] = hi[a];
  if (n < 64) return;
  const size_t m = std::min<size_t>(n, 4096);
  std::vector<double> v(m);
  for (int a = 0; a < 3; ++a) {
    for (size_t i = 0; i < m; ++i) {
      const Vec3& p = s.points[i * n / m];
      v[i] = a == 0 ? p.x : a == 1 ? p.y : p.z;
    }
    std::sort(v.begin(), v.end());
    const double q_lo = v[(m - 1) / 100];
    const double q_hi = v[(m - 1) - (m - 1) / 100];
    const double bulk = q_hi - q_lo;
    if (hi[a] - lo[a] > 4 * bulk) {
      const double margin = 0.25 * bulk;
      glo[a] = std::max(lo[a], q_lo - margin);
      ghi[a] = std::min(hi[a], q_hi + margin);
    }
  }
}

// The grid's single allocation. Large grids are aligned to 2 MiB and marked for transparent
// huge pages where the system offers them (Linux, madvise mode): random queries over a grid of
// tens of megabytes otherwise spend much of their time in TLB misses. Throws std::bad_alloc.
unsigned char* AllocateGridMemory(size_t bytes) {
  constexpr size_t kHugePage = size_t{2} << 20;
  bytes = std::max<size_t>(bytes, 1);
  void* p = nullptr;
  if (bytes < kHugePage) {
    p = std::malloc(bytes);
  } else {
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    p = std::aligned_alloc(kHugePage, rounded);
#ifdef MADV_HUGEPAGE
    if (p) madvise(p, rounded, MADV_HUGEPAGE);
#endif
  }
  if (!p) throw std::bad_alloc();
  return static_cast<unsigned char*>(p);
}

}  // namespace

void TerrainGrid::FreeMemory::operator()(unsigned char* p) const { std::free(p); }

const char* StatusName(Status status) {
  switch (status) {
    case Status::kOk:
      return "ok";
    case Status::kNoFoothold:
      return "no_foothold";
    case Status::kInvalidArgument:
      return "invalid_argument";
    case Status::kUnknownTerrain:
      return "unknown_terrain";
    case Status::kLimitExceeded:
      return "limit_exceeded";
    case Status::kIoError:
      return "io_error";
    case Status::kParseError:
      return "parse_error";
    case Status::kAccessDenied:
      return "access_denied";
    case Status::kUnavailable:
      return "unavailable";
    case Status::kInternalError:
      return "internal_error";
  }
  return "unknown_status";
}

TerrainGrid::TerrainGrid() = default;
TerrainGrid::~TerrainGrid() = default;
TerrainGrid::TerrainGrid(TerrainGrid&&) noexcept = default;
TerrainGrid& TerrainGrid::operator=(TerrainGrid&&) noexcept = default;

Status TerrainGrid::Build(const RawSamples& samples, const GridOptions& options, TerrainGrid* out,
                          std::string* error) {
  const size_t n = samples.points.size();
  if (samples.normals.size() != n) {
    if (error) *error = "points and normals differ in count";
    return Status::kInvalidArgument;
  }
  if (n > 0xFFFFFFFEull) {
    if (error) *error = "too many samples (limit 4294967294)";
    return Status::kLimitExceeded;
  }
  if (!(options.samples_per_cell > 0) || !(options.cells_per_sample > 0)) {
    if (error) *error = "grid options must be positive";
    return Status::kInvalidArgument;
  }
  TerrainGrid g;
  g.count_ = n;
  // 1. True bounds, checking every value.
  double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = samples.points[i];
    if (!IsFinite(p) || !IsFinite(samples.normals[i])) {
      if (error) *error = "sample " + std::to_string(i) + " is not finite";
      return Status::kInvalidArgument;
    }
    const double c[3] = {p.x, p.y, p.z};
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
  }
  if (n == 0) {
    for (int a = 0; a < 3; ++a) lo[a] = hi[a] = 0;
  }
  // 2. The box the cells divide, and the origin at its centre.
  double glo[3], ghi[3];
  ChooseGridBox(samples, lo, hi, glo, ghi);
  double extent[3];
  for (int a = 0; a < 3; ++a) {
    g.origin_[a] = 0.5 * (glo[a] + ghi[a]);
    g.grid_lo_[a] = glo[a] - g.origin_[a];
    extent[a] = ghi[a] - glo[a];
  }
  // 3. Positions as float offsets from the origin; bounds recomputed from the stored values.
  std::vector<float> local(3 * n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = samples.points[i];
    local[3 * i + 0] = static_cast<float>(p.x - g.origin_[0]);
    local[3 * i + 1] = static_cast<float>(p.y - g.origin_[1]);
    local[3 * i + 2] = static_cast<float>(p.z - g.origin_[2]);
  }
  for (int a = 0; a < 3; ++a) g.bounds_lo_[a] = kInf, g.bounds_hi_[a] = -kInf;
  for (size_t i = 0; i < 3 * n; ++i) {
    const int a = static_cast<int>(i % 3);
    g.bounds_lo_[a] = std::min(g.bounds_lo_[a], static_cast<double>(local[i]));
    g.bounds_hi_[a] = std::max(g.bounds_hi_[a], static_cast<double>(local[i]));
  }
  if (n == 0) {
    for (int a = 0; a < 3; ++a) g.bounds_lo_[a] = g.bounds_hi_[a] = 0;
  }
  // 4. Cell size: the smallest that fits the memory cap, then grown until occupied cells hold
  //    about options.samples_per_cell samples (a surface's occupancy falls as 1/h^2).
  const double budget = std::max(64.0, options.cells_per_sample * static_cast<double>(n));
  const double max_extent = std::max({extent[0], extent[1], extent[2]});
  double h = 1;
  if (max_extent > 0) {
    double h_hi = max_extent, h_lo = max_extent / (budget + 1);
    for (int it = 0; it < 100 && h_hi > h_lo * (1 + 1e-12); ++it) {
      const double mid = std::sqrt(h_lo * h_hi);
      (CellCount(extent, mid) <= budget ? h_hi : h_lo) = mid;
    }
    h = h_hi;
    g.cell_size_ = h, g.inv_cell_size_ = 1 / h;
    for (int a = 0; a < 3; ++a) g.dims_[a] = AxisCells(extent[a], h);
    const size_t total = size_t{g.dims_[0]} * g.dims_[1] * g.dims_[2];
    std::vector<bool> occupied(total, false);
    size_t occupied_count = 0;
    for (size_t i = 0; i < n; ++i) {
      const float* p = &local[3 * i];
      const size_t cell =
          (size_t{g.CellCoord(p[2], 2)} * g.dims_[1] + g.CellCoord(p[1], 1)) * g.dims_[0] +
          g.CellCoord(p[0], 0);
      if (!occupied[cell]) occupied[cell] = true, ++occupied_count;
    }
    const double per_cell = static_cast<double>(n) / std::max<size_t>(1, occupied_count);
    if (per_cell < options.samples_per_cell) h *= std::sqrt(options.samples_per_cell / per_cell);
  }
  g.cell_size_ = h, g.inv_cell_size_ = 1 / h;
  for (int a = 0; a < 3; ++a) g.dims_[a] = AxisCells(extent[a], h);
  for (int a = 0; a < 3; ++a) g.last_cell_[a] = g.dims_[a] - 1.0;
  const size_t cells = size_t{g.dims_[0]} * g.dims_[1] * g.dims_[2];
  g.cells_ = cells;
  g.avx2_ = options.use_avx2 && CpuHasAvx2();
  // Cell boxes are padded so that rounding can never prune a sample: in cell assignment
  // (relative to the grid's extent) and in distances (relative to the query's, added per query).
  g.pad_ = 1e-9 * (h + (g.bounds_hi_[0] - g.bounds_lo_[0]) + (g.bounds_hi_[1] - g.bounds_lo_[1]) +
                   (g.bounds_hi_[2] - g.bounds_lo_[2]));

  // 5. Counting sort of samples by cell, stable in source index (so ties scan in index order).
  std::vector<uint32_t> cell_of(n);
  for (size_t i = 0; i < n; ++i) {
    const float* p = &local[3 * i];
    cell_of[i] = static_cast<uint32_t>(
        (size_t{g.CellCoord(p[2], 2)} * g.dims_[1] + g.CellCoord(p[1], 1)) * g.dims_[0] +
        g.CellCoord(p[0], 0));
  }
  for (int a = 0; a < 3; ++a) g.block_dims_[a] = (g.dims_[a] + kBlockCells - 1) / kBlockCells;
  const size_t blocks = size_t{g.block_dims_[0]} * g.block_dims_[1] * g.block_dims_[2];
  // Positions end with 4 spare floats: a cell scan loads 4 samples at a time.
  const size_t position_floats = 3 * n + 4;
  const size_t bytes = n * sizeof(SampleAnswer) + (cells + 1) * sizeof(uint32_t) +
                       blocks * 6 * sizeof(float) + position_floats * sizeof(float);
  g.memory_.reset(AllocateGridMemory(bytes));
  SampleAnswer* answers = reinterpret_cast<SampleAnswer*>(g.memory_.get());
  uint32_t* cell_start = reinterpret_cast<uint32_t*>(answers + n);
  float* block_bounds = reinterpret_cast<float*>(cell_start + cells + 1);
  float* positions = block_bounds + blocks * 6;
  std::fill(cell_start, cell_start + cells + 1, 0u);
  for (size_t i = 0; i < n; ++i) ++cell_start[cell_of[i] + 1];
  for (size_t c = 0; c < cells; ++c) cell_start[c + 1] += cell_start[c];
  size_t occupied_cells = 0;
  for (size_t c = 0; c < cells; ++c) occupied_cells += cell_start[c + 1] > cell_start[c];
  {
    std::vector<uint32_t> cursor(cell_start, cell_start + cells);
    for (size_t i = 0; i < n; ++i) {
      const uint32_t cell = cell_of[i];
      const uint32_t first = cell_start[cell], count = cell_start[cell + 1] - first;
      const uint32_t slot = cursor[cell]++;
      float* x = positions + 3 * size_t{first} + (slot - first);
      x[0] = local[3 * i], x[count] = local[3 * i + 1], x[2 * size_t{count}] = local[3 * i + 2];
      const Vec3& nv = samples.normals[i];
      const double len = Length(nv);
      const double inv = len > 0 ? 1 / len : 0;
      answers[slot].normal[0] = static_cast<float>(nv.x * inv);
      answers[slot].normal[1] = static_cast<float>(nv.y * inv);
      answers[slot].normal[2] = static_cast<float>(nv.z * inv);
      answers[slot].index = static_cast<uint32_t>(i);
    }
    std::fill(positions + 3 * n, positions + position_floats, 0.0f);
  }
  g.positions_ = positions;
  g.answers_ = answers;
  g.cell_start_ = cell_start;
  // 6. Tight bounds of the samples of each block of cells, for queries far from the grid.
  for (size_t b = 0; b < blocks; ++b) {
    for (int a = 0; a < 3; ++a) {
      block_bounds[6 * b + a] = std::numeric_limits<float>::infinity();
      block_bounds[6 * b + 3 + a] = -std::numeric_limits<float>::infinity();
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const float* p = &local[3 * i];
    const size_t b = (size_t{g.CellCoord(p[2], 2) / kBlockCells} * g.block_dims_[1] +
                      g.CellCoord(p[1], 1) / kBlockCells) *
                         g.block_dims_[0] +
                     g.CellCoord(p[0], 0) / kBlockCells;
    for (int a = 0; a < 3; ++a) {
      block_bounds[6 * b + a] = std::min(block_bounds[6 * b + a], p[a]);
      block_bounds[6 * b + 3 + a] = std::max(block_bounds[6 * b + 3 + a], p[a]);
    }
  }
  g.block_bounds_ = block_bounds;

  GridStats& st = g.stats_;
  st.samples = n;
  for (int a = 0; a < 3; ++a) st.cells[a] = g.dims_[a];
  st.cell_size = h;
  st.occupied_cells = occupied_cells;
  st.bytes = bytes;
  const double* o = g.origin_;
  st.bounds_min = {o[0] + g.bounds_lo_[0], o[1] + g.bounds_lo_[1], o[2] + g.bounds_lo_[2]};
  st.bounds_max = {o[0] + g.bounds_hi_[0], o[1] + g.bounds_hi_[1], o[2] + g.bounds_hi_[2]};
  st.grid_min = {glo[0], glo[1], glo[2]};
  st.grid_max = {o[0] + g.grid_lo_[0] + g.dims_[0] * h, o[1] + g.grid_lo_[1] + g.dims_[1] * h,
                 o[2] + g.grid_lo_[2] + g.dims_[2] * h};
  *out = std::move(g);
  return Status::kOk;
}

int64_t TerrainGrid::ClampedCell(const double c[3], int64_t ci[3]) const {
  for (int a = 0; a < 3; ++a) {
    double t = (c[a] - grid_lo_[a]) * inv_cell_size_;
    t = t > 0 ? t : 0;  // NaN too
    t = t < last_cell_[a] ? t : last_cell_[a];
    ci[a] = static_cast<int64_t>(t);
  }
  return ci[0] + (ci[1] + ci[2] * int64_t{dims_[1]}) * dims_[0];
}

uint32_t TerrainGrid::CellCoord(double local, int axis) const {
  const double t = (local - grid_lo_[axis]) * inv_cell_size_;
  if (!(t > 0)) return 0;
  if (t >= static_cast<double>(dims_[axis])) return dims_[axis] - 1;
  return static_cast<uint32_t>(t);
}

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

  // 1b. The common case, cheaply: the best ball reaches at most the direct neighbours. Per
  //     axis, a neighbour is visited only if the ball crosses the face it shares with ci.
  if (scanner.limit2() < kInf) {
    const double limit = scanner.limit2();
    double gap[3][3];
    int64_t from[3], to[3];
    bool simple = true;
    for (int a = 0; a < 3 && simple; ++a) {
      const double face = grid_lo_[a] + static_cast<double>(ci[a]) * cell_size_;
      const double dlo = c[a] - face - pad;               // to the face with cell ci - 1
      const double dhi = face + cell_size_ - c[a] - pad;  // to the face with cell ci + 1
      const double beyond_lo = dlo + cell_size_, beyond_hi = dhi + cell_size_;
      if ((ci[a] >= 2 && (beyond_lo <= 0 || beyond_lo * beyond_lo <= limit)) ||
          (ci[a] <= n[a] - 3 && (beyond_hi <= 0 || beyond_hi * beyond_hi <= limit))) {
        simple = false;  // the ball may reach two cells away
        break;
      }
      gap[a][0] = dlo > 0 ? dlo * dlo : 0;
      gap[a][1] = 0;
      gap[a][2] = dhi > 0 ? dhi * dhi : 0;
      from[a] = ci[a] >= 1 && gap[a][0] <= limit ? -1 : 0;
      to[a] = ci[a] <= n[a] - 2 && gap[a][2] <= limit ? 1 : 0;
    }
    if (simple) {
      for (int64_t dk = from[2]; dk <= to[2]; ++dk) {
        for (int64_t dj = from[1]; dj <= to[1]; ++dj) {
          const double gjk = gap[2][dk + 1] + gap[1][dj + 1];
          if (gjk > scanner.limit2()) continue;
          for (int64_t di = from[0]; di <= to[0]; ++di) {
            if ((di | dj | dk) == 0) continue;
            if (gjk + gap[0][di + 1] > scanner.limit2()) continue;
            visit(ci[0] + di, ci[1] + dj, ci[2] + dk);
          }
        }
      }
      return;
    }
  }

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
  // Skips a cell lying wholly behind the foot: its farthest corner along dir is not ahead.
  bool KeepCell(const double* lo, const double* hi) const {
    double support = 0;
    for (int a = 0; a < 3; ++a) {
      const double d = f->dir[a];
      support += d * ((d > 0 ? hi[a] : lo[a]) - f->foot[a]);
    }
    return support > 0;  // the padded box absorbs rounding
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

// The body of TerrainGrid::NearestNearby, compiled twice: portable, and for AVX2 where the
// compiler offers it (the cell scans then take four samples per instruction).
struct NearbySearch {
#if defined(__GNUC__)
  __attribute__((always_inline))
#endif
  static inline bool
  Run(const TerrainGrid& g, const double c[3], uint32_t* cell_out, uint32_t* slot_out) {
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
    for (int a = 0; a < 3; ++a) {
      const double face = g.grid_lo_[a] + static_cast<double>(ci[a]) * g.cell_size_;
      const double dlo = c[a] - face - pad, dhi = face + g.cell_size_ - c[a] - pad;
      far[a][0] = dlo + g.cell_size_, far[a][1] = dhi + g.cell_size_;
      sides[a] = 0;
      const double glo = dlo > 0 ? dlo * dlo : 0, ghi = dhi > 0 ? dhi * dhi : 0;
      if (ci[a] >= 1 && glo <= best) gap[a][sides[a]] = glo, step[a][sides[a]++] = -stride[a];
      if (ci[a] + 1 < g.dims_[a] && ghi <= best)
        gap[a][sides[a]] = ghi, step[a][sides[a]++] = stride[a];
    }
    // The ball of the own cell's nearest bounds the search: when it reaches two cells away, so
    // might the answer.
    if (!own_empty && reaches_two_away()) return false;
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
                                                uint32_t* cell, uint32_t* slot) {
  return NearbySearch::Run(g, c, cell, slot);
}
#endif

bool NearbyPortable(const TerrainGrid& g, const double c[3], uint32_t* cell, uint32_t* slot) {
  return NearbySearch::Run(g, c, cell, slot);
}

}  // namespace

bool CpuHasAvx2() {
#ifdef FOOTFALL_AVX2_SCAN
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

bool TerrainGrid::NearestNearby(const double c[3], uint32_t* cell, uint32_t* slot) const {
#ifdef FOOTFALL_AVX2_SCAN
  if (avx2_) return NearbyAvx2(*this, c, cell, slot);
#endif
  return NearbyPortable(*this, c, cell, slot);
}

TerrainGrid::Located TerrainGrid::LocateSnap(const Vec3& q, QueryTrace* trace) const {
  Located found;  // kInvalidArgument
  if (!IsFinite(q)) return found;
  const double c[3] = {q.x - origin_[0], q.y - origin_[1], q.z - origin_[2]};
  if (!detail::InQueryRange(c)) return found;
  found.status = Status::kNoFoothold;
  if (trace) {
    *trace = QueryTrace{}, trace->ideal = q;
    SnapScanner<true> s{*this, c, trace};
    Search(c, s);
    found.cell = s.best_cell, found.slot = s.best_slot;
  } else if (!NearestNearby(c, &found.cell, &found.slot)) {
    SnapScanner<false> s{*this, c, nullptr};
    Search(c, s);
    found.cell = s.best_cell, found.slot = s.best_slot;
  }
  if (found.slot != kNoIndex) found.status = Status::kOk;
  return found;
}

TerrainGrid::Located TerrainGrid::LocateNext(const StepQuery& q, double tolerance,
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
    if (!NearestNearby(f.ideal, &found.cell, &found.slot)) {
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
  return Answer(LocateSnap(q, trace));
}

Foothold TerrainGrid::Next(const StepQuery& q, double tolerance, QueryTrace* trace) const {
  return Answer(LocateNext(q, tolerance, trace));
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

void TerrainGrid::SnapBatch(const Vec3* queries, size_t count, Foothold* out,
                            BatchPool* pool) const {
  auto answer = [&](size_t b, size_t e) {
    Located found[kAnswerLag];
    for (size_t g = b; g < e; g += kAnswerLag) {
      const size_t n = std::min(kAnswerLag, e - g);
      for (size_t i = g; i < g + n; ++i) {
        if (i + 2 * kPrefetchDistance < e) Prefetch(queries[i + 2 * kPrefetchDistance], false);
        if (i + kPrefetchDistance < e) Prefetch(queries[i + kPrefetchDistance], true);
        found[i - g] = LocateSnap(queries[i], nullptr);
      }
      for (size_t i = 0; i < n; ++i) out[g + i] = Answer(found[i]);
    }
  };
  if (pool)
    pool->Run(count, BatchPool::kQueryChunk, answer);
  else
    answer(0, count);
}

void TerrainGrid::NextBatch(const StepQuery* queries, size_t count, double tolerance, Foothold* out,
                            BatchPool* pool) const {
  auto answer = [&](size_t b, size_t e) {
    Located found[kAnswerLag];
    for (size_t g = b; g < e; g += kAnswerLag) {
      const size_t n = std::min(kAnswerLag, e - g);
      for (size_t i = g; i < g + n; ++i) {
        if (i + 2 * kPrefetchDistance < e) {
          const StepQuery& ahead = queries[i + 2 * kPrefetchDistance];
          Prefetch(ahead.foot + ahead.direction, false);
        }
        if (i + kPrefetchDistance < e) {
          const StepQuery& ahead = queries[i + kPrefetchDistance];
          Prefetch(ahead.foot + ahead.direction, true);
        }
        found[i - g] = LocateNext(queries[i], tolerance, nullptr);
      }
      for (size_t i = 0; i < n; ++i) out[g + i] = Answer(found[i]);
    }
  };
  if (pool)
    pool->Run(count, BatchPool::kQueryChunk, answer);
  else
    answer(0, count);
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
