// TerrainGrid: terrain samples packed into a fixed uniform 3D grid, answering exact
// nearest-sample ("snap", "normal") and foothold ("next") queries.
//
// The grid covers the samples' bounding box in any orientation (walls, ceilings, spheres, not
// only height fields). Its cell size is chosen for query speed (a few samples per occupied cell)
// under a memory cap of 0.95 cells per sample, whatever the bounds. A few far outliers do
// not stretch it: the grid then covers the bulk of the samples, and its border cells take the
// outliers (border cells extend to the true bounds). Queries are exact: they return what a
// brute-force scan over all samples returns (see brute_force.h), ties going to the lowest index.
//
// Samples are stored as float offsets from the grid's origin (the centre of the bulk of the
// samples): a stored sample differs from its input by at most ~6e-8 of its distance to that
// origin. ForEachSample() yields the stored values; every answer uses them.
//
// The grid is immutable, move-only, and lives in one allocation of parallel arrays: positions
// (each cell's samples as a run of x, then y, then z, so one cell is one contiguous span that a
// query scans several samples at a time), each sample's normal with its source index (read only
// for the answer), and cell offsets. Queries are const and thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "footfall/terrain/samples.h"
#include "footfall/terrain/status.h"
#include "footfall/terrain/vec3.h"

namespace footfall {

class BatchPool;

// The answer to one query. On kOk, index/point/normal describe the chosen sample; on
// kNoFoothold or an error status they are zero.
struct Foothold {
  Status status = Status::kInvalidArgument;
  uint32_t index = 0;  // 0-based order of the sample in its source
  Vec3 point;          // world space
  Vec3 normal;         // unit
};

// A "next" query: the foot at `foot` moves along `direction`, whose length is the step length.
struct StepQuery {
  Vec3 foot;       // world space
  Vec3 direction;  // world space, non-zero and finite
};

// What a query examined, for debugging and the viewer. Filled only when passed.
struct QueryTrace {
  Vec3 ideal;                              // the query point, or foot + direction for next
  double radius = 0;                       // next: the candidate radius; snap: 0
  std::vector<uint32_t> cells;             // linear indices of cells whose samples were scanned
  std::vector<uint32_t> examined_samples;  // sample indices whose distance was computed
  std::vector<uint32_t> candidates;        // next: samples that met the candidate conditions
};

// Below this many samples, GridStats::spacing is measured sample to sample (see there).
inline constexpr size_t kDirectSpacingSamples = 40;

struct GridStats {
  size_t samples = 0;
  uint32_t cells[3] = {0, 0, 0};  // grid dimensions in x, y, z
  double cell_size = 0;           // [Units: wu] edge length of a (cubic) cell
  size_t occupied_cells = 0;
  // [Units: wu] The typical distance between neighbouring samples, taking them as a surface: the
  // side of the square each sample covers, from how many cells they occupy in a grid of about
  // 20 samples per occupied cell (not the query cells: it does not change with
  // GridOptions::samples_per_cell), less the extra cells a surface crosses where it leans
  // across the axes, so that it stays within a per cent or two however the terrain is turned
  // (it read up to 15% wider on ground turned 37 degrees). Fewer than kDirectSpacingSamples,
  // too few to fill such cells, give instead the median distance from a sample to its nearest
  // other one at a different place. 0 for no samples.
  double spacing = 0;
  size_t bytes = 0;             // the grid's single allocation
  Vec3 bounds_min, bounds_max;  // world-space bounds of all samples
  Vec3 grid_min, grid_max;      // world-space box the cells divide (the bulk of the samples)
  // [Units: wu] The farthest a stored sample lies from the sample as given: samples are float
  // offsets from the centre of the bulk, kept to about 6e-8 of their distance from it. Queries
  // are exact for the samples as stored.
  double max_rounding = 0;
};

struct GridOptions {
  // Target mean samples per occupied cell. [Limit: > 0]
  double samples_per_cell = 12;
  // Memory cap: total cells <= max(64, cells_per_sample * samples). [Limit: > 0] The default
  // keeps a grid within 32 bytes per sample: 28 for the sample and its normal, 4 per cell.
  double cells_per_sample = 0.95;
  // Scan cells with AVX2 when the CPU has it (x86-64 builds with GCC or Clang); false: the
  // portable code, same answers.
  bool use_avx2 = true;
};

// True when this build can scan with AVX2 and the CPU has it.
bool CpuHasAvx2();

class TerrainGrid {
 public:
  TerrainGrid();
  ~TerrainGrid();
  TerrainGrid(TerrainGrid&&) noexcept;
  TerrainGrid& operator=(TerrainGrid&&) noexcept;
  TerrainGrid(const TerrainGrid&) = delete;
  TerrainGrid& operator=(const TerrainGrid&) = delete;

