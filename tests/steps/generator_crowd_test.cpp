// The step generator's crowds and runs: batched queries, characters left out, passes, key
// memory, determinism across threads, and options refused with their reason.
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <string>

#include <catch2/catch.hpp>

#include "footfall/import/mesh_generators.h"
#include "footfall/import/mesh_sampler.h"
#include "footfall/import/terrain_generators.h"
#include "footfall/import/terrain_loader.h"
#include "generator_fixtures.h"
#include "walk_checks.h"

using namespace footfall;
using namespace footfall::test;

namespace {

// A real embedded session that counts the batch calls it serves.
class CountingSession final : public TerrainSession {
 public:
  CountingSession() : inner_(MakeEmbeddedSession()) {}
  Status LoadServerFile(const std::string& p, const TerrainLoadOptions& o,
                        TerrainHandle* out) override {
    return inner_->LoadServerFile(p, o, out);
  }
  Status LoadSamples(const RawSamples& s, const std::string& n, TerrainHandle* out) override {
    return inner_->LoadSamples(s, n, out);
  }
  Status Info(TerrainHandle t, TerrainInfo* out) override { return inner_->Info(t, out); }
  Status Unload(TerrainHandle t) override { return inner_->Unload(t); }
  Status Snap(TerrainHandle t, const Vec3* p, size_t n, Foothold* out) override {
    ++snaps;
    return inner_->Snap(t, p, n, out);
  }
  Status Normal(TerrainHandle t, const Vec3* p, size_t n, Foothold* out) override {
    ++snaps;
    return inner_->Normal(t, p, n, out);
  }
  Status Next(TerrainHandle t, const StepQuery* q, size_t n, double tol, Foothold* out) override {
    ++nexts, next_queries += n;
    return inner_->Next(t, q, n, tol, out);
  }
  std::string Describe() const override { return "counting " + inner_->Describe(); }
  bool InProcess() const override { return !remote && inner_->InProcess(); }
  size_t snaps = 0, nexts = 0, next_queries = 0;
  bool remote = false;  // says it answers out of process, as an RPC session does

 private:
  std::unique_ptr<TerrainSession> inner_;
};

}  // namespace

TEST_CASE("A crowd batches every character's queries into one call per round",
          "[steps][generator][crowd]") {
  const Character c = LoadShipped("hexapod");
  const RawSamples ground = MakeFlat(300, 0.012, 0);
  auto run = [&](int crowd, CountingSession* session, Walk* w) {
    TerrainHandle h;
    REQUIRE(session->LoadSamples(ground, "flat", &h) == Status::kOk);
    GenerateOptions o = CrowdOptions({1.8, 0, 1.2}, 10, crowd, 0.5);
    std::string error;
    REQUIRE(GenerateWalk(*session, h, c, o, w, &error) == Status::kOk);
    Terrain t = LoadTerrain(ground, 0.012);
    CheckWalk(t, c, o, *w);
  };
  CountingSession one, many;
  Walk w1, w9;
  run(1, &one, &w1);
  run(9, &many, &w9);
  CHECK(w9.stopped.empty());
  CHECK(many.next_queries == 9 * one.next_queries);
  CHECK(many.nexts == one.nexts);
  CHECK(many.snaps == one.snaps);
  CHECK(one.nexts == 10);  // flat ground: one Next batch per step, no retries
  // Tracks are named per character.
  CHECK(w9.tracks.size() == 9 * (c.feet.size() + 1));
  CHECK(w9.tracks.front().character == "c1");
  CHECK(w9.tracks.back().character == "c9");
}

