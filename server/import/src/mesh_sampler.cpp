#include "footfall/import/mesh_sampler.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <system_error>
#include <thread>
#include <tuple>
#include <vector>

#include "footfall/terrain/large_memory.h"

namespace footfall {
namespace {

// SplitMix64: a small, fast generator whose output is fixed by the standard-free arithmetic below,
// so a seed gives the same order everywhere.
struct SplitMix64 {
  explicit SplitMix64(uint64_t seed) : state(seed) {}
  uint64_t Next() {
    uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, n), n > 0 (Lemire's multiply-shift; the tiny bias is irrelevant here).
  uint64_t Below(uint64_t n) {
    return static_cast<uint64_t>((static_cast<unsigned __int128>(Next()) * n) >> 64);
  }
  double Unit() { return static_cast<double>(Next() >> 11) * (1.0 / 9007199254740992.0); }
  uint64_t state;
};

// A step-1 piece's centroid, relative to the cell grid's corner, for distance tests. Its
// triangle and barycentric position are found again in step 4 from its index (candidates are
// stored in triangle order, each triangle's pieces in SplitTriangle's order).
// `side` is its triangle's unit normal times 127, rounded: pieces facing apart (a thin slab's
// top and bottom) do not thin each other out.
struct Candidate {
  float offset[3];
  int8_t side[4];  // x, y, z; the fourth is padding
};

// True when two pieces face the same way, within 90 degrees (a zero side, from a triangle too
// thin for a normal, faces every way).
bool SameSide(const int8_t* a, const int8_t* b) {
  const int dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const bool a_zero = (a[0] | a[1] | a[2]) == 0, b_zero = (b[0] | b[1] | b[2]) == 0;
  return dot > 0 || a_zero || b_zero;
}

// Steps 1 and 4 take another thread only for this many more pieces to cut, or samples to place.
constexpr double kPiecesPerThread = 200000;
constexpr double kSamplesPerThread = 50000;
// Step 1's threads add their pieces to the shared count this often.
constexpr size_t kCountEvery = 4096;

constexpr int kCellBits = 21;
constexpr uint64_t kCellLimit = 1ull << kCellBits;
constexpr uint32_t kNone = 0xffffffffu;

uint64_t CellKey(uint64_t x, uint64_t y, uint64_t z) {
  return (x << (2 * kCellBits)) | (y << kCellBits) | z;
}

// Open-addressing map from cell key to a dense cell id; grows to stay at most half full.
class CellTable {
 public:
  explicit CellTable(size_t expected) { Reset(std::max<size_t>(16, 2 * expected)); }
  // The id of `key`, inserting it with id `next` when absent.
  uint32_t Insert(uint64_t key, uint32_t next) {
    if (2 * (size_ + 1) > entries_.size()) Grow();
    for (size_t i = Hash(key) & mask_;; i = (i + 1) & mask_) {
      if (entries_[i].key == key) return entries_[i].id;
      if (entries_[i].key == kEmpty) {
        entries_[i] = {key, next};
        ++size_;
        return next;
      }
    }
  }
  uint32_t Find(uint64_t key) const {
    for (size_t i = Hash(key) & mask_;; i = (i + 1) & mask_) {
      if (entries_[i].key == key) return entries_[i].id;
      if (entries_[i].key == kEmpty) return kNone;
    }
  }

 private:
  static constexpr uint64_t kEmpty = ~0ull;
  struct Entry {
    uint64_t key;
    uint32_t id;
  };
  static size_t Hash(uint64_t key) {
    key ^= key >> 33, key *= 0xff51afd7ed558ccdull, key ^= key >> 33;
    return static_cast<size_t>(key);
  }
  void Reset(size_t minimum) {
    size_t capacity = 16;
    while (capacity < minimum) capacity *= 2;
    entries_.assign(capacity, Entry{kEmpty, kNone});
    mask_ = capacity - 1;
    size_ = 0;
  }
  void Grow() {
    LargeVector<Entry> old;
    old.swap(entries_);
    Reset(old.size() * 2);
    for (const Entry& e : old) {
      if (e.key != kEmpty) Insert(e.key, e.id);
    }
  }
  LargeVector<Entry> entries_;
  size_t mask_ = 0, size_ = 0;
};

// Map from cell coordinates to a dense cell id: a hash of 4^3-cell tiles, each a dense block,
// so that looking up a cell's neighbours mostly stays within one cached block.
class CellMap {
 public:
  explicit CellMap(size_t expected_cells) : tiles_(expected_cells / 8 + 16) {}
  // The id of cell (x, y, z), inserting it with id `next` when absent.
  uint32_t Insert(uint64_t x, uint64_t y, uint64_t z, uint32_t next) {
    uint32_t* block = Block(x, y, z, true);
    uint32_t& id = block[Local(x, y, z)];
    if (id == kNone) id = next;
    return id;
  }
  // The ids of tile (tx, ty, tz), cells (4 tx .. 4 tx + 3, ...), at Local(x, y, z) (kNone
  // where absent), or nullptr when the tile holds no cell.
  const uint32_t* Tile(uint64_t tx, uint64_t ty, uint64_t tz) const {
    const uint32_t tile = tiles_.Find(CellKey(tx, ty, tz));
    return tile == kNone ? nullptr : &blocks_[static_cast<size_t>(tile) * 64];
  }
  static size_t Local(uint64_t x, uint64_t y, uint64_t z) {
    return static_cast<size_t>((x & 3) << 4 | (y & 3) << 2 | (z & 3));
  }