  // Packs validated samples (ValidateAndNormalize) into a grid. Returns kInvalidArgument for
  // non-finite values or mismatched counts, kLimitExceeded beyond 2^32-2 samples. An empty
  // sample set gives an empty grid whose queries answer kNoFoothold.
  static Status Build(const RawSamples& samples, const GridOptions& options, TerrainGrid* out,
                      std::string* error);

  bool empty() const { return count_ == 0; }
  size_t size() const { return count_; }
  const GridStats& stats() const { return stats_; }

  // Every stored sample, in storage order: fn(index, world point, unit normal).
  template <typename Fn>
  void ForEachSample(Fn&& fn) const {
    for (uint32_t cell = 0; count_ > 0 && cell < cells_; ++cell) {
      for (uint32_t slot = cell_start_[cell]; slot < cell_start_[cell + 1]; ++slot) {
        const Foothold f = MakeFoothold(cell, slot);
        fn(f.index, f.point, f.normal);
      }
    }
  }

  // The sample nearest to q (world space). kInvalidArgument for non-finite q, kNoFoothold only
  // on an empty grid.
  Foothold Snap(const Vec3& q, QueryTrace* trace = nullptr) const;

  // Same as Snap: the answer's normal is the unit normal of the nearest sample.
  Foothold Normal(const Vec3& q, QueryTrace* trace = nullptr) const { return Snap(q, trace); }

  // The foothold for a foot at q.foot moving along q.direction. Candidates are samples p ahead
  // of the foot, dot(p - foot, direction) > 0 in double for p the point an answer reports
  // (never level with the foot by a caller's own check), within `radius` of the ideal point
  // foot + direction, where radius = tolerance if tolerance > 0 and |direction| otherwise.
  // The answer is the candidate nearest the ideal point (ties: lowest index), or kNoFoothold.
  // kInvalidArgument for a zero or non-finite direction, non-finite foot or tolerance.
  Foothold Next(const StepQuery& q, double tolerance, QueryTrace* trace = nullptr) const;

  // Batch forms: out[i] answers queries[i]. Thread-safe. With a pool, the batch is shared with
  // its threads, BatchPool::kQueryChunk queries at a time; without, it runs on the caller.
  void SnapBatch(const Vec3* queries, size_t count, Foothold* out, BatchPool* pool = nullptr) const;
  void NextBatch(const StepQuery* queries, size_t count, double tolerance, Foothold* out,
                 BatchPool* pool = nullptr) const;

  // Grid-cell geometry, for the viewer: the world-space box of linear cell `cell`, and the
  // linear indices of cells holding samples.
  void CellBox(uint32_t cell, Vec3* lo, Vec3* hi) const;
  std::vector<uint32_t> OccupiedCells() const;