TEST_CASE("A crowd member left out inside the terrain is told why", "[steps][generator][crowd]") {
  // Bipeds 0.35 apart on samples 0.25 apart, turned across the grid: some members' feet snap
  // onto their neighbours' samples, well inside the terrain. Said as "the grid runs off the
  // terrain there", which it did not.
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(81, 0.25, 0), 0.25);
  GenerateOptions o = CrowdOptions({10, 0, 10}, 1, 100, 0.35);
  o.heading = {1, 0, 1};
  const Walk w = Generate(t, c, o);
  REQUIRE_FALSE(w.stops.empty());
  for (const std::string& stop : w.stops) {
    INFO(stop);
    CHECK_THAT(stop, Catch::Contains("left out of the walk"));
    CHECK_THAT(stop, Catch::Contains("the terrain's samples, about ") &&
                         Catch::Contains(" apart, are coarse for the crowd's spacing, 0.35: give "
                                         "a wider --crowd-spacing)"));
    CHECK_THAT(stop, !Catch::Contains("runs off the terrain"));
  }
}

TEST_CASE("Crowd places that snap onto another character's start are left out",
          "[steps][generator][crowd]") {
  // A 3 x 3 grid 1 m apart around (0.3, 0, 0.3) on a 10 m square: the places at -0.7 snap onto
  // the edge, 0.3 from their neighbours' starts. They stood on top of them and walked the same
  // tracks; now the five of them are left out (no tracks), each stop saying why.
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(200, 0.05, 0), 0.05);
  const GenerateOptions o = CrowdOptions({0.3, 0, 0.3}, 4, 9, 1.0);
  const Walk w = Generate(t, c, o);
  std::set<std::string> characters;
  std::vector<Vec3> starts;
  for (const WalkTrack& track : w.tracks) {
    characters.insert(track.character);
    if (track.kind == TrackKind::kBody) starts.push_back(track.keys.front().position);
  }
  CHECK(characters == std::set<std::string>{"c5", "c6", "c8", "c9"});
  CHECK(w.tracks.size() == 4 * (c.feet.size() + 1));
  for (size_t i = 0; i < starts.size(); ++i)
    for (size_t j = i + 1; j < starts.size(); ++j) CHECK(Distance(starts[i], starts[j]) > 0.9);
  REQUIRE(w.stops.size() == 5);
  for (const std::string& stop : w.stops) {
    CHECK_THAT(stop, Catch::Contains("its place on the crowd's grid"));
    CHECK_THAT(stop, Catch::Contains("(its place snaps ") &&
                         Catch::Contains(" sideways: the grid runs off the terrain, or over a "
                                         "drop, there): left out"));
    // The distance to the other start, said as a distance ("within 0.25 of" read as a bound).
    CHECK_THAT(stop, Catch::Matches(".*, only [0-9.e+-]+ from c[0-9]+'s start .*"));
  }
}

TEST_CASE("A crowd member left out on coarse hills is told of the samples, not of an edge",
          "[steps][generator][crowd]") {
  // Bipeds 0.4 apart on the bundled hills (samples 0.25 apart): members 1.35 m inside the
  // terrain, whose feet took their neighbours' samples, were said to stand where "the grid
  // runs off the terrain": measured from the place to the ground, 0.1 of snapping onto the
  // lattice and the hill's rise passed for an edge.
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(LoadShippedTerrain("hills"), 0.25);
  const Walk w = Generate(t, c, CrowdOptions({0.75, 0, 5}, 2, 36, 0.4));
  size_t inside = 0;
  for (const std::string& stop : w.stops) {
    INFO(stop);
    const size_t at = stop.find("its place on the crowd's grid, (");
    const size_t around = stop.find("its feet, around (");
    const size_t open = at != std::string::npos ? at + 32 : around + 18;
    if (at == std::string::npos && around == std::string::npos) continue;
    const double x = std::stod(stop.substr(open));
    if (x < 1) continue;  // a place within a metre of the edge at x = 0
    ++inside;
    CHECK_THAT(stop, !Catch::Contains("runs off the terrain"));
    CHECK_THAT(stop, Catch::Contains("are coarse for the crowd's spacing, 0.4"));
  }
  CHECK(inside > 0);
}

