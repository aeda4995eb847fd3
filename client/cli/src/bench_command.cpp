// `footfall bench`: how fast footfall answers on a given terrain, through the same session as
// `footfall query` (the embedded engine, or footfalld with --server). It reports the load time,
// the grid's memory, and snap / next times in random and spatially coherent order, one query per
// call and in batches, each beside a baseline measured in the same run: a brute-force scan of
// the samples for single queries, the embedded engine for RPC batches.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iomanip>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "footfall/cli/number_checks.h"
#include "footfall/import/terrain_loader.h"
#include "footfall/terrain/brute_force.h"
#include "footfall/terrain/large_memory.h"
#include "terrain_flags.h"

namespace footfall::cli {
namespace {

// Whether a query got an answer: a foothold, or none found (not refused as invalid).
bool Answered(Status s) { return s == Status::kOk || s == Status::kNoFoothold; }

using Clock = std::chrono::steady_clock;

// [Units: bytes] Memory per query point: its random and coherent points, steps and answers
// (measured 144 resident).
constexpr double kBytesPerQuery = 160;

struct BenchFlags {
  TerrainFlags terrain;
  size_t queries = 65536;
  size_t batch = 4096;
  double jitter = -1;  // < 0: a quarter of the grid's cell size
  double step = 0;     // 0: twice the grid's cell size
  double min_time = 0.3;
  uint64_t seed = 1;
  bool json = false;
};

// Seconds since `start`.
double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Runs `pass` (which answers `per_pass` queries) until at least min_time seconds have passed
// and returns nanoseconds per query; the first pass warms caches and is not counted.
double NsPerQuery(const std::function<bool()>& pass, size_t per_pass, double min_time, bool* ok) {
  *ok = pass();
  size_t passes = 0;
  const Clock::time_point start = Clock::now();
  double elapsed = 0;
  while (*ok && (passes == 0 || elapsed < min_time)) {
    *ok = pass();
    ++passes;
    elapsed = Since(start);
  }
  return elapsed * 1e9 / static_cast<double>(passes * per_pass);
}

// Interleaves the bits of three 21-bit integers (a Morton code).
uint64_t Morton(uint64_t x, uint64_t y, uint64_t z) {
  auto spread = [](uint64_t v) {
    uint64_t r = 0;
    for (int b = 0; b < 21; ++b) r |= ((v >> b) & 1u) << (3 * b);
    return r;
  };
  return spread(x) | spread(y) << 1 | spread(z) << 2;
}

// The same points sorted along a Morton curve over the terrain bounds: each query near the
// one before, as a walking character or a crowd sorted by position asks them.
std::vector<Vec3> CoherentOrder(std::vector<Vec3> points, const Vec3& lo, const Vec3& hi) {
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-300});
  const double scale = static_cast<double>((1u << 21) - 1) / extent;
  auto code = [&](const Vec3& p) {
    auto q = [&](double v, double l) {
      return static_cast<uint64_t>(std::clamp((v - l) * scale, 0.0, double((1u << 21) - 1)));
    };
    return Morton(q(p.x, lo.x), q(p.y, lo.y), q(p.z, lo.z));
  };
  std::vector<std::pair<uint64_t, size_t>> keys(points.size());
  for (size_t i = 0; i < points.size(); ++i) keys[i] = {code(points[i]), i};
  std::sort(keys.begin(), keys.end());
  std::vector<Vec3> sorted(points.size());
  for (size_t i = 0; i < keys.size(); ++i) sorted[i] = points[keys[i].second];
  return sorted;
}

// Foot-like query points: uniform points of the bounds snapped to the terrain, then moved by
// up to `jitter` along each axis.
Status MakeQueries(TerrainSession& session, TerrainHandle terrain, const GridStats& stats,
                   const BenchFlags& flags, double jitter, std::vector<Vec3>* out,
                   std::string* error) {
  std::mt19937_64 rng(flags.seed);
  std::uniform_real_distribution<double> u(0, 1), j(-jitter, jitter);
  const Vec3 lo = stats.bounds_min, hi = stats.bounds_max;
  std::vector<Vec3> uniform(flags.queries);
  for (Vec3& p : uniform)
    p = {lo.x + u(rng) * (hi.x - lo.x), lo.y + u(rng) * (hi.y - lo.y),
         lo.z + u(rng) * (hi.z - lo.z)};
  std::vector<Foothold> snapped(uniform.size());
  for (size_t b = 0; b < uniform.size(); b += flags.batch) {
    const size_t n = std::min(flags.batch, uniform.size() - b);
    if (session.Snap(terrain, &uniform[b], n, &snapped[b]) != Status::kOk) {
      *error = session.last_error();
      return Status::kUnavailable;
    }
  }
  out->resize(uniform.size());
  for (size_t i = 0; i < uniform.size(); ++i)
    (*out)[i] = snapped[i].point + Vec3{j(rng), j(rng), j(rng)};
  return Status::kOk;
}

