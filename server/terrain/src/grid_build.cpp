// TerrainGrid::Build: bounds, the grid box, the cell size, and the single allocation the samples
// are packed into (see grid.h for the layout).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <vector>

#include "footfall/terrain/grid.h"
#include "footfall/terrain/large_memory.h"
#include "grid_layout.h"

namespace footfall {
namespace {

using detail::kBlockCells;
constexpr double kInf = std::numeric_limits<double>::infinity();
// GridStats::spacing is measured on cells grown to hold about this many samples each, whatever
// the query cells hold: callers size their checks by it (the step generator's swing arcs).
constexpr double kSpacingSamplesPerCell = 20;
// Fewer samples than kDirectSpacingSamples cannot fill such cells (two samples 1 m apart read a
// spacing of 0.07, the size of the cells they stopped growing at).
static_assert(kDirectSpacingSamples >= 2 * kSpacingSamplesPerCell, "too few to fill the cells");

// Total cells for a cell size h over local extents e, saturating in double.
double CellCount(const double e[3], double h) {
  double total = 1;
  for (int a = 0; a < 3; ++a) total *= std::max(1.0, std::ceil(e[a] / h));
  return total;
}

uint32_t AxisCells(double extent, double h) {
  return static_cast<uint32_t>(std::max(1.0, std::ceil(extent / h)));
}

// A well-mixed 64-bit hash of i (SplitMix64's finaliser): where a subsample looks in each run of
// the samples.
uint64_t Scramble(uint64_t i) {
  i += 0x9E3779B97F4A7C15ull;
  i = (i ^ (i >> 30)) * 0xBF58476D1CE4E5B9ull;
  i = (i ^ (i >> 27)) * 0x94D049BB133111EBull;
  return i ^ (i >> 31);
}

// Picks the grid box per axis: the true bounds, unless a few far outliers stretch an axis to
// more than 4 times its bulk, then the bulk plus margin. The bulk runs from the (k+1)-th lowest
// to the (k+1)-th highest value of a subsample of m (every sample up to 4096; else one from each
// of 4096 equal runs of the samples, at a place in the run that varies from run to run: at a
// fixed stride, outliers one every so many samples were all picked and taken for bulk), k = 1%
// of m and at least 1 (a terrain of 100 samples and one outlier kept the outlier in its box,
// and its origin far from the rest, whose float offsets then lost their spacing).
void ChooseGridBox(const RawSamples& s, const double lo[3], const double hi[3], double glo[3],
                   double ghi[3]) {
  const size_t n = s.size();
  for (int a = 0; a < 3; ++a) glo[a] = lo[a], ghi[a] = hi[a];
  if (n < 3) return;  // (two samples have no bulk between them)
  const size_t m = std::min<size_t>(n, 4096);
  const size_t k = std::max<size_t>(1, (m - 1) / 100);
  std::vector<size_t> picked(m);
  for (size_t i = 0; i < m; ++i) {
    const size_t begin = i * n / m, end = (i + 1) * n / m;
    picked[i] = begin + static_cast<size_t>(Scramble(i) % (end - begin));
  }
  std::vector<double> v(m);
  for (int a = 0; a < 3; ++a) {
    for (size_t i = 0; i < m; ++i) {
      const Vec3& p = s.points[picked[i]];
      v[i] = a == 0 ? p.x : a == 1 ? p.y : p.z;
    }
    std::sort(v.begin(), v.end());
    const double q_lo = v[k];
    const double q_hi = v[(m - 1) - k];
    const double bulk = q_hi - q_lo;
    if (hi[a] - lo[a] > 4 * bulk) {
      const double margin = 0.25 * bulk;
      glo[a] = std::max(lo[a], q_lo - margin);
      ghi[a] = std::min(hi[a], q_hi + margin);
    }
  }
  // Samples of the subsample near the box (within 4 times its diagonal: the few a small
  // terrain's trimming left just outside) are taken in; the outliers left must be a few, one or
  // up to 2% of the subsample, or the true bounds stay (three samples far apart, or a cross of
  // five, were trimmed to their middle sample: a box of no size, a cell size of 1 and a spacing
  // made up whatever their scale).
  const double diagonal =
      std::sqrt((ghi[0] - glo[0]) * (ghi[0] - glo[0]) + (ghi[1] - glo[1]) * (ghi[1] - glo[1]) +
                (ghi[2] - glo[2]) * (ghi[2] - glo[2]));
  double grown_lo[3] = {glo[0], glo[1], glo[2]}, grown_hi[3] = {ghi[0], ghi[1], ghi[2]};
  size_t outside = 0;
  for (const size_t i : picked) {
    const Vec3& p = s.points[i];
    const double c[3] = {p.x, p.y, p.z};
    double gap2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double gap = std::max({0.0, glo[a] - c[a], c[a] - ghi[a]});
      gap2 += gap * gap;
    }
    if (!(gap2 > 0)) continue;
    if (std::sqrt(gap2) > 4 * diagonal) {
      ++outside;
      continue;
    }
    for (int a = 0; a < 3; ++a)
      grown_lo[a] = std::min(grown_lo[a], c[a]), grown_hi[a] = std::max(grown_hi[a], c[a]);
  }
  const bool few = outside <= std::max<size_t>(1, m / 50);
  for (int a = 0; a < 3; ++a) {
    glo[a] = few ? grown_lo[a] : lo[a];
    ghi[a] = few ? grown_hi[a] : hi[a];
  }
}

// The cells of size h over the grid box (local corner lo, extents e), each sample in the cell
// TerrainGrid::CellCoord gives it.
struct CellIndexer {
  uint32_t dims[3];
  double lo[3];
  double inv;
  CellIndexer(const double grid_lo[3], const double e[3], double h) : inv(1 / h) {
    for (int a = 0; a < 3; ++a) dims[a] = AxisCells(e[a], h), lo[a] = grid_lo[a];
  }
  size_t Cells() const { return size_t{dims[0]} * dims[1] * dims[2]; }
  size_t Coord(float v, int a) const {
    const double t = (v - lo[a]) * inv;
    if (!(t > 0)) return 0;
    if (t >= static_cast<double>(dims[a])) return dims[a] - 1;
    return static_cast<size_t>(t);
  }
  // The cell of the sample at p (x, y, z).
  size_t Cell(const float* p) const {
    return (Coord(p[2], 2) * dims[1] + Coord(p[1], 1)) * dims[0] + Coord(p[0], 0);
  }
};

// The cells of size h over the grid box (local corner lo, extents e) that hold a sample of
// `local` (x, y, z per sample).
size_t CountOccupiedCells(const std::vector<float>& local, const double lo[3], const double e[3],
                          double h) {
  const CellIndexer cells(lo, e, h);
  std::vector<bool> occupied(cells.Cells(), false);
  size_t count = 0;
  for (size_t i = 0; i + 2 < local.size(); i += 3) {
    const size_t cell = cells.Cell(&local[i]);
    if (!occupied[cell]) occupied[cell] = true, ++count;
  }
  return count;
}

// The median, over the samples of `local` (x, y, z per sample) that have another at a different
// place, of the distance to the nearest such one; 0 when every sample is at one place. Compares
// every pair: for the few samples below kDirectSpacingSamples.
double MedianNearestDistance(const std::vector<float>& local) {
  const size_t n = local.size() / 3;
  std::vector<double> nearest;
  nearest.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    double best = kInf;
    for (size_t j = 0; j < n; ++j) {
      const double d = std::hypot(static_cast<double>(local[3 * j]) - local[3 * i],
                                  static_cast<double>(local[3 * j + 1]) - local[3 * i + 1],
                                  static_cast<double>(local[3 * j + 2]) - local[3 * i + 2]);
      if (d > 0) best = std::min(best, d);
    }
    if (best < kInf) nearest.push_back(best);
  }
  if (nearest.empty()) return 0;
  const auto middle = nearest.begin() + static_cast<std::ptrdiff_t>(nearest.size() / 2);
  std::nth_element(nearest.begin(), middle, nearest.end());
  return *middle;
}