TEST_CASE("A crowd member whose place hangs over a drop beside blocks is told so",
          "[steps][generator][crowd]") {
  // Hexapods on piles of blocks: places hanging a metre up beside a pile snap sideways onto its
  // face, along the face's normal. Measured across the normal alone, as over hills, they were
  // blamed on samples coarse for the spacing, and told to widen it.
  const Character c = LoadShipped("hexapod");
  Terrain t = LoadTerrain(MakeBlocks(8, 8, 3, 0.05, 3), 0.05);
  const Walk w = Generate(t, c, CrowdOptions({2, 3, 2}, 4, 49, 2 * c.reach));
  size_t left_out = 0;
  for (const std::string& stop : w.stops) {
    if (stop.find("left out") == std::string::npos) continue;
    ++left_out;
    INFO(stop);
    CHECK_THAT(stop, Catch::Contains("the grid runs off the terrain, or over a drop, there"));
    CHECK_THAT(stop, !Catch::Contains("are coarse for the crowd's spacing"));
  }
  CHECK(left_out > 0);
}

TEST_CASE("Crowd places closer than the terrain's samples are left out for their spacing",
          "[steps][generator][crowd]") {
  // A 2 x 2 grid 1 cm apart in the middle of ground sampled every 25 cm: every place snaps onto
  // one sample, not because the grid runs off the terrain (as the stops said) but because the
  // spacing is finer than the samples.
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(40, 0.25, 0), 0.25);
  const Walk w = Generate(t, c, CrowdOptions({5, 0, 5}, 4, 4, 0.01));
  REQUIRE(w.stops.size() == 3);
  for (const std::string& stop : w.stops) {
    CHECK_THAT(stop, Catch::Contains("(the crowd's spacing, 0.01, is finer than the terrain's "
                                     "samples, about 0.2"));
    // The terrain's spacing as measured: within a few per cent of the 25 cm it was made at.
    const size_t about = stop.find("samples, about ");
    REQUIRE(about != std::string::npos);
    CHECK(std::stod(stop.substr(about + 15)) == Approx(0.25).epsilon(0.05));
    CHECK_THAT(stop, Catch::EndsWith("apart): left out of the walk"));
    CHECK_THAT(stop, !Catch::Contains("runs off the terrain"));
  }
}

TEST_CASE("Crowd members on a terrain of one point are told so, not of a spacing",
          "[steps][generator][crowd]") {
  // One sample, or several at one place: the grid's spacing is no measure there (it read
  // "the terrain's samples, about 1 apart, are coarse for the crowd's spacing").
  const Character c = LoadShipped("quadruped");
  for (const int copies : {1, 3}) {
    INFO(copies << " samples");
    RawSamples point;
    for (int i = 0; i < copies; ++i) point.push_back({0, 0, 0}, {0, 1, 0});
    Terrain t = LoadTerrain(point, 0.1);
    const Walk w = Generate(t, c, CrowdOptions({0, 0, 0}, 2, 2, 2 * c.reach));
    size_t left_out = 0;
    for (const std::string& stop : w.stops) {
      if (stop.find("left out") == std::string::npos) continue;
      ++left_out;
      CHECK_THAT(stop, Catch::Contains("(the terrain is a single point, onto which every place "
                                       "snaps): left out of the walk"));
      CHECK_THAT(stop, !Catch::Contains("apart"));
    }
    CHECK(left_out == 1);
  }
}