// Steps of length `step` from each point, in directions turning around the terrain's up-ish
// axis (the bounds' thinnest axis).
std::vector<StepQuery> MakeSteps(const std::vector<Vec3>& points, const GridStats& stats,
                                 double step) {
  const Vec3 e = stats.bounds_max - stats.bounds_min;
  const int up = e.x <= e.y && e.x <= e.z ? 0 : e.y <= e.z ? 1 : 2;
  std::vector<StepQuery> steps(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const double a = 0.37 * static_cast<double>(i);
    const double c = step * std::cos(a), s = step * std::sin(a);
    const Vec3 d = up == 0 ? Vec3{0, c, s} : up == 1 ? Vec3{c, 0, s} : Vec3{c, s, 0};
    steps[i] = {points[i], d};
  }
  return steps;
}

struct Figure {
  std::string name;    // e.g. "snap random, batches of 4096"
  double ns = 0;       // per query
  std::string base;    // what it is compared with
  double base_ns = 0;  // the baseline's time per query (0: none)
};

int RunBench(const BenchFlags& flags) {
  const std::string who = "footfall bench: ";
  if (flags.queries == 0 || flags.batch == 0) {
    std::cerr << who << "--queries and --batch must be positive\n";
    return 1;
  }
  // The query points, steps and answers: as many as this machine holds, refused before the
  // terrain is loaded (--queries 16777216 under a 2 GB limit ran out of memory after 25 s).
  if (const double bytes = static_cast<double>(flags.queries) * kBytesPerQuery,
      memory = UsableMemoryBytes();
      memory > 0 && bytes > memory) {
    std::cerr << who << std::setprecision(3) << "--queries " << flags.queries << " needs about "
              << bytes / 1e9 << " GB for its queries, more than the " << memory / 1e9
              << " GB of memory this process may use (give fewer)\n";
    return 1;
  }
  std::unique_ptr<TerrainSession> session;
  TerrainHandle terrain = 0;
  std::string error;
  const Clock::time_point load_start = Clock::now();
  if (OpenTerrain(flags.terrain, &session, &terrain, &error) != Status::kOk) {
    std::cerr << who << error << '\n';
    return 1;
  }
  const double load_s = Since(load_start);
  TerrainInfo info;
  if (session->Info(terrain, &info) != Status::kOk) {
    std::cerr << who << session->last_error() << '\n';
    return 1;
  }
  const GridStats& st = info.stats;
  if (st.samples == 0) {
    std::cerr << who << info.name << ": the terrain has no samples\n";
    return 1;
  }
  const double jitter = flags.jitter >= 0 ? flags.jitter : 0.25 * st.cell_size;
  const double step = flags.step > 0 ? flags.step : 2 * st.cell_size;
  std::vector<Vec3> random;
  if (MakeQueries(*session, terrain, st, flags, jitter, &random, &error) != Status::kOk) {
    std::cerr << who << error << '\n';
    return 1;
  }
  const std::vector<Vec3> coherent = CoherentOrder(random, st.bounds_min, st.bounds_max);
  const std::vector<StepQuery> random_steps = MakeSteps(random, st, step);
  const std::vector<StepQuery> coherent_steps = MakeSteps(coherent, st, step);

  // Queries the engine refuses (a step whose ideal point lies beyond the query range, on a
  // terrain at huge coordinates) are timed as refusals: counted first, and said beside the
  // figures (they were timed as answers, without a word).
  size_t refused_snaps = 0, refused_nexts = 0;
  {
    std::vector<Foothold> answers(std::min<size_t>(random.size(), 4096));
    for (size_t b = 0; b < random.size(); b += answers.size()) {
      const size_t count = std::min(answers.size(), random.size() - b);
      if (session->Snap(terrain, &random[b], count, answers.data()) == Status::kOk)
        for (size_t i = 0; i < count; ++i) refused_snaps += !Answered(answers[i].status);
      if (session->Next(terrain, &random_steps[b], count, 0, answers.data()) == Status::kOk)
        for (size_t i = 0; i < count; ++i) refused_nexts += !Answered(answers[i].status);
    }
  }

  // The brute-force baseline needs the samples here: read the terrain file once more.
  std::unique_ptr<TerrainGrid> local;
  if (!flags.terrain.terrain.empty()) {
    RawSamples samples;
    local = std::make_unique<TerrainGrid>();
    if (LoadTerrain(flags.terrain.terrain, flags.terrain.load, &samples, &error) != Status::kOk ||
        TerrainGrid::Build(samples, GridOptions{}, local.get(), &error) != Status::kOk) {
      std::cerr << who << error << '\n';
      return 1;
    }
  }
  // The embedded baseline of RPC batches: the same terrain in this process.
  std::unique_ptr<TerrainSession> embedded;
  TerrainHandle embedded_terrain = 0;
  if (!flags.terrain.server.empty() && !flags.terrain.terrain.empty()) {
    embedded = MakeEmbeddedSession(flags.terrain.threads);
    if (embedded->LoadFile(flags.terrain.terrain, flags.terrain.load, &embedded_terrain) !=
        Status::kOk) {
      std::cerr << who << embedded->last_error() << '\n';
      return 1;
    }
  }

  std::vector<Figure> figures;
  bool ok = true;
  std::vector<Foothold> out(std::max(flags.batch, size_t{1}));
  const size_t n = random.size();
  const bool rpc = !flags.terrain.server.empty();
  // One query per call: a fixed stretch of the sequence, so RPC round trips stay bounded.
  const size_t singles = std::min<size_t>(n, rpc ? 2048 : n);
  auto single_snaps = [&](TerrainSession& s, TerrainHandle t, const std::vector<Vec3>& q) {
    return [&s, t, &q, &out, singles] {
      for (size_t i = 0; i < singles; ++i)
        if (s.Snap(t, &q[i], 1, out.data()) != Status::kOk) return false;
      return true;
    };
  };
  auto single_nexts = [&](TerrainSession& s, TerrainHandle t, const std::vector<StepQuery>& q) {
    return [&s, t, &q, &out, singles] {
      for (size_t i = 0; i < singles; ++i)
        if (s.Next(t, &q[i], 1, 0, out.data()) != Status::kOk) return false;
      return true;
    };
  };
  auto batch_snaps = [&](TerrainSession& s, TerrainHandle t, const std::vector<Vec3>& q) {
    return [&s, t, &q, &out, n, &flags] {
      for (size_t b = 0; b < n; b += flags.batch)
        if (s.Snap(t, &q[b], std::min(flags.batch, n - b), out.data()) != Status::kOk) return false;
      return true;
    };
  };
  auto batch_nexts = [&](TerrainSession& s, TerrainHandle t, const std::vector<StepQuery>& q) {
    return [&s, t, &q, &out, n, &flags] {
      for (size_t b = 0; b < n; b += flags.batch)
        if (s.Next(t, &q[b], std::min(flags.batch, n - b), 0, out.data()) != Status::kOk)
          return false;
      return true;
    };
  };
  // Brute force over a few queries (each scans every sample).
  double brute_snap = 0, brute_next = 0;
  if (local) {
    const BruteForce oracle(*local);
    const size_t k = std::max<size_t>(1, std::min<size_t>(n, 2e7 / st.samples));
    bool unused;
    brute_snap = NsPerQuery(
        [&] {
          for (size_t i = 0; i < k; ++i) out[0] = oracle.Snap(random[i]);
          return true;
        },
        k, 0.1, &unused);
    brute_next = NsPerQuery(
        [&] {
          for (size_t i = 0; i < k; ++i) out[0] = oracle.Next(random_steps[i], 0);
          return true;
        },
        k, 0.1, &unused);
  }
  const std::string batch_name =
      "batches of " + std::to_string(std::min(flags.batch, flags.queries));
  for (int order = 0; order < 2 && ok; ++order) {
    const std::string o = order == 0 ? "random" : "coherent";
    const std::vector<Vec3>& q = order == 0 ? random : coherent;
    const std::vector<StepQuery>& sq = order == 0 ? random_steps : coherent_steps;
    bool good = true;
    figures.push_back(
        {"snap " + o + ", one per call",
         NsPerQuery(single_snaps(*session, terrain, q), singles, flags.min_time, &good),
         local ? "brute force" : "", brute_snap});
    ok = ok && good;
    figures.push_back(
        {"next " + o + ", one per call",
         NsPerQuery(single_nexts(*session, terrain, sq), singles, flags.min_time, &good),
         local ? "brute force" : "", brute_next});
    ok = ok && good;
    Figure snaps{"snap " + o + ", " + batch_name,
                 NsPerQuery(batch_snaps(*session, terrain, q), n, flags.min_time, &good), "", 0};
    ok = ok && good;
    Figure nexts{"next " + o + ", " + batch_name,
                 NsPerQuery(batch_nexts(*session, terrain, sq), n, flags.min_time, &good), "", 0};
    ok = ok && good;
    if (embedded) {
      bool eg = true;
      snaps.base = "embedded";
      snaps.base_ns =
          NsPerQuery(batch_snaps(*embedded, embedded_terrain, q), n, flags.min_time, &eg);
      nexts.base = "embedded";
      nexts.base_ns =
          NsPerQuery(batch_nexts(*embedded, embedded_terrain, sq), n, flags.min_time, &eg);
      ok = ok && eg;
    }
    figures.push_back(snaps);
    figures.push_back(nexts);
  }
  if (!ok) {
    std::cerr << who << "a query failed: " << session->last_error() << '\n';
    return 1;
  }

  const double bytes_per_sample =
      static_cast<double>(st.bytes) / static_cast<double>(std::max<size_t>(st.samples, 1));
  if (flags.json) {
    nlohmann::ordered_json j;
    j["backend"] = session->Describe();
    j["samples"] = st.samples;
    j["cells"] = {st.cells[0], st.cells[1], st.cells[2]};
    j["cell_size"] = st.cell_size;
    j["occupied_cells"] = st.occupied_cells;
    j["bytes_per_sample"] = bytes_per_sample;
    j["load_s"] = load_s;
    j["queries"] = n;
    j["jitter"] = jitter;
    j["step"] = step;
    j["refused_snap_queries"] = refused_snaps;
    j["refused_next_queries"] = refused_nexts;
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const Figure& f : figures) {
      nlohmann::ordered_json e = {
          {"name", f.name}, {"ns_per_query", f.ns}, {"queries_per_s", 1e9 / f.ns}};
      if (f.base_ns > 0) {
        e["baseline"] = f.base;
        e["baseline_ns_per_query"] = f.base_ns;
        e["ratio"] = f.ns / f.base_ns;
      }
      list.push_back(e);
    }
    j["figures"] = list;
    std::cout << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << '\n';
    return 0;
  }
  std::cout << "backend: " << session->Describe() << '\n'
            << "terrain: " << st.samples << " samples, grid " << st.cells[0] << " x " << st.cells[1]
            << " x " << st.cells[2] << " cells of " << st.cell_size << " (" << st.occupied_cells
            << " occupied), " << std::fixed << std::setprecision(1) << bytes_per_sample
            << " bytes per sample\n"
            << "load ("
            << (!rpc                            ? "read, build"
                : flags.terrain.terrain.empty() ? "footfalld reads, builds"
                                                : "read, upload, build")
            << "): " << std::setprecision(3) << load_s << " s\n"
            << "queries: " << n << " foot-like points (jitter " << std::defaultfloat << jitter
            << "), steps of " << step << '\n';
  for (const Figure& f : figures) {
    std::cout << "  " << std::left << std::setw(40) << f.name << std::right << std::fixed
              << std::setprecision(0) << std::setw(10) << f.ns << " ns/query";
    if (f.base_ns > 0)
      // (Three significant digits: against brute force on a large terrain, three decimals
      // read x0.000.)
      std::cout << "   " << f.base << " " << f.base_ns << " ns (x" << std::defaultfloat
                << std::setprecision(3) << f.ns / f.base_ns << ")";
    std::cout << std::defaultfloat << '\n';
  }
  if (refused_snaps + refused_nexts > 0) {
    std::cerr << who << "note: of the " << n << " queries, " << refused_snaps << " snap and "
              << refused_nexts << " next queries are refused as invalid (points or ideal points "
              << "with a coordinate more than 1e15 from the terrain's centre: steps of " << step
              << "); their figures time the refusal (give a smaller --step)\n";
  }
  return 0;
}

}  // namespace