 private:
  uint32_t* Block(uint64_t x, uint64_t y, uint64_t z, bool create) {
    const uint64_t key = CellKey(x >> 2, y >> 2, z >> 2);
    if (key != last_key_) {
      uint32_t tile = tiles_.Find(key);
      if (tile == kNone) {
        if (!create) return nullptr;
        tile = tiles_.Insert(key, static_cast<uint32_t>(blocks_.size() / 64));
        blocks_.resize(blocks_.size() + 64, kNone);
      }
      last_key_ = key, last_tile_ = tile;
    }
    return &blocks_[static_cast<size_t>(last_tile_) * 64];
  }
  CellTable tiles_;
  LargeVector<uint32_t> blocks_;
  uint64_t last_key_ = ~0ull;
  uint32_t last_tile_ = 0;
};

// A piece of a triangle in step 1's longest-edge bisection: its corners and how many cuts
// made it, and with kBarycentric (for step 4) each corner's barycentric (u, v) in the source
// triangle.
template <bool kBarycentric>
struct Piece {
  Vec3 p[3];
  int depth;
};
template <>
struct Piece<true> {
  Vec3 p[3];
  int depth;
  double b[3][2];
};

// Step 1 for triangle t: bisects its longest edge until each piece's centroid lies within
// sqrt(h2) of the piece's corners (or 60 cuts deep), and calls leaf(piece) for each final
// piece, in a fixed order, until leaf returns false. `stack` is scratch space.
template <bool kBarycentric, typename Leaf>
void SplitTriangle(const TriangleMesh& mesh, size_t t, double h2,
                   std::vector<Piece<kBarycentric>>* stack, const Leaf& leaf) {
  const auto& tri = mesh.triangles[t];
  stack->clear();
  Piece<kBarycentric> whole;
  whole.p[0] = mesh.vertices[tri[0]], whole.p[1] = mesh.vertices[tri[1]];
  whole.p[2] = mesh.vertices[tri[2]];
  whole.depth = 0;
  if constexpr (kBarycentric) {
    const double corners[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    std::copy(&corners[0][0], &corners[0][0] + 6, &whole.b[0][0]);
  }
  stack->push_back(whole);
  while (!stack->empty()) {
    Piece<kBarycentric>& piece = stack->back();
    const Vec3 g = (piece.p[0] + piece.p[1] + piece.p[2]) / 3;
    const double reach =
        std::max({Distance2(g, piece.p[0]), Distance2(g, piece.p[1]), Distance2(g, piece.p[2])});
    if (reach <= h2 || piece.depth >= 60) {
      const bool more = leaf(piece);
      stack->pop_back();
      if (!more) return;
      continue;
    }
    // Split the longest edge (i, j) at its midpoint; k is the opposite corner. The piece
    // becomes (m, j, k) where it lies, and (i, m, k) goes above it, to be cut first.
    int i = 0;
    double longest = -1;
    for (int e = 0; e < 3; ++e) {
      const double d = Distance2(piece.p[e], piece.p[(e + 1) % 3]);
      if (d > longest) longest = d, i = e;
    }
    const int j = (i + 1) % 3;
    Piece<kBarycentric> a = piece;
    const Vec3 m = (piece.p[i] + piece.p[j]) / 2;
    a.p[j] = m, piece.p[i] = m;
    if constexpr (kBarycentric) {
      const double mb[2] = {(piece.b[i][0] + piece.b[j][0]) / 2,
                            (piece.b[i][1] + piece.b[j][1]) / 2};
      a.b[j][0] = mb[0], a.b[j][1] = mb[1];
      piece.b[i][0] = mb[0], piece.b[i][1] = mb[1];
    }
    a.depth = piece.depth = piece.depth + 1;
    stack->push_back(a);  // (piece is not used again: the push may move it)
  }
}

Vec3 Blend(const Vec3& a, const Vec3& b, const Vec3& c, double u, double v) {
  return a * (1 - u - v) + b * u + c * v;
}

// Step 4: the sample normal at barycentric (u, v) of triangle t, whose corner normals are
// `corners` (CornerNormals::Of), or nullptr for the face's.
Vec3 SampleNormal(const TriangleMesh& mesh, const std::array<Vec3, 3>* corners, size_t t, double u,
                  double v) {
  const Vec3 face = Normalize(TriangleCross(mesh, t));
  if (!corners) return face;
  const Vec3 n = Blend((*corners)[0], (*corners)[1], (*corners)[2], u, v);
  const double length = Length(n);
  if (!(length > 1e-12) || Dot(n, face) <= 0) return face;
  return n / length;
}

Vec3 SamplePoint(const TriangleMesh& mesh, size_t t, double u, double v) {
  const auto& tri = mesh.triangles[t];
  return Blend(mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]], u, v);
}

Status CheckMesh(const TriangleMesh& mesh, std::string* error) {
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (!IsFinite(mesh.vertices[i])) {
      if (error) *error = "vertex " + std::to_string(i) + " is not finite";
      return Status::kInvalidArgument;
    }
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (uint32_t v : mesh.triangles[t]) {
      if (v >= mesh.vertices.size()) {
        if (error)
          *error = "triangle " + std::to_string(t) + " uses missing vertex " + std::to_string(v);
        return Status::kInvalidArgument;
      }
    }
  }
  return Status::kOk;
}

// `x` with 3 significant digits ("0.283", "1.5e-05").
std::string Format3(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

// The smallest value of 3 significant digits >= x (x > 0), so the value shown is enough.
double RoundUp3(double x) {
  const double step = std::pow(10.0, std::floor(std::log10(x)) - 2);
  return std::ceil(x / step) * step;
}

// Runs work(part) for each part in [0, parts): part 0 on the calling thread, the others on
// threads of their own, or after part 0 on the calling thread when no thread could be started
// for them (the parts must not wait on each other). The first exception thrown (std::bad_alloc)
// is rethrown once all end.
template <typename Work>
void RunParts(size_t parts, const Work& work) {
  std::vector<std::exception_ptr> failed(parts);
  auto run = [&](size_t part) {
    try {
      work(part);
    } catch (...) {
      failed[part] = std::current_exception();
    }
  };
  // Parts no thread could be started for (a memory or process limit) run on this one.
  std::vector<std::thread> threads;
  size_t started = 1;
  try {
    threads.reserve(parts);
    for (; started < parts; ++started) threads.emplace_back(run, started);
  } catch (const std::system_error&) {
  } catch (const std::bad_alloc&) {
  }
  run(0);
  for (size_t part = started; part < parts; ++part) run(part);
  for (std::thread& t : threads) t.join();
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

// The threads SampleMesh cuts triangles on: options.threads, or the machine's cores for 0,
// and no more than one per `per_thread` of `work` (a thread costs tens of microseconds).
size_t CuttingThreads(int threads, double work, double per_thread) {
  size_t n = threads > 0 ? static_cast<size_t>(threads) : std::thread::hardware_concurrency();
  n = std::min<size_t>(std::max<size_t>(n, 1), 64);
  return std::max<size_t>(1, std::min(n, static_cast<size_t>(work / per_thread)));
}

// What step 1 of SampleMesh allows at separation s: its estimate of the pieces the mesh is cut
// into (from each triangle's longest edge, squared in `longest2`) against its limit.
bool PiecesFit(const std::vector<double>& longest2, double area, size_t max_samples, double s) {
  const double h2 = (s / 3) * (s / 3);
  double estimate = 0;
  for (double l2 : longest2) estimate += std::max(1.0, l2 / (2.25 * h2));
  const double predicted = 1.6 * area / (s * s);
  const double limit =
      std::min(std::max(256 * predicted, 4e6), 32.0 * static_cast<double>(max_samples)) +
      static_cast<double>(longest2.size());
  return estimate <= limit;
}

// The smallest separation, rounded up to 3 significant digits, that SampleMesh takes: its
// samples within max_samples, and its pieces (long thin triangles make many) within their limit.
double SeparationThatFits(const TriangleMesh& mesh, double area, size_t max_samples) {
  // The sampler's cells (2s/3 wide) must number fewer than kCellLimit - 2 along every axis.
  Vec3 lo, hi;
  MeshBounds(mesh, &lo, &hi);
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  const double for_extent = 1.01 * 1.5 * extent / static_cast<double>(kCellLimit - 2);
  std::vector<double> longest2;
  longest2.reserve(mesh.triangles.size());
  for (const auto& tri : mesh.triangles) {
    const Vec3 &a = mesh.vertices[tri[0]], &b = mesh.vertices[tri[1]], &c = mesh.vertices[tri[2]];
    longest2.push_back(std::max({Distance2(a, b), Distance2(b, c), Distance2(c, a)}));
  }
  double low = std::max(
      for_extent, std::sqrt(1.6 * area / std::max<double>(1, static_cast<double>(max_samples))));
  if (!(low > 0)) low = 1e-300;
  if (PiecesFit(longest2, area, max_samples, low)) return RoundUp3(low);
  double high = low;
  for (int i = 0; i < 2100 && !PiecesFit(longest2, area, max_samples, high); ++i) high *= 2;
  for (int i = 0; i < 60; ++i) {
    const double mid = std::sqrt(low * high);
    (PiecesFit(longest2, area, max_samples, mid) ? high : low) = mid;
  }
  return RoundUp3(high);
}

}  // namespace

double DefaultSeparation(const TriangleMesh& mesh) {
  double sum = 0;
  size_t n = 0;
  for (const auto& tri : mesh.triangles) {
    for (int e = 0; e < 3; ++e) {
      sum += Distance(mesh.vertices[tri[e]], mesh.vertices[tri[(e + 1) % 3]]), ++n;
    }
  }
  return n ? sum / n : 1.0;
}

Status SampleMesh(const TriangleMesh& mesh, const MeshSampleOptions& options, RawSamples* out,
                  std::string* error, MeshSampleStats* stats) {
  out->clear();
  if (stats) *stats = MeshSampleStats{};
  const double s = options.separation;
  if (!(std::isfinite(s) && s > 0)) {
    if (error) *error = "separation must be a finite number > 0, got " + std::to_string(s);
    return Status::kInvalidArgument;
  }
  Status status = CheckMesh(mesh, error);
  if (status != Status::kOk) return status;
  const double area = SurfaceArea(mesh);
  const double predicted = 1.6 * area / (s * s);
  if (predicted > static_cast<double>(options.max_samples)) {
    if (error) {
      *error = "separation " + Format3(s) + " would give " +
               (predicted < 9e18           ? "about " + std::to_string(std::llround(predicted))
                : std::isfinite(predicted) ? "about " + Format3(predicted)
                                           : std::string("more than 1e+308")) +
               " samples (limit " + std::to_string(options.max_samples) + ")" +
               // (With no room at all, a separation "that fits" was offered all the same.)
               (options.max_samples == 0
                    ? std::string(": no separation fits")
                    : "; choose a separation of at least " +
                          Format3(SeparationThatFits(mesh, area, options.max_samples)));
    }
    return Status::kLimitExceeded;
  }
  if (mesh.triangles.empty()) return Status::kOk;

  const double h = s / 3, r = 2 * s / 3;
  const double h2 = h * h, r2 = r * r;
  Vec3 lo, hi;
  MeshBounds(mesh, &lo, &hi);
  const double inv_cell = 1 / r;
  const Vec3 extent = hi - lo;
  if (extent.x * inv_cell >= kCellLimit - 2 || extent.y * inv_cell >= kCellLimit - 2 ||
      extent.z * inv_cell >= kCellLimit - 2) {
    if (error)
      *error = "separation " + Format3(s) +
               " is too small for the mesh's extent; choose a separation of at least " +
               Format3(SeparationThatFits(mesh, area, options.max_samples));
    return Status::kLimitExceeded;
  }

  // 1. Candidates by longest-edge bisection, one per piece at its centroid. Long thin
  // triangles (a height map whose cells are far smaller than its heights) are cut into far more
  // pieces than their area predicts, and are refused before many are stored. Pieces keep
  // their triangle's thinness: well-shaped triangles give about 9 per predicted sample, slivers
  // 70 times longer than wide about 175; the limit allows 256 (at least 4 million), within 32
  // per sample of the budget. (A 2 x 2 16-bit height map 65535 units tall took 80 s and 4.6 GB
  // for 136,000 samples under the budget's limit alone.)
  const double pieces_for_area = std::max(256 * predicted, 4e6);
  const size_t candidate_limit =
      static_cast<size_t>(
          std::min(pieces_for_area, 32.0 * static_cast<double>(options.max_samples))) +
      mesh.triangles.size();
  auto refuse_pieces = [&]() {
    if (error) {
      *error = "separation " + Format3(s) + " would cut the mesh into more than " +
               std::to_string(candidate_limit) +
               " pieces: its triangles are long and thin for their area; choose a separation "
               "of at least " +
               Format3(std::max(SeparationThatFits(mesh, area, options.max_samples),
                                RoundUp3(1.01 * s)));
    }
    return Status::kLimitExceeded;
  };
  // Pieces keep their triangle's shape, so a triangle with longest edge L makes about
  // (L / 1.5h)^2 of them: up to about twice as many when well shaped, and the estimate
  // overshoots slivers by up to ~15 times (the tests' 1e4 x 1e-4 strip). An estimate 64 times
  // over the limit refuses at once; one within an eighth of it is cut straight into candidates
  // (a limit reached all the same stops the cutting there); between the two, the pieces are
  // counted first (seconds for the worst slivers, heights of 1e6 on unit cells: 16 s), so that
  // none is stored for a mesh refused.
  double estimate = 0;
  for (const auto& tri : mesh.triangles) {
    const Vec3 &a = mesh.vertices[tri[0]], &b = mesh.vertices[tri[1]], &c = mesh.vertices[tri[2]];
    const double longest2 = std::max({Distance2(a, b), Distance2(b, c), Distance2(c, a)});
    estimate += std::max(1.0, longest2 / (2.25 * h2));
  }
  const double limit = static_cast<double>(candidate_limit);
  if (estimate > 64 * limit) return refuse_pieces();
  std::vector<Piece<false>> stack;
  // (The estimate came within 0.74 to 1.13 of the count on real and generated meshes.)
  size_t expected = static_cast<size_t>(
      std::min(limit, 1.5 * estimate + static_cast<double>(mesh.triangles.size())));
  if (8 * estimate > limit) {
    size_t counted = 0;
    for (size_t t = 0; t < mesh.triangles.size() && counted <= candidate_limit; ++t)
      SplitTriangle(mesh, t, h2, &stack,
                    [&](const Piece<false>&) { return ++counted <= candidate_limit; });
    if (counted > candidate_limit) return refuse_pieces();
    expected = counted;
  }
  // Cut on several threads, each a run of triangles of about equal estimated pieces, into its
  // own array; joined in triangle order, the candidates are those one thread would cut. The
  // limit holds for their sum: each thread adds its count to `cut` every few thousand pieces.
  const size_t parts = CuttingThreads(options.threads, estimate, kPiecesPerThread);
  std::vector<size_t> part_first(parts + 1, mesh.triangles.size());  // triangles per part
  part_first[0] = 0;
  {
    double sum = 0;
    size_t part = 1;
    for (size_t t = 0; t < mesh.triangles.size() && part < parts; ++t) {
      const auto& tri = mesh.triangles[t];
      const Vec3 &a = mesh.vertices[tri[0]], &b = mesh.vertices[tri[1]], &c = mesh.vertices[tri[2]];
      sum += std::max(1.0,
                      std::max({Distance2(a, b), Distance2(b, c), Distance2(c, a)}) / (2.25 * h2));
      while (part < parts && sum >= estimate * static_cast<double>(part) / parts)
        part_first[part++] = t + 1;
    }
  }
  LargeVector<Candidate> candidates;
  candidates.reserve(expected);
  // Each on cache lines of its own: a vector's end moves with every push.
  struct alignas(64) Part {
    LargeVector<Candidate> candidates;
  };
  std::vector<Part> later_parts(parts - 1);
  LargeVector<uint32_t> first_candidate(mesh.triangles.size() + 1);  // per triangle
  std::atomic<size_t> cut{0};
  std::atomic<bool> over{false};
  RunParts(parts, [&](size_t part) {
    LargeVector<Candidate>& into = part == 0 ? candidates : later_parts[part - 1].candidates;
    if (part > 0) {
      const double share = static_cast<double>(part_first[part + 1] - part_first[part]) /
                           static_cast<double>(mesh.triangles.size());
      into.reserve(static_cast<size_t>(static_cast<double>(expected) * std::min(1.0, 2 * share)));
    }
    std::vector<Piece<false>> stack;
    size_t counted = 0;  // of into's candidates, those added to `cut`
    auto count = [&]() {
      const size_t total = cut += into.size() - counted;
      counted = into.size();
      if (total > candidate_limit) over = true;
      return !over;
    };
    for (size_t t = part_first[part]; t < part_first[part + 1] && !over; ++t) {
      first_candidate[t] = static_cast<uint32_t>(into.size());
      const Vec3 normal = Normalize(TriangleCross(mesh, t));
      int8_t side[4] = {0, 0, 0, 0};
      if (IsFinite(normal)) {
        side[0] = static_cast<int8_t>(std::lround(127 * normal.x));
        side[1] = static_cast<int8_t>(std::lround(127 * normal.y));
        side[2] = static_cast<int8_t>(std::lround(127 * normal.z));
      }
      SplitTriangle(mesh, t, h2, &stack, [&](const Piece<false>& piece) {
        const Vec3 local = (piece.p[0] + piece.p[1] + piece.p[2]) / 3 - lo;
        into.push_back({{static_cast<float>(local.x), static_cast<float>(local.y),
                         static_cast<float>(local.z)},
                        {side[0], side[1], side[2], 0}});
        return into.size() - counted < kCountEvery || count();
      });
    }
    count();
  });
  if (over || cut > candidate_limit) return refuse_pieces();
  for (size_t part = 1; part < parts; ++part) {
    LargeVector<Candidate>& piece = later_parts[part - 1].candidates;
    const uint32_t base = static_cast<uint32_t>(candidates.size());
    for (size_t t = part_first[part]; t < part_first[part + 1]; ++t) first_candidate[t] += base;
    candidates.insert(candidates.end(), piece.begin(), piece.end());
    LargeVector<Candidate>().swap(piece);
  }
  first_candidate.back() = static_cast<uint32_t>(candidates.size());

  // Cells of side r over the bounds; each candidate's cell id.
  const size_t n = candidates.size();
  auto table = std::make_unique<CellMap>(static_cast<size_t>(predicted) + 16);
  LargeVector<uint32_t> cell_of(n);
  LargeVector<uint64_t> cell_keys;
  uint64_t last_key = ~0ull;
  uint32_t last_id = kNone;
  for (size_t c = 0; c < n; ++c) {
    const uint64_t x = static_cast<uint64_t>(std::max(0.0, candidates[c].offset[0] * inv_cell));
    const uint64_t y = static_cast<uint64_t>(std::max(0.0, candidates[c].offset[1] * inv_cell));
    const uint64_t z = static_cast<uint64_t>(std::max(0.0, candidates[c].offset[2] * inv_cell));
    const uint64_t key = CellKey(x + 1, y + 1, z + 1);  // +1: neighbours never underflow
    if (key != last_key) {  // neighbouring candidates mostly share a cell
      last_id = table->Insert(x + 1, y + 1, z + 1, static_cast<uint32_t>(cell_keys.size()));
      if (last_id == cell_keys.size()) cell_keys.push_back(key);
      last_key = key;
    }
    cell_of[c] = last_id;
  }
  // Renumber cells by tile (8^3 cells), then phase (coordinates mod 3), so that step 3 works
  // through one small tile at a time with its cells' data close in memory.
  const size_t cells = cell_keys.size();
  const uint64_t field = kCellLimit - 1;
  auto phase_of = [&](uint64_t key) {
    return static_cast<int>((key >> (2 * kCellBits)) % 3 * 9 +
                            ((key >> kCellBits) & field) % 3 * 3 + (key & field) % 3);
  };
  auto tile_of = [&](uint64_t key) {
    return CellKey(key >> (2 * kCellBits) >> 3, ((key >> kCellBits) & field) >> 3,
                   (key & field) >> 3);
  };
  SplitMix64 rng(options.seed);
  int phase_rank[27];
  {
    int phase_order[27];
    for (int p = 0; p < 27; ++p) phase_order[p] = p;
    for (int m = 27; m > 1; --m) std::swap(phase_order[m - 1], phase_order[rng.Below(m)]);
    for (int p = 0; p < 27; ++p) phase_rank[phase_order[p]] = p;
  }
  LargeVector<uint32_t> rank(cells);
  {
    LargeVector<std::tuple<uint64_t, int, uint32_t>> sort_keys(cells);
    for (uint32_t id = 0; id < cells; ++id) {
      sort_keys[id] = {tile_of(cell_keys[id]), phase_rank[phase_of(cell_keys[id])], id};
    }
    std::sort(sort_keys.begin(), sort_keys.end());
    LargeVector<uint64_t> sorted_keys(cells);
    for (uint32_t r = 0; r < cells; ++r) {
      rank[std::get<2>(sort_keys[r])] = r;
      sorted_keys[r] = cell_keys[std::get<2>(sort_keys[r])];
    }
    cell_keys.swap(sorted_keys);
    for (uint32_t& id : cell_of) id = rank[id];
  }
  // A cell's neighbours (itself included) are read from a window around the tile of cells that
  // step 3 works through (the tiles are in the renumbered order): the renumbered ids of the
  // tile's cells and of the cells around it, copied from the few table tiles it overlaps.
  constexpr int kWindow = 10;  // a tile's 8 cells and one more each side, per axis
  std::vector<uint32_t> window(kWindow * kWindow * kWindow);
  // A cell's 27 neighbours as steps in the window, nearest first (itself, then faces, edges,
  // corners: most rejections end early).
  int ring_steps[27];
  {
    int k = 0;
    for (int ring = 0; ring <= 3; ++ring)
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz)
            if (std::abs(dx) + std::abs(dy) + std::abs(dz) == ring)
              ring_steps[k++] = (dx * kWindow + dy) * kWindow + dz;
  }
  int64_t window_base[3] = {0, 0, 0};  // the window's lowest cell, per axis
  // Fills the window around tile `tile` (a tile_of key).
  auto fill_window = [&](uint64_t tile) {
    int64_t* base = window_base;  // -1 beside tile 0: cells are numbered from 1
    base[0] = static_cast<int64_t>(tile >> (2 * kCellBits)) * 8 - 1;
    base[1] = static_cast<int64_t>((tile >> kCellBits) & field) * 8 - 1;
    base[2] = static_cast<int64_t>(tile & field) * 8 - 1;
    std::fill(window.begin(), window.end(), kNone);
    // The table tiles (4 cells wide) the window overlaps, and the cells of each in it.
    auto tiles = [&](int a) {
      return std::make_pair(std::max<int64_t>(0, base[a] >> 2), (base[a] + kWindow - 1) >> 2);
    };
    const auto [x0, x1] = tiles(0);
    const auto [y0, y1] = tiles(1);
    const auto [z0, z1] = tiles(2);
    for (int64_t tx = x0; tx <= x1; ++tx) {
      for (int64_t ty = y0; ty <= y1; ++ty) {
        for (int64_t tz = z0; tz <= z1; ++tz) {
          const uint32_t* ids = table->Tile(tx, ty, tz);
          if (!ids) continue;
          const int64_t t[3] = {tx, ty, tz};
          int64_t lo[3], hi[3];
          for (int a = 0; a < 3; ++a)
            lo[a] = std::max(4 * t[a], base[a]),
            hi[a] = std::min(4 * t[a] + 3, base[a] + kWindow - 1);
          for (int64_t x = lo[0]; x <= hi[0]; ++x) {
            for (int64_t y = lo[1]; y <= hi[1]; ++y) {
              for (int64_t z = lo[2]; z <= hi[2]; ++z) {
                const uint32_t id = ids[CellMap::Local(x, y, z)];
                if (id != kNone)
                  window[((x - base[0]) * kWindow + (y - base[1])) * kWindow + (z - base[2])] =
                      rank[id];
              }
            }
          }
        }
      }
    }
  };

  // 2. A seeded random order with locality (after Wei, "Parallel Poisson disk sampling", 2008):
  // each cell's candidates are shuffled; then, tile by tile, pass j tries the j-th candidate of
  // every cell of the tile, cells taken by phase in a seeded phase order. Cells of one phase are
  // at least 2r apart, so the order within a phase does not matter.
  LargeVector<uint32_t> cell_start(cells + 1, 0);
  for (size_t c = 0; c < n; ++c) ++cell_start[cell_of[c] + 1];
  for (size_t id = 0; id < cells; ++id) cell_start[id + 1] += cell_start[id];
  LargeVector<uint32_t> by_cell(n);
  {
    LargeVector<uint32_t> fill(cell_start.begin(), cell_start.end() - 1);
    for (size_t c = 0; c < n; ++c) by_cell[fill[cell_of[c]]++] = static_cast<uint32_t>(c);
  }
  LargeVector<uint32_t>().swap(cell_of);
  for (size_t id = 0; id < cells; ++id) {
    uint32_t* first = &by_cell[cell_start[id]];
    for (uint32_t m = cell_start[id + 1] - cell_start[id]; m > 1; --m) {
      std::swap(first[m - 1], first[rng.Below(m)]);
    }
  }

  // 3. Accept candidates farther than r from every accepted sample facing the same way. Each
  // cell keeps its first kInline accepted samples inline, for cache-friendly tests, and any
  // more (rare: cells are r wide) in a chain of overflow blocks. (Samples facing the same way
  // are at most 8 a cell, its corners; facing every way, as on rough detail, a few dozen.)
  constexpr uint32_t kInline = 2, kBlock = 6;
  struct Slots {
    uint32_t count;
    uint32_t more;  // with count > kInline: its first block in `overflow`
    uint32_t last;  // ... and its last
    Candidate p[kInline];
  };
  struct Block {
    Candidate p[kBlock];
    uint32_t next = kNone;
  };
  LargeVector<Slots> slots(cells);
  for (Slots& slot : slots) slot.count = 0;
  LargeVector<Block> overflow;
  LargeVector<uint32_t> accepted;
  accepted.reserve(static_cast<size_t>(predicted * 1.2) + 16);
  const float r2f = static_cast<float>(r2);
  // Too near an accepted piece facing the same way.
  auto near = [&](const Candidate& a, const Candidate& cand) {
    const float* p = a.offset;
    const float dx = p[0] - cand.offset[0], dy = p[1] - cand.offset[1], dz = p[2] - cand.offset[2];
    return dx * dx + dy * dy + dz * dz < r2f && SameSide(a.side, cand.side);
  };
  auto try_candidate = [&](uint32_t c, uint32_t cell) {
    const Candidate& cand = candidates[c];
    const uint64_t key = cell_keys[cell];
    const uint32_t* around =
        &window[((static_cast<int64_t>(key >> (2 * kCellBits)) - window_base[0]) * kWindow +
                 (static_cast<int64_t>((key >> kCellBits) & field) - window_base[1])) *
                    kWindow +
                static_cast<int64_t>(key & field) - window_base[2]];
    for (const int step : ring_steps) {
      if (around[step] == kNone) continue;
      const Slots& slot = slots[around[step]];
      for (uint32_t q = 0; q < std::min(slot.count, kInline); ++q)
        if (near(slot.p[q], cand)) return;
      uint32_t block = slot.more;
      for (uint32_t q = kInline; q < slot.count; q += kBlock, block = overflow[block].next) {
        for (uint32_t k = 0; k < std::min(kBlock, slot.count - q); ++k)
          if (near(overflow[block].p[k], cand)) return;
      }
    }
    Slots& own = slots[cell];
    Candidate* to = &own.p[0];
    if (own.count < kInline) {
      to = &own.p[own.count];
    } else {
      const uint32_t at = (own.count - kInline) % kBlock;
      if (at == 0) {  // a new block, first or chained
        const uint32_t block = static_cast<uint32_t>(overflow.size());
        overflow.emplace_back();
        if (own.count == kInline)
          own.more = block;
        else
          overflow[own.last].next = block;
        own.last = block;
      }
      to = &overflow[own.last].p[at];
    }
    *to = cand;
    ++own.count;
    accepted.push_back(c);
  };
  std::vector<uint32_t> active;
  for (size_t tile_begin = 0; tile_begin < cells;) {
    size_t tile_end = tile_begin + 1;
    const uint64_t tile = tile_of(cell_keys[tile_begin]);
    while (tile_end < cells && tile_of(cell_keys[tile_end]) == tile) ++tile_end;
    fill_window(tile);
    active.clear();
    for (size_t id = tile_begin; id < tile_end; ++id) active.push_back(static_cast<uint32_t>(id));
    for (uint32_t pass = 0; !active.empty(); ++pass) {
      size_t kept = 0;
      for (uint32_t cell : active) {  // in phase order: the renumbering sorted them so
        const uint32_t at = cell_start[cell] + pass;
        if (at >= cell_start[cell + 1]) continue;  // exhausted: drop from the list
        try_candidate(by_cell[at], cell);
        active[kept++] = cell;
      }
      active.resize(kept);
    }
    tile_begin = tile_end;
  }

  table.reset();
  LargeVector<uint32_t>().swap(rank);

  // 4. Points and normals, in triangle order.
  std::sort(accepted.begin(), accepted.end());
  std::optional<CornerNormals> corner_normals;
  if (options.smooth_normals) corner_normals.emplace(mesh, options.crease_angle_deg);
  const size_t accepted_count = accepted.size();
  out->points.resize(accepted_count);
  out->normals.resize(accepted_count);
  LargeVector<Candidate>().swap(candidates);  // no longer needed: step 4 cuts again
  // The triangle holding candidate c.
  auto triangle_of = [&first_candidate](uint32_t c) {
    return static_cast<size_t>(std::upper_bound(first_candidate.begin(), first_candidate.end(), c) -
                               first_candidate.begin() - 1);
  };
  // On several threads, each a run of whole triangles of about equal accepted pieces, each
  // sample written at its place in triangle order.
  const size_t parts4 =
      CuttingThreads(options.threads, static_cast<double>(accepted_count), kSamplesPerThread);
  std::vector<size_t> part_accepted(parts4 + 1, accepted_count);
  part_accepted[0] = 0;
  for (size_t part = 1; part < parts4; ++part) {
    const size_t at = accepted_count * part / parts4;
    // Moved back to its triangle's first accepted piece (a triangle is placed by one thread).
    part_accepted[part] =
        std::max(part_accepted[part - 1],
                 static_cast<size_t>(std::lower_bound(accepted.begin(), accepted.end(),
                                                      first_candidate[triangle_of(accepted[at])]) -
                                     accepted.begin()));
  }
  RunParts(parts4, [&](size_t part) {
    // Each triangle holding accepted pieces is cut again (the same pieces in the same order),
    // up to its last accepted piece; a piece's barycentric position is the mean of its
    // corners', as step 1 had it.
    std::vector<Piece<true>> uv_stack;
    for (size_t a = part_accepted[part]; a < part_accepted[part + 1];) {
      const size_t t = triangle_of(accepted[a]);
      std::array<Vec3, 3> corners;
      if (corner_normals) corners = corner_normals->Of(t);
      const size_t last = static_cast<size_t>(
          std::lower_bound(accepted.begin() + a, accepted.end(), first_candidate[t + 1]) -
          accepted.begin());
      uint32_t piece = first_candidate[t];
      SplitTriangle(mesh, t, h2, &uv_stack, [&](const Piece<true>& cut) {
        if (piece++ != accepted[a]) return true;
        const float u = static_cast<float>((cut.b[0][0] + cut.b[1][0] + cut.b[2][0]) / 3);
        const float v = static_cast<float>((cut.b[0][1] + cut.b[1][1] + cut.b[2][1]) / 3);
        out->points[a] = SamplePoint(mesh, t, u, v);
        out->normals[a] = SampleNormal(mesh, corner_normals ? &corners : nullptr, t, u, v);
        return ++a < last;
      });
    }
  });
  if (stats) stats->candidates = n, stats->samples = accepted_count;
  return Status::kOk;
}

void SampleMeshUniform(const TriangleMesh& mesh, size_t count, bool smooth_normals,
                       double crease_angle_deg, uint64_t seed, RawSamples* out) {
  out->clear();
  if (mesh.triangles.empty()) return;
  std::vector<double> cumulative(mesh.triangles.size());
  double total = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    total += Length(TriangleCross(mesh, t));
    cumulative[t] = total;
  }
  // Every triangle's corner normals, computed once: the samples pick triangles at random.
  std::vector<std::array<Vec3, 3>> corners;
  if (smooth_normals) {
    const CornerNormals corner_normals(mesh, crease_angle_deg);
    corners.reserve(mesh.triangles.size());
    for (size_t t = 0; t < mesh.triangles.size(); ++t) corners.push_back(corner_normals.Of(t));
  }
  SplitMix64 rng(seed);
  out->points.reserve(count);
  out->normals.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    const double pick = rng.Unit() * total;
    const size_t t = std::min<size_t>(
        std::upper_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin(),
        mesh.triangles.size() - 1);
    double u = rng.Unit(), v = rng.Unit();
    if (u + v > 1) u = 1 - u, v = 1 - v;
    out->push_back(SamplePoint(mesh, t, u, v),
                   SampleNormal(mesh, smooth_normals ? &corners[t] : nullptr, t, u, v));
  }
}

}  // namespace footfall