// Cells of side h over local extents e that hold samples, and in *crossing how many more cells
// the surface crosses than its area in cell faces, averaged over the samples: a plane of area A
// with unit normal n crosses about A (|nx| + |ny| + |nz|) / h^2 cubes of side h (1 for a
// surface facing along an axis, up to sqrt(3) across the diagonal). Taken from each cell's mean
// normal where its samples' normals agree (the surface's direction at the cell's scale, not the
// roughness within it), else from each sample's own (an edge or a corner, as of a stair).
size_t OccupiedCellsAndCrossing(const std::vector<float>& local, const std::vector<Vec3>& normals,
                                const double lo[3], const double e[3], double h, double* crossing) {
  const CellIndexer indexer(lo, e, h);
  // Per occupied cell: the sum of its samples' unit normals, of their |nx| + |ny| + |nz|, and
  // their count.
  struct CellNormals {
    Vec3 sum;
    double across = 0;
    uint32_t count = 0;
  };
  constexpr uint32_t kEmpty = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> slot_of(indexer.Cells(), kEmpty);
  std::vector<CellNormals> cells;
  for (size_t i = 0; 3 * i + 2 < local.size(); ++i) {
    const size_t cell = indexer.Cell(&local[3 * i]);
    if (slot_of[cell] == kEmpty) {
      slot_of[cell] = static_cast<uint32_t>(cells.size());
      cells.emplace_back();
    }
    CellNormals& c = cells[slot_of[cell]];
    const Vec3& v = normals[i];
    const double len2 = Dot(v, v);
    // Normals are unit once validated: the square root only for those that are not.
    const Vec3 u = std::fabs(len2 - 1) < 1e-12 ? v : len2 > 0 ? v / std::sqrt(len2) : Vec3{};
    c.sum += u;
    c.across += len2 > 0 ? std::fabs(u.x) + std::fabs(u.y) + std::fabs(u.z) : 1.0;
    ++c.count;
  }
  constexpr double kAgree = 0.9;  // the mean of the cell's unit normals at least this long
  double total = 0, samples = 0;
  for (const CellNormals& c : cells) {
    const double count = c.count, len2 = Dot(c.sum, c.sum);
    samples += count;
    if (len2 >= kAgree * kAgree * count * count)
      total +=
          count * (std::fabs(c.sum.x) + std::fabs(c.sum.y) + std::fabs(c.sum.z)) / std::sqrt(len2);
    else
      total += c.across;
  }
  *crossing = samples > 0 ? std::clamp(total / samples, 1.0, std::sqrt(3.0)) : 1.0;
  return cells.size();
}

}  // namespace