void AddBenchCommand(CLI::App& app, int* exit_code) {
  auto flags = std::make_shared<BenchFlags>();
  CLI::App* cmd = app.add_subcommand(
      "bench",
      "Measure load time, memory and snap / next speed on a terrain (embedded, or footfalld "
      "with --server), beside brute force and, over RPC, the embedded engine");
  AddTerrainFlags(cmd, &flags->terrain);
  cmd->add_option("--threads", flags->terrain.threads, "threads of the embedded engine's batches")
      ->transform(WholeRange(1, 256));
  cmd->add_option("--queries", flags->queries, "query points per pass")
      ->transform(WholeRange(1, 1 << 24));
  cmd->add_option("--batch", flags->batch,
                  "queries per batch call (over RPC, a batch above 4096 goes as several calls)")
      ->transform(WholeRange(1, 1 << 20));
  cmd->add_option("--jitter", flags->jitter,
                  "how far query points lie off the terrain, per axis (default: a quarter cell)")
      ->check(FiniteRange(0, 1e12));
  cmd->add_option("--step", flags->step, "step length of next queries (default: two cells)")
      ->check(FiniteAboveUpTo(0, 1e12));
  cmd->add_option("--min-time", flags->min_time, "seconds each figure is measured for at least")
      ->check(FiniteRange(0.001, 3600));
  cmd->add_option("--query-seed", flags->seed, "seed of the query points")->transform(Seed());
  cmd->add_flag("--json", flags->json, "write the figures as one JSON object");
  cmd->callback([flags, exit_code] { *exit_code = RunBench(*flags); });
}

}  // namespace footfall::cli