TEST_CASE("Crowd members pushed onto the terrain's edge plant no foot on another's sample",
          "[steps][generator][crowd]") {
  // 1,000 hexapods on 12 m of rocks: the grid runs far off the terrain, and places pushed onto
  // its edge snapped just over half a spacing from others' starts, so both kept walking with a
  // foot each on one sample (three samples shared). The member pushed farther is left out.
  const Character c = LoadShipped("hexapod");
  const RawSamples ground = MakeRocks(12, 0.4, 0.025, 3);
  Terrain t = LoadTerrain(ground, 0.025);
  const Walk w = Generate(t, c, CrowdOptions({6, 1, 6}, 1, 1000, 2 * c.reach));
  std::map<std::pair<uint32_t, int>, std::string> owner;  // (x, z) in mm -> member
  std::map<std::string, int> members;
  size_t shared = 0;
  for (const WalkTrack& track : w.tracks) {
    if (track.kind != TrackKind::kFoot) continue;
    ++members[track.character];
    const Vec3& p = track.keys.front().position;
    const auto at = std::make_pair(static_cast<uint32_t>(std::lround(p.x * 1000 + 1e6)),
                                   static_cast<int>(std::lround(p.z * 1000)));
    const auto [it, added] = owner.emplace(at, track.character);
    if (!added && it->second != track.character) {
      ++shared;
      UNSCOPED_INFO(track.character << " and " << it->second << " share a sample at " << p.x << ", "
                                    << p.z);
    }
  }
  CHECK(shared == 0);
  CHECK(members.size() > 400);  // the members on the terrain kept
  bool said = false;
  for (const std::string& stop : w.stops)
    said |= stop.find("stands on the sample a foot of c") != std::string::npos &&
            stop.find(
                "the grid runs off the terrain, or over a drop, there): left out of the "
                "walk") != std::string::npos;
  CHECK(said);
}

TEST_CASE("A crowd of insects on bumpy ground stands on a grid across world up",
          "[steps][generator][crowd]") {
  // The grid lay in the plane of the start sample's normal: on gentle bumps it tilted metres
  // above and below the ground at its edges, and its places snapped onto the bumps' tops
  // together (826 of 10,000 hexapods started on another's sample, the duplicates now left out).
  const Character c = LoadShipped("hexapod");
  Terrain t = LoadTerrain(MakeHeightField(300, 300, 0.04, 0.02, 11), 0.04);
  GenerateOptions o = CrowdOptions({6, 0, 6}, 2, 400, 0.5);
  const Walk w = Generate(t, c, o);
  for (const std::string& stop : w.stops) CHECK_THAT(stop, !Catch::Contains("left out"));
  CHECK(w.tracks.size() == 400 * (c.feet.size() + 1));
}

TEST_CASE("By default a crowd walks in passes in process and all at once out of process",
          "[steps][generator][crowd]") {
  const Character c = LoadShipped("hexapod");
  const RawSamples ground = MakeFlat(400, 0.012, 0);  // 4.8 m square
  const int crowd = kInProcessCharactersPerPass + 1, steps = 2;
  auto run = [&](CountingSession* session, int* passes) {
    TerrainHandle h;
    REQUIRE(session->LoadSamples(ground, "flat", &h) == Status::kOk);
    GenerateOptions o = CrowdOptions({2.4, 0, 2.2}, steps, crowd, 0.1);
    o.progress = [passes, steps](int, int total) { *passes = total / steps; };
    Walk w;
    std::string error;
    REQUIRE(GenerateWalk(*session, h, c, o, &w, &error) == Status::kOk);
    CHECK(w.stopped.empty());
    return w;
  };
  CountingSession local, remote;
  remote.remote = true;
  int local_passes = 0, remote_passes = 0;
  const Walk a = run(&local, &local_passes), b = run(&remote, &remote_passes);
  CHECK(local_passes == 2);
  CHECK(remote_passes == 1);
  CHECK(local.nexts == 2 * remote.nexts);
  CHECK(local.next_queries == remote.next_queries);
  REQUIRE(a.tracks.size() == b.tracks.size());
  size_t differ = 0;
  for (size_t i = 0; i < a.tracks.size(); ++i) {
    REQUIRE(a.tracks[i].keys.size() == b.tracks[i].keys.size());
    for (size_t k = 0; k < a.tracks[i].keys.size(); ++k)
      differ += !(a.tracks[i].keys[k].position == b.tracks[i].keys[k].position);
  }
  CHECK(differ == 0);
}