 private:
  friend class BruteForce;
  friend struct NearbySearch;
  // What a query reads of a sample only once it is the answer.
  struct SampleAnswer {
    float normal[3];  // unit
    uint32_t index;   // 0-based order of the sample in its source
  };
  // The local position of a stored sample: slot `slot` of cell `cell`.
  void LocalPoint(uint32_t cell, uint32_t slot, float p[3]) const {
    const uint32_t first = cell_start_[cell], count = cell_start_[cell + 1] - first;
    const float* x = positions_ + 3 * size_t{first} + (slot - first);
    p[0] = x[0], p[1] = x[count], p[2] = x[2 * size_t{count}];
  }
  // The common case of a nearest-sample search, in few instructions: the ball around the query
  // of the nearest sample in its cell (or, when that cell is empty, in its direct neighbours)
  // reaches no cell two away. Then sets *cell and *slot to the nearest sample and returns true;
  // otherwise returns false, and Search must answer. `prefetched`: a batch has already started
  // loading the query's cell (Prefetch), so the search does not.
  bool NearestNearby(const double c[3], bool prefetched, uint32_t* cell, uint32_t* slot) const;
  // Search's visitors for nearest-sample and candidate scans (grid.cpp).
  template <bool kTraced>
  struct SnapScanner;
  template <bool kTraced>
  struct NextScanner;
  // Visits cells in shells of growing Chebyshev radius around the local point `center`, skipping
  // cells farther than scanner.limit2() or rejected by scanner.KeepCell(lo, hi); stops when no
  // unvisited cell can hold a sample within scanner.limit2(). Calls scanner.Scan(cell, b, e).
  template <typename Scanner>
  void Search(const double center[3], Scanner& scanner) const;
  // Starts loading what a query at q reads first: its cell's offsets, or (once those have
  // arrived) its cell's samples. Any q is safe.
  void Prefetch(const Vec3& q, bool samples) const;
  // Starts loading the positions of cell `cell` and of its neighbours along x (one run in
  // memory), and the cell's answers; ci are the cell's coordinates.
  void PrefetchRow(int64_t cell, const int64_t ci[3]) const;
  // The linear index of the cell holding local point c, clamped into the grid (NaN counts as
  // below); ci receives its coordinates. Same cell as CellCoord per axis.
  // (Inline: it starts every query, also in the AVX2 search.)
  int64_t ClampedCell(const double c[3], int64_t ci[3]) const {
    for (int a = 0; a < 3; ++a) {
      double t = (c[a] - grid_lo_[a]) * inv_cell_size_;
      t = t > 0 ? t : 0;  // NaN too
      t = t < last_cell_[a] ? t : last_cell_[a];
      ci[a] = static_cast<int64_t>(t);
    }
    return ci[0] + (ci[1] + ci[2] * int64_t{dims_[1]}) * dims_[0];
  }
  // The cell coordinate along `axis` of a local coordinate, clamped into the grid.
  uint32_t CellCoord(double local, int axis) const {
    const double t = (local - grid_lo_[axis]) * inv_cell_size_;
    if (!(t > 0)) return 0;
    if (t >= static_cast<double>(dims_[axis])) return dims_[axis] - 1;
    return static_cast<uint32_t>(t);
  }
  double CellLo(uint32_t i, int axis) const;
  double CellHi(uint32_t i, int axis) const;
  Foothold MakeFoothold(uint32_t cell, uint32_t slot) const;
  // A query's outcome before its answer is read: on kOk, the answer's cell and slot.
  struct Located {
    Status status = Status::kInvalidArgument;
    uint32_t cell = 0xFFFFFFFFu;
    uint32_t slot = 0xFFFFFFFFu;
  };
  // `prefetched` as for NearestNearby.
  Located LocateSnap(const Vec3& q, bool prefetched, QueryTrace* trace) const;
  Located LocateNext(const StepQuery& q, double tolerance, bool prefetched,
                     QueryTrace* trace) const;
  Foothold Answer(const Located& found) const;
  // The batch loop shared by SnapBatch and NextBatch: ideal(i) is where query i searches (for
  // prefetching), locate(i) finds its answer.
  template <typename Ideal, typename Locate>
  void AnswerBatch(size_t count, Foothold* out, BatchPool* pool, const Ideal& ideal,
                   const Locate& locate) const;

  size_t count_ = 0;
  GridStats stats_;
  double origin_[3] = {0, 0, 0};     // world position of local (0, 0, 0)
  double grid_lo_[3] = {0, 0, 0};    // local corner of cell (0, 0, 0)
  double bounds_lo_[3] = {0, 0, 0};  // local bounds of all samples
  double bounds_hi_[3] = {0, 0, 0};
  double cell_size_ = 1, inv_cell_size_ = 1;
  double pad_ = 0;  // the query-independent part of the cell-box pad
  uint32_t dims_[3] = {1, 1, 1};
  double last_cell_[3] = {0, 0, 0};  // dims_ - 1, as doubles
  size_t cells_ = 0;                 // dims_[0] * dims_[1] * dims_[2]
  bool avx2_ = false;                // cells scanned with AVX2 (GridOptions::use_avx2)
  struct FreeMemory {
    void operator()(unsigned char* p) const;
  };
  std::unique_ptr<unsigned char[], FreeMemory> memory_;
  // Views into memory_, in cell order:
  const float* positions_ = nullptr;       // per cell from 3 * its first slot: x..., y..., z...
  const SampleAnswer* answers_ = nullptr;  // per slot
  const uint32_t* cell_start_ = nullptr;   // cells + 1 offsets into the slots
  const float* block_bounds_ = nullptr;    // per block of 8^3 cells: local min xyz, max xyz
  uint32_t block_dims_[3] = {1, 1, 1};
};

}  // namespace footfall