void TerrainGrid::FreeMemory::operator()(unsigned char* p) const { FreeLargeMemory(p); }

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
  double rounding2 = 0, tiny_rounding = 0;
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = samples.points[i];
    const Vec3 offset{p.x - g.origin_[0], p.y - g.origin_[1], p.z - g.origin_[2]};
    local[3 * i + 0] = static_cast<float>(offset.x);
    local[3 * i + 1] = static_cast<float>(offset.y);
    local[3 * i + 2] = static_cast<float>(offset.z);
    const Vec3 kept{local[3 * i + 0], local[3 * i + 1], local[3 * i + 2]};
    const double d2 = Distance2(kept, offset);
    rounding2 = std::max(rounding2, d2);
    // Offsets below about 1e-154 square to nothing: a terrain of such size, whose floats flush
    // to zero, must not be said to be stored exactly.
    if (d2 == 0 && !(kept.x == offset.x && kept.y == offset.y && kept.z == offset.z))
      tiny_rounding = std::max(tiny_rounding,
                               std::hypot(kept.x - offset.x, kept.y - offset.y, kept.z - offset.z));
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
  //    about options.samples_per_cell samples (a surface's occupancy falls as 1/h^2). The
  //    sample spacing is measured on cells grown to kSpacingSamplesPerCell instead, so that it
  //    does not follow the query cells' size, less the extra cells a surface leaning across
  //    the axes crosses, so that it does not follow the terrain's orientation.
  const double budget = std::max(64.0, options.cells_per_sample * static_cast<double>(n));
  const double max_extent = std::max({extent[0], extent[1], extent[2]});
  double h = 1, spacing_h = 1, crossing = 1;
  size_t spacing_occupied = 0;  // 0: count them in the final grid (no extent)
  if (max_extent > 0) {
    double h_hi = max_extent, h_lo = max_extent / (budget + 1);
    for (int it = 0; it < 100 && h_hi > h_lo * (1 + 1e-12); ++it) {
      const double mid = std::sqrt(h_lo * h_hi);
      (CellCount(extent, mid) <= budget ? h_hi : h_lo) = mid;
    }
    const double per_cell =
        static_cast<double>(n) /
        std::max<size_t>(1, CountOccupiedCells(local, g.grid_lo_, extent, h_hi));
    auto grown = [&](double target) {
      return per_cell < target ? h_hi * std::sqrt(target / per_cell) : h_hi;
    };
    h = grown(options.samples_per_cell);
    spacing_h = grown(kSpacingSamplesPerCell);
    spacing_occupied =
        OccupiedCellsAndCrossing(local, samples.normals, g.grid_lo_, extent, spacing_h, &crossing);
  }
  g.cell_size_ = h, g.inv_cell_size_ = 1 / h;
  for (int a = 0; a < 3; ++a) g.dims_[a] = AxisCells(extent[a], h);
  for (int a = 0; a < 3; ++a) g.last_cell_[a] = g.dims_[a] - 1.0;
  const size_t cells = size_t{g.dims_[0]} * g.dims_[1] * g.dims_[2];
  g.cells_ = cells;
  g.avx2_ = options.use_avx2 && CpuHasAvx2();
  // Cell boxes are padded so that rounding can never prune a sample: in cell assignment
  // (relative to the coordinates the cells span) and in distances (relative to the query's,
  // added per query). Samples beyond the cells' box are in the outer cells, whose boxes reach
  // them exactly (CellLo, CellHi): the pad is not sized by them. (Sized by all the samples'
  // bounds, one outlier 1e12 away padded every cell by a thousand units, and every query
  // scanned every cell: slower than brute force.)
  double span = h;
  for (int a = 0; a < 3; ++a) span += std::fabs(g.grid_lo_[a]) + g.dims_[a] * h;
  g.pad_ = 1e-9 * span;

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
  // One block, in huge pages when large (large_memory.h).
  g.memory_.reset(static_cast<unsigned char*>(AllocateLargeMemory(bytes)));
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
  if (spacing_occupied == 0) spacing_occupied = occupied_cells;
  st.spacing = n > 0 ? spacing_h * std::sqrt(static_cast<double>(spacing_occupied) /
                                             (static_cast<double>(n) * crossing))
                     : 0;
  if (n >= 2 && n < kDirectSpacingSamples) {
    const double direct = MedianNearestDistance(local);
    if (direct > 0) st.spacing = direct;
  }
  st.bytes = bytes;
  st.max_rounding = std::max(std::sqrt(rounding2), tiny_rounding);
  const double* o = g.origin_;
  st.bounds_min = {o[0] + g.bounds_lo_[0], o[1] + g.bounds_lo_[1], o[2] + g.bounds_lo_[2]};
  st.bounds_max = {o[0] + g.bounds_hi_[0], o[1] + g.bounds_hi_[1], o[2] + g.bounds_hi_[2]};
  st.grid_min = {glo[0], glo[1], glo[2]};
  st.grid_max = {o[0] + g.grid_lo_[0] + g.dims_[0] * h, o[1] + g.grid_lo_[1] + g.dims_[1] * h,
                 o[2] + g.grid_lo_[2] + g.dims_[2] * h};
  *out = std::move(g);
  return Status::kOk;
}

}  // namespace footfall