TEST_CASE("A generated walk's keys share one block that its tracks keep alive",
          "[steps][generator][crowd]") {
  // 100 hexapods x 40 steps: a few megabytes of keys, a block returned to the system when the
  // last track holding it goes. After the walks are gone, new walks are generated (reusing
  // their memory), and the kept tracks must still read their own keys.
  const Character c = LoadShipped("hexapod");
  Terrain t = LoadTerrain(MakeFlat(300, 0.02, 0), 0.02);
  GenerateOptions o = CrowdOptions({3, 0, 2}, 40, 100, 0.2);
  std::optional<WalkTrack> kept, assigned;
  WalkTrack copied;
  std::vector<WalkKey> expected, expected_assigned;
  {
    Walk w = Generate(t, c, o);
    REQUIRE(w.stopped.empty());
    const std::pmr::memory_resource* arena = w.tracks.front().memory.get();
    REQUIRE(arena != nullptr);
    for (const WalkTrack& track : w.tracks) {
      REQUIRE(track.memory.get() == arena);
      REQUIRE(track.keys.get_allocator().resource() == arena);
    }
    WalkTrack& last = w.tracks.back();  // the last character's body
    expected.assign(last.keys.begin(), last.keys.end());
    REQUIRE(expected.size() == static_cast<size_t>(o.steps + 1));
    copied = last;  // a copy's keys live on the default heap, and hold no block
    CHECK(copied.keys.get_allocator().resource() == std::pmr::get_default_resource());
    CHECK(copied.memory.get() == nullptr);
    kept.emplace(std::move(last));  // moved: the keys and their block go along
    CHECK(kept->memory.get() == arena);
    // A track of this walk assigned another walk's track keeps its keys in this walk's block,
    // and keeps that block alive.
    assigned.emplace(std::move(w.tracks.front()));
    o.start = {1, 0, 1};
    Walk other = Generate(t, c, o);
    expected_assigned.assign(other.tracks.front().keys.begin(), other.tracks.front().keys.end());
    *assigned = std::move(other.tracks.front());
    CHECK(assigned->memory.get() == arena);
    CHECK(assigned->keys.get_allocator().resource() == arena);
  }
  o.start = {4, 0, 3};
  const Walk reuse1 = Generate(t, c, o), reuse2 = Generate(t, c, o);
  REQUIRE(kept->keys.size() == expected.size());
  REQUIRE(assigned->keys.size() == expected_assigned.size());
  size_t differ = 0;
  for (size_t k = 0; k < expected.size(); ++k)
    differ += !(kept->keys[k].position == expected[k].position &&
                copied.keys[k].position == expected[k].position);
  for (size_t k = 0; k < expected_assigned.size(); ++k)
    differ += !(assigned->keys[k].position == expected_assigned[k].position);
  CHECK(differ == 0);
  // A kept track grows past its reservation.
  for (int i = 0; i < 20000; ++i) kept->keys.push_back(expected[i % expected.size()]);
  CHECK(kept->keys[expected.size() + 19999].position == expected[19999 % expected.size()].position);
  CHECK(kept->keys.front().position == expected.front().position);
}

TEST_CASE("A crowd that reserves more keys than it writes backs only the keys it writes",
          "[steps][generator][crowd]") {
  // 600 hexapods x 10,000 steps reserve about 1.2 GB of keys (4096 per foot); on a 3 m floor
  // they reach its edge and stop within a few steps. Blocks in huge pages would be backed whole
  // on their first key; beyond the huge-page budget the keys use ordinary pages.
  const Character c = LoadShipped("hexapod");
  Terrain t = LoadTerrain(MakeFlat(150, 0.02, 0), 0.02);
  GenerateOptions o = CrowdOptions({1.5, 0, 1.5}, 10000, 600, 0.08);
  auto resident_mb = [] {
    std::ifstream statm("/proc/self/statm");
    double size = 0, resident = 0;
    statm >> size >> resident;
    return resident * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1 << 20);
  };
  const double before = resident_mb();
  const Walk w = Generate(t, c, o);
  const double grown = resident_mb() - before;
  CHECK_THAT(w.stopped, Catch::Contains("more characters stopped"));
  size_t keys = 0;
  for (const WalkTrack& track : w.tracks) keys += track.keys.size();
  INFO("resident memory grew " << grown << " MB for " << keys << " keys");
  CHECK(keys < 600 * 7 * 200);
  CHECK(grown < 300);
}

