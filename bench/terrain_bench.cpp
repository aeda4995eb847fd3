// Terrain engine benchmarks on a 1M-sample height field: grid build, bytes per sample, snap and
// next per query in random and spatially coherent order on 1 and 2 threads, and batched RPC
// throughput against a real footfalld on loopback. Baselines measured in the same run: brute
// force, a nanoflann k-d tree, and the embedded engine for the RPC figures.
//
//   build/bench/terrain_bench --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include <nanoflann.hpp>

#include "footfall/client/terrain_session.h"
#include "footfall/import/terrain_generators.h"
#include "footfall/terrain/brute_force.h"
#include "footfall/terrain/grid.h"
#include "server_process.h"

using namespace footfall;

namespace {

constexpr int kSide = 1000;       // 1000 x 1000 = 1M samples
constexpr double kSpacing = 0.1;  // 100 m x 100 m
constexpr size_t kQueries = 1 << 16;

const RawSamples& Samples() {
  static const RawSamples s = MakeHeightField(kSide, kSide, kSpacing, 0.15, 3);
  return s;
}

const TerrainGrid& Grid() {
  static const TerrainGrid g = [] {
    TerrainGrid grid;
    std::string error;
    TerrainGrid::Build(Samples(), GridOptions{}, &grid, &error);
    return grid;
  }();
  return g;
}

// Random order: foot-like query points (terrain samples jittered by up to 5 cm) in random order.
const std::vector<Vec3>& RandomPoints() {
  static const std::vector<Vec3> q = [] {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> jitter(-0.05, 0.05);
    const RawSamples& s = Samples();
    std::vector<Vec3> v(kQueries);
    for (auto& p : v) p = s.points[rng() % s.size()] + Vec3{jitter(rng), jitter(rng), jitter(rng)};
    return v;
  }();
  return q;
}

// Coherent order: the same points sorted along a serpentine path (1 m rows), as a walking
// character or a crowd sorted by position would ask them.
const std::vector<Vec3>& CoherentPoints() {
  static const std::vector<Vec3> q = [] {
    std::vector<Vec3> v = RandomPoints();
    auto key = [](const Vec3& p) {
      const int row = static_cast<int>(std::floor(p.z));
      return std::make_pair(row, row % 2 ? -p.x : p.x);
    };
    std::sort(v.begin(), v.end(), [&](const Vec3& a, const Vec3& b) { return key(a) < key(b); });
    return v;
  }();
  return q;
}

// Dense coherent order: as many points from a 25 x 25 m patch (about one query per sample
// there, as dense as a crowd's feet and swing arcs), sorted along 25 cm serpentine rows:
// consecutive queries reuse cells, which the sparse coherent order over the whole terrain
// (6.5 queries per square metre against 100 samples) does not.
const std::vector<Vec3>& DenseCoherentPoints() {
  static const std::vector<Vec3> q = [] {
    std::mt19937_64 rng(2);
    std::uniform_real_distribution<double> jitter(-0.05, 0.05);
    const RawSamples& s = Samples();
    const double side = 0.25 * kSide * kSpacing;
    std::vector<Vec3> v;
    v.reserve(kQueries);
    while (v.size() < kQueries) {
      const Vec3& p = s.points[rng() % s.size()];
      if (p.x < side && p.z < side) v.push_back(p + Vec3{jitter(rng), jitter(rng), jitter(rng)});
    }
    auto key = [](const Vec3& p) {
      const int row = static_cast<int>(std::floor(p.z * 4));
      return std::make_pair(row, row % 2 ? -p.x : p.x);
    };
    std::sort(v.begin(), v.end(), [&](const Vec3& a, const Vec3& b) { return key(a) < key(b); });
    return v;
  }();
  return q;
}

std::vector<StepQuery> StepsFrom(const std::vector<Vec3>& points) {
  std::vector<StepQuery> steps(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const double a = 0.37 * static_cast<double>(i);
    steps[i] = {points[i], {0.6 * std::cos(a), 0, 0.6 * std::sin(a)}};  // 60 cm steps
  }
  return steps;
}

const std::vector<Vec3>& Points(int order) {
  return order == 0 ? RandomPoints() : order == 1 ? CoherentPoints() : DenseCoherentPoints();
}
const char* OrderName(int order) {
  return order == 0 ? "random" : order == 1 ? "coherent" : "dense coherent";
}

// --- the grid --------------------------------------------------------------------------------

void BM_GridBuild(benchmark::State& state) {
  const RawSamples& s = Samples();
  size_t bytes = 0;
  for (auto _ : state) {
    TerrainGrid g;
    std::string error;
    TerrainGrid::Build(s, GridOptions{}, &g, &error);
    bytes = g.stats().bytes;
    benchmark::DoNotOptimize(g);
  }
  state.counters["samples"] = static_cast<double>(s.size());
  state.counters["bytes_per_sample"] = static_cast<double>(bytes) / s.size();
  const GridStats& st = Grid().stats();
  state.counters["samples_per_cell"] = static_cast<double>(s.size()) / st.occupied_cells;
}
BENCHMARK(BM_GridBuild)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

void BM_GridSnap(benchmark::State& state) {
  const TerrainGrid& g = Grid();
  const std::vector<Vec3>& q = Points(static_cast<int>(state.range(0)));
  // Each thread takes its own stretch of the query sequence.
  size_t i = static_cast<size_t>(state.thread_index()) * (kQueries / 2);
  for (auto _ : state) {
    benchmark::DoNotOptimize(g.Snap(q[i++ & (kQueries - 1)]));
  }
  state.SetLabel(OrderName(static_cast<int>(state.range(0))));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_GridSnap)->Arg(0)->Arg(1)->Arg(2)->Threads(1)->Threads(2)->UseRealTime();

void BM_GridNext(benchmark::State& state) {
  const TerrainGrid& g = Grid();
  static const std::vector<StepQuery> random = StepsFrom(RandomPoints());
  static const std::vector<StepQuery> coherent = StepsFrom(CoherentPoints());
  const std::vector<StepQuery>& q = state.range(0) == 0 ? random : coherent;
  size_t i = static_cast<size_t>(state.thread_index()) * (kQueries / 2);
  for (auto _ : state) {
    benchmark::DoNotOptimize(g.Next(q[i++ & (kQueries - 1)], 0));
  }
  state.SetLabel(OrderName(static_cast<int>(state.range(0))));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_GridNext)->Arg(0)->Arg(1)->Threads(1)->Threads(2)->UseRealTime();

// Batches of 4096 queries, which prefetch ahead (TerrainGrid::SnapBatch / NextBatch).
void BM_GridSnapBatch(benchmark::State& state) {
  const TerrainGrid& g = Grid();
  const std::vector<Vec3>& q = Points(static_cast<int>(state.range(0)));
  std::vector<Foothold> out(4096);
  size_t offset = 0;
  for (auto _ : state) {
    g.SnapBatch(&q[offset], out.size(), out.data());
    benchmark::DoNotOptimize(out.data());
    offset = (offset + out.size()) % (kQueries - out.size());
  }
  state.SetLabel(OrderName(static_cast<int>(state.range(0))));
  state.SetItemsProcessed(state.iterations() * out.size());
}
BENCHMARK(BM_GridSnapBatch)->Arg(0)->Arg(1)->UseRealTime();

void BM_GridNextBatch(benchmark::State& state) {
  const TerrainGrid& g = Grid();
  static const std::vector<StepQuery> random = StepsFrom(RandomPoints());
  static const std::vector<StepQuery> coherent = StepsFrom(CoherentPoints());
  const std::vector<StepQuery>& q = state.range(0) == 0 ? random : coherent;
  std::vector<Foothold> out(4096);
  size_t offset = 0;
  for (auto _ : state) {
    g.NextBatch(&q[offset], out.size(), 0, out.data());
    benchmark::DoNotOptimize(out.data());
    offset = (offset + out.size()) % (kQueries - out.size());
  }
  state.SetLabel(OrderName(static_cast<int>(state.range(0))));
  state.SetItemsProcessed(state.iterations() * out.size());
}
BENCHMARK(BM_GridNextBatch)->Arg(0)->Arg(1)->UseRealTime();

// A malicious or careless next query: off the terrain's edge, outward, with a tolerance far
// larger than the terrain, so that no sample is a candidate. Baseline: brute force.
void BM_GridNextNoCandidate(benchmark::State& state) {
  const TerrainGrid& g = Grid();
  const GridStats& st = g.stats();
  const StepQuery q{{st.bounds_max.x, 0, 0.5 * (st.bounds_min.z + st.bounds_max.z)}, {0.6, 0, 0}};
  const bool brute = state.range(0) == 1;
  static const BruteForce oracle(Grid());
  for (auto _ : state) benchmark::DoNotOptimize(brute ? oracle.Next(q, 1e6) : g.Next(q, 1e6));
  state.SetLabel(brute ? "brute force" : "grid");
}
BENCHMARK(BM_GridNextNoCandidate)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// --- baselines: brute force and a k-d tree -------------------------------------------------

void BM_BruteForceSnap(benchmark::State& state) {
  const BruteForce oracle(Grid());
  const std::vector<Vec3>& q = RandomPoints();
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(oracle.Snap(q[i++ & (kQueries - 1)]));
  state.SetLabel("random");
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_BruteForceSnap)->Unit(benchmark::kMicrosecond)->Iterations(50);

struct Cloud {
  const std::vector<Vec3>* points;
  size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(size_t i, size_t dim) const {
    const Vec3& p = (*points)[i];
    return dim == 0 ? p.x : dim == 1 ? p.y : p.z;
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>,
                                                   Cloud, 3, uint32_t>;

const Cloud& TheCloud() {
  static const Cloud c{&Samples().points};
  return c;
}

void BM_KdTreeBuild(benchmark::State& state) {
  for (auto _ : state) {
    KdTree tree(3, TheCloud(), nanoflann::KDTreeSingleIndexAdaptorParams(10));
    benchmark::DoNotOptimize(tree.vAcc.data());
  }
}
BENCHMARK(BM_KdTreeBuild)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

void BM_KdTreeSnap(benchmark::State& state) {
  static const KdTree tree(3, TheCloud(), nanoflann::KDTreeSingleIndexAdaptorParams(10));
  const std::vector<Vec3>& q = Points(static_cast<int>(state.range(0)));
  size_t i = static_cast<size_t>(state.thread_index()) * (kQueries / 2);
  for (auto _ : state) {
    const Vec3& p = q[i++ & (kQueries - 1)];
    const double query[3] = {p.x, p.y, p.z};
    uint32_t index;
    double d2;
    tree.knnSearch(query, 1, &index, &d2);
    benchmark::DoNotOptimize(index);
  }
  state.SetLabel(OrderName(static_cast<int>(state.range(0))));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_KdTreeSnap)->Arg(0)->Arg(1)->Arg(2)->Threads(1)->Threads(2)->UseRealTime();

// --- batches: embedded and over RPC ----------------------------------------------------------

constexpr size_t kBatch = 4096;  // FF_MAX_BATCH

struct Backends {
  std::unique_ptr<test::ServerProcess> server;
  std::unique_ptr<TerrainSession> rpc, embedded;
  TerrainHandle rpc_terrain = 0, embedded_terrain = 0;
};

Backends& TheBackends() {
  static Backends b = [] {
    Backends x;
    x.server = std::make_unique<test::ServerProcess>();
    RpcOptions o;
    o.port = x.server->port();
    o.call_timeout_s = 60;
    x.rpc = MakeRpcSession(o);
    // As many threads as footfalld answers batches with (its default: every core).
    x.embedded =
        MakeEmbeddedSession(static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
    x.rpc->LoadSamples(Samples(), "bench", &x.rpc_terrain);
    x.embedded->LoadSamples(Samples(), "bench", &x.embedded_terrain);
    return x;
  }();
  return b;
}

// Batches of FF_MAX_BATCH queries through a TerrainSession, embedded or over RPC, in random
// (Arg 0) or coherent (Arg 1) order.
void BatchBench(benchmark::State& state, bool rpc, bool next) {
  Backends& b = TheBackends();
  TerrainSession& s = rpc ? *b.rpc : *b.embedded;
  const TerrainHandle t = rpc ? b.rpc_terrain : b.embedded_terrain;
  const int order = static_cast<int>(state.range(0));
  static const std::vector<StepQuery> random_steps = StepsFrom(RandomPoints());
  static const std::vector<StepQuery> coherent_steps = StepsFrom(CoherentPoints());
  const std::vector<StepQuery>& steps = order == 0 ? random_steps : coherent_steps;
  const std::vector<Vec3>& points = Points(order);
  std::vector<Foothold> out(kBatch);
  size_t offset = 0;
  for (auto _ : state) {
    const Status st = next ? s.Next(t, &steps[offset], kBatch, 0, out.data())
                           : s.Snap(t, &points[offset], kBatch, out.data());
    if (st != Status::kOk) state.SkipWithError(s.last_error().c_str());
    offset = (offset + kBatch) % (kQueries - kBatch);
  }
  state.SetLabel(std::string(rpc ? "rpc" : "embedded") + (next ? " next" : " snap") +
                 " batch of 4096, " + OrderName(order));
  state.SetItemsProcessed(state.iterations() * kBatch);
}

void BM_EmbeddedSnapBatch(benchmark::State& state) { BatchBench(state, false, false); }
void BM_RpcSnapBatch(benchmark::State& state) { BatchBench(state, true, false); }
void BM_EmbeddedNextBatch(benchmark::State& state) { BatchBench(state, false, true); }
void BM_RpcNextBatch(benchmark::State& state) { BatchBench(state, true, true); }
BENCHMARK(BM_EmbeddedSnapBatch)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_RpcSnapBatch)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_EmbeddedNextBatch)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_RpcNextBatch)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond)->UseRealTime();