TEST_CASE("Generation is deterministic", "[steps][generator]") {
  const Character c = LoadShipped("quadruped");
  Terrain t = LoadTerrain(MakeHeightField(200, 200, 0.04, 0.1, 7), 0.04);
  GenerateOptions o;
  o.steps = 16;
  const Walk a = Generate(t, c, o), b = Generate(t, c, o);
  REQUIRE(a.tracks.size() == b.tracks.size());
  for (size_t i = 0; i < a.tracks.size(); ++i) {
    REQUIRE(a.tracks[i].keys.size() == b.tracks[i].keys.size());
    for (size_t k = 0; k < a.tracks[i].keys.size(); ++k)
      CHECK(a.tracks[i].keys[k].position == b.tracks[i].keys[k].position);
  }
}

// The walk of `c` with options `o` in an embedded session of `threads` threads, on the terrain
// load(session, &handle) loads.
template <typename Load>
Walk WalkOnThreads(int threads, const Character& c, GenerateOptions o, Load&& load) {
  auto session = MakeEmbeddedSession(threads);
  TerrainHandle h = 0;
  REQUIRE(load(*session, &h) == Status::kOk);
  o.threads = threads;
  Walk w;
  std::string error;
  const Status s = GenerateWalk(*session, h, c, o, &w, &error);
  INFO(error);
  REQUIRE(s == Status::kOk);
  return w;
}

TEST_CASE("A crowd walked in passes on two threads says what one thread says",
          "[steps][generator][crowd]") {
  // 260 octopods on the shipped hills, whose samples are too far apart for a foot of some to
  // stand within reach at the start: the note of the first such character was made on the
  // copy that walked its pass, and lost, on two threads.
  const Character c = LoadShipped("octopod");
  const std::string hills = std::string(FOOTFALL_SOURCE_DIR) + "/data/terrain/hills.pts";
  GenerateOptions o;
  o.steps = 1, o.crowd = 260, o.crowd_spacing = 1;
  auto load = [&](TerrainSession& s, TerrainHandle* h) {
    return s.LoadFile(hills, TerrainLoadOptions{}, h);
  };
  const Walk one = WalkOnThreads(1, c, o, load), two = WalkOnThreads(2, c, o, load);
  REQUIRE_FALSE(one.notes.empty());
  CHECK_THAT(one.notes.back(), Catch::Contains("at the start, foot "));
  CHECK(two.notes == one.notes);
}

TEST_CASE("A large crowd's walk is the same on one thread and on two",
          "[steps][generator][crowd]") {
  // 2,100 hexapods: enough for the generator and the engine to split their work.
  const Character c = LoadShipped("hexapod");
  const RawSamples ground = MakeHeightField(500, 500, 0.03, 0.01, 3);
  const GenerateOptions o = CrowdOptions({7.5, 0, 7}, 4, 2100, 0.3);
  auto load = [&](TerrainSession& s, TerrainHandle* h) {
    return s.LoadSamples(ground, "bumps", h);
  };
  const Walk one = WalkOnThreads(1, c, o, load), two = WalkOnThreads(2, c, o, load);
  CHECK(one.stopped == two.stopped);
  REQUIRE(one.tracks.size() == two.tracks.size());
  size_t left_out = 0;  // crowd places at the terrain's edge snapped onto others' starts
  for (const std::string& stop : one.stops)
    left_out += stop.find("left out of the walk") != std::string::npos;
  CHECK(left_out < 100);
  REQUIRE(one.tracks.size() == (2100 - left_out) * (c.feet.size() + 1));
  size_t keys = 0, differ = 0;
  for (size_t i = 0; i < one.tracks.size(); ++i) {
    REQUIRE(one.tracks[i].name == two.tracks[i].name);
    REQUIRE(one.tracks[i].character == two.tracks[i].character);
    REQUIRE(one.tracks[i].keys.size() == two.tracks[i].keys.size());
    for (size_t k = 0; k < one.tracks[i].keys.size(); ++k) {
      const WalkKey &a = one.tracks[i].keys[k], &b = two.tracks[i].keys[k];
      ++keys;
      const Quat qa = one.tracks[i].Rotation(k), qb = two.tracks[i].Rotation(k);
      differ +=
          !(a.frame == b.frame && a.phase == b.phase && a.position == b.position &&
            a.normal == b.normal && qa.x == qb.x && qa.y == qb.y && qa.z == qb.z && qa.w == qb.w);
    }
  }
  CHECK(keys > 2100 * 10);
  CHECK(differ == 0);
  GenerateOptions bad;
  bad.threads = 0;
  Terrain t = LoadTerrain(MakeFlat(10, 0.1, 0), 0.1);
  Walk w;
  std::string error;
  CHECK(GenerateWalk(*t.session, t.handle, c, bad, &w, &error) == Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("threads"));
}

TEST_CASE(
    "A crowd on rocks (raised arcs, refused footholds, stops) is the same on one thread, "
    "on two, and walked in passes",
    "[steps][generator][crowd]") {
  // 600 hexapods 5 cm apart on data/terrain/rocks.pts (8 cm samples): enough characters for the
  // per-character passes to split; some arcs need raising (their characters finish in a later
  // round of arc checks) and some characters stop.
  Character c = LoadShipped("hexapod");
  c.max_rise = 0.03;  // so that some characters stop at ridges
  const RawSamples rocks = LoadShippedTerrain("rocks");
  GenerateOptions o;
  o.steps = 30;
  o.crowd = 600;
  o.crowd_spacing = 0.05;
  std::vector<std::pair<int, int>> progress;
  auto run = [&](int threads, int per_pass) {
    Terrain t = LoadTerrain(rocks, 0.08);
    o.threads = threads;
    o.characters_per_pass = per_pass;
    progress.clear();
    o.progress = [&progress](int done, int total) { progress.emplace_back(done, total); };
    return Generate(t, c, o);
  };
  const Walk one = run(1, -1), two = run(2, -1);
  // 5 passes of 128 characters, the last one short; a pass ends early once all its characters
  // have stopped.
  const Walk passes = run(2, 128);
  REQUIRE(!progress.empty());
  CHECK(progress.back().first == progress.back().second);
  CHECK(progress.back().second == 5 * o.steps);
  for (size_t i = 1; i < progress.size(); ++i) CHECK(progress[i].first >= progress[i - 1].first);
  CHECK_THAT(one.stopped, Catch::Contains("more characters stopped"));
  size_t raised = 0;
  for (const Walk* other : {&two, &passes}) {
    CHECK(one.stopped == other->stopped);
    REQUIRE(one.tracks.size() == other->tracks.size());
    size_t differ = 0;
    for (size_t i = 0; i < one.tracks.size(); ++i) {
      const auto &ka = one.tracks[i].keys, &kb = other->tracks[i].keys;
      REQUIRE(ka.size() == kb.size());
      for (size_t k = 0; k < ka.size(); ++k) {
        differ += !(ka[k].frame == kb[k].frame && ka[k].phase == kb[k].phase &&
                    ka[k].position == kb[k].position && ka[k].normal == kb[k].normal &&
                    one.tracks[i].Rotation(k).x == other->tracks[i].Rotation(k).x &&
                    one.tracks[i].Rotation(k).w == other->tracks[i].Rotation(k).w);
        // A raised arc: its mid key more than step_height above the chord's midpoint.
        if (ka[k].phase == KeyPhase::kMid)
          raised += Distance(ka[k].position, (ka[k - 1].position + ka[k + 1].position) * 0.5) >
                    1.01 * c.step_height;
      }
    }
    CHECK(differ == 0);
  }
  CHECK(raised > 0);
  Terrain t = LoadTerrain(rocks, 0.08);
  CheckWalk(t, c, o, passes);
}