// The floor of the batch path: snap batches of non-finite points, which the engine refuses at
// once (each answer kInvalidArgument), on the benchmark terrain. The RPC figure is the
// transport's own ceiling (client and server coding, copies, system calls, wake-ups), the
// embedded one the cost of the session call.
void FloorBench(benchmark::State& state, bool rpc) {
  Backends& b = TheBackends();
  TerrainSession& s = rpc ? *b.rpc : *b.embedded;
  const TerrainHandle t = rpc ? b.rpc_terrain : b.embedded_terrain;
  const std::vector<Vec3> points(kBatch, Vec3{std::nan(""), 0, 0});
  std::vector<Foothold> out(kBatch);
  for (auto _ : state) {
    const Status st = s.Snap(t, points.data(), kBatch, out.data());
    if (st != Status::kOk) state.SkipWithError(s.last_error().c_str());
  }
  state.SetLabel(std::string(rpc ? "rpc" : "embedded") + " snap batch of 4096 refused points");
  state.SetItemsProcessed(state.iterations() * kBatch);
}
void BM_EmbeddedBatchFloor(benchmark::State& state) { FloorBench(state, false); }
void BM_RpcBatchFloor(benchmark::State& state) { FloorBench(state, true); }
BENCHMARK(BM_EmbeddedBatchFloor)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK(BM_RpcBatchFloor)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