TEST_CASE("Bad options are refused with a message", "[steps][generator]") {
  const Character c = LoadShipped("biped");
  Terrain t = LoadTerrain(MakeFlat(10, 0.1, 0), 0.1);
  Walk w;
  std::string error;
  GenerateOptions o;
  o.heading = {0, 0, 0};
  CHECK(GenerateWalk(*t.session, t.handle, c, o, &w, &error) == Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("heading"));
  o = GenerateOptions{};
  o.up = {0, std::nan(""), 0};
  CHECK(GenerateWalk(*t.session, t.handle, c, o, &w, &error) == Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("up"));
  o = GenerateOptions{};
  CHECK(GenerateWalk(*t.session, t.handle + 99, c, o, &w, &error) == Status::kUnknownTerrain);
  CHECK_THAT(error, Catch::Contains("handle"));
}

namespace footfall::test {

TEST_CASE("Options no walk can follow are refused with the reason", "[steps][generator]") {
  Terrain t = LoadTerrain(MakeFlat(40, 0.05, 0), 0.05);
  Walk w;
  std::string error;
  SECTION("a heading along the up where the character starts") {
    // The insect's up is the floor's normal: straight up gives no direction on the ground (it
    // used to fall back to another direction silently).
    GenerateOptions o;
    o.heading = {0, 2, 0};
    CHECK(GenerateWalk(*t.session, t.handle, LoadShipped("hexapod"), o, &w, &error) ==
          Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("the heading (0.0000, 1.0000, 0.0000) is along the up"));
    // A few degrees off the up, what is left on the ground is noise or the ground's tilt (the
    // default +Z heading on a Z-up terrain walked an insect downhill): refused too.
    const double rad = 3.14159265358979323846 / 180;
    o.heading = {std::sin(8 * rad), std::cos(8 * rad), 0};
    CHECK(GenerateWalk(*t.session, t.handle, LoadShipped("hexapod"), o, &w, &error) ==
          Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("within 10 deg of it"));
    // Past the threshold the heading's ground part is the direction walked.
    o.heading = {std::sin(12 * rad), std::cos(12 * rad), 0};
    REQUIRE(GenerateWalk(*t.session, t.handle, LoadShipped("hexapod"), o, &w, &error) ==
            Status::kOk);
    const WalkTrack& body = w.tracks.back();
    REQUIRE(body.keys.size() > 2);
    const Vec3 moved = body.keys.back().position - body.keys.front().position;
    CHECK(moved.x > 0.1);
    CHECK(std::fabs(moved.z) < 0.25 * moved.x);
    // With a path, the heading is not used.
    o.path = {{1.5, 0, 1.5}};
    CHECK(GenerateWalk(*t.session, t.handle, LoadShipped("hexapod"), o, &w, &error) == Status::kOk);
  }
  SECTION("a start frame or fps beyond the command line's bounds, from any caller") {
    GenerateOptions o;
    o.start_frame = 1e300;  // every key landed on one frame
    CHECK(GenerateWalk(*t.session, t.handle, LoadShipped("biped"), o, &w, &error) ==
          Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("the start frame within +-1e+09"));
    o.start_frame = 1;
    o.fps = 1e7;
    CHECK(GenerateWalk(*t.session, t.handle, LoadShipped("biped"), o, &w, &error) ==
          Status::kInvalidArgument);
  }
}

}  // namespace footfall::test
