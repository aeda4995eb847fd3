// JoinedCalls: threads querying through their members get the answers they would get alone,
// while the session sees one call per round, kind, terrain and tolerance.
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "counting_session.h"
#include "footfall/client/joined_calls.h"
#include "footfall/import/terrain_generators.h"

using namespace footfall;
using footfall::test::CountingSession;

namespace {

struct Fixture {
  Fixture() {
    embedded = MakeEmbeddedSession();
    REQUIRE(embedded->LoadSamples(MakeHeightField(60, 60, 0.1, 0.2, 5), "hills", &terrain) ==
            Status::kOk);
    counting = std::make_unique<CountingSession>(*embedded);
  }
  std::unique_ptr<TerrainSession> embedded;
  std::unique_ptr<CountingSession> counting;
  TerrainHandle terrain = 0;
};

// Query points of thread t, round r: a few, a different number for each thread.
std::vector<Vec3> PointsOf(int t, int r) {
  std::vector<Vec3> p;
  for (int i = 0; i <= t % 4; ++i)
    p.push_back({0.3 + 0.7 * t + 0.05 * i, 0.5, 0.2 + 0.4 * r + 0.03 * t});
  return p;
}

// Runs `threads` members of one JoinedCalls, thread t calling body(t, member).
void RunMembers(JoinedCalls& joined, int threads,
                const std::function<void(int, TerrainSession&)>& body) {
  std::vector<std::unique_ptr<TerrainSession>> members;
  for (int t = 0; t < threads; ++t) members.push_back(joined.Join());
  std::vector<std::thread> running;
  for (int t = 0; t < threads; ++t)
    running.emplace_back([&, t] {
      body(t, *members[t]);
      members[t].reset();
    });
  for (std::thread& th : running) th.join();
}

bool Same(const Foothold& a, const Foothold& b) {
  return a.status == b.status && a.index == b.index && a.point.x == b.point.x &&
         a.point.y == b.point.y && a.point.z == b.point.z && a.normal.x == b.normal.x &&
         a.normal.y == b.normal.y && a.normal.z == b.normal.z;
}

}  // namespace

TEST_CASE("Joined threads get their own answers in one call per round", "[joined]") {
  Fixture f;
  JoinedCalls joined(*f.counting);
  constexpr int kThreads = 8, kRounds = 12;
  std::vector<int> wrong(kThreads, 0);
  RunMembers(joined, kThreads, [&](int t, TerrainSession& s) {
    for (int r = 0; r < kRounds; ++r) {
      const std::vector<Vec3> p = PointsOf(t, r);
      std::vector<Foothold> got(p.size());
      if (r % 2 == 0) {
        if (s.Snap(f.terrain, p.data(), p.size(), got.data()) != Status::kOk) ++wrong[t];
        for (size_t i = 0; i < p.size(); ++i)
          if (!Same(got[i], f.embedded->Snap(f.terrain, p[i]))) ++wrong[t];
      } else {
        std::vector<StepQuery> q;
        for (const Vec3& x : p) q.push_back({x, {0.3, 0, 0.1 * t - 0.2}});
        if (s.Next(f.terrain, q.data(), q.size(), 0, got.data()) != Status::kOk) ++wrong[t];
        for (size_t i = 0; i < q.size(); ++i)
          if (!Same(got[i], f.embedded->Next(f.terrain, q[i]))) ++wrong[t];
      }
    }
  });
  for (int t = 0; t < kThreads; ++t) CHECK(wrong[t] == 0);
  CHECK(f.counting->query_calls == kRounds);
  CHECK(joined.calls() == static_cast<size_t>(kRounds));
}

TEST_CASE("Joined calls of different kinds or tolerances in one round stay apart", "[joined]") {
  Fixture f;
  JoinedCalls joined(*f.counting);
  constexpr int kThreads = 6, kRounds = 5;
  std::vector<int> wrong(kThreads, 0);
  RunMembers(joined, kThreads, [&](int t, TerrainSession& s) {
    for (int r = 0; r < kRounds; ++r) {
      const std::vector<Vec3> p = PointsOf(t, r);
      std::vector<Foothold> got(p.size());
      std::vector<StepQuery> q;
      for (const Vec3& x : p) q.push_back({x, {0.2, 0, 0.2}});
      const double tolerance = t % 3 == 2 ? 0.05 : 0;
      const Status s1 = t % 3 == 0 ? s.Normal(f.terrain, p.data(), p.size(), got.data())
                                   : s.Next(f.terrain, q.data(), q.size(), tolerance, got.data());
      if (s1 != Status::kOk) ++wrong[t];
      for (size_t i = 0; i < p.size(); ++i) {
        const Foothold alone = t % 3 == 0 ? f.embedded->Snap(f.terrain, p[i])
                                          : f.embedded->Next(f.terrain, q[i], tolerance);
        if (!Same(got[i], alone)) ++wrong[t];
      }
    }
  });
  for (int t = 0; t < kThreads; ++t) CHECK(wrong[t] == 0);
  // Normal; next at tolerance 0; next at 0.05.
  CHECK(f.counting->query_calls == 3 * kRounds);
}

TEST_CASE("Joined threads that stop early or fail leave the others served", "[joined]") {
  Fixture f;
  JoinedCalls joined(*f.counting);
  constexpr int kThreads = 5;
  std::vector<int> wrong(kThreads, 0);
  std::vector<std::string> errors(kThreads);
  RunMembers(joined, kThreads, [&](int t, TerrainSession& s) {
    // Thread t makes t + 1 calls (its members leave one after the other); thread 4 asks an
    // unknown terrain in its third call, and a direct call (Info) between two of them.
    for (int r = 0; r <= t; ++r) {
      const std::vector<Vec3> p = PointsOf(t, r);
      std::vector<Foothold> got(p.size());
      const bool unknown = t == 4 && r == 2;
      const Status st =
          s.Snap(unknown ? f.terrain + 100 : f.terrain, p.data(), p.size(), got.data());
      if (unknown) {
        if (st != Status::kUnknownTerrain) ++wrong[t];
        errors[t] = s.last_error();
        continue;
      }
      if (st != Status::kOk) ++wrong[t];
      for (size_t i = 0; i < p.size(); ++i)
        if (!Same(got[i], f.embedded->Snap(f.terrain, p[i]))) ++wrong[t];
      TerrainInfo info;
      if (t == 4 && r == 1 && s.Info(f.terrain, &info) != Status::kOk) ++wrong[t];
    }
    // A call without queries answers at once, the session's own (no call is joined for it).
    if (s.Snap(f.terrain, nullptr, 0, nullptr) != Status::kOk) ++wrong[t];
  });
  for (int t = 0; t < kThreads; ++t) CHECK(wrong[t] == 0);
  CHECK(errors[4].find("terrain") != std::string::npos);
  CHECK(f.counting->info_calls == 1);
  // Five rounds of snaps, and the unknown terrain's call: the snaps of threads 2 and 3 that
  // wait beside it go either before it (six calls in all) or after it, with thread 4's next
  // snap (five), as the threads arrive; and each thread's call without queries.
  CHECK(f.counting->query_calls >= 5 + kThreads);
  CHECK(f.counting->query_calls <= 6 + kThreads);
}

TEST_CASE("A joined call whose session throws fails for every member in it, none left waiting",
          "[joined]") {
  // (The exception left RunCall through one member's thread; the others waited for ever.)
  Fixture f;
  f.counting->throw_on_snap = true;
  JoinedCalls joined(*f.counting);
  constexpr int kThreads = 3;
  std::vector<Status> status(kThreads, Status::kOk);
  std::vector<std::string> errors(kThreads);
  RunMembers(joined, kThreads, [&](int t, TerrainSession& s) {
    const std::vector<Vec3> p = PointsOf(t, 0);
    std::vector<Foothold> got(p.size());
    status[t] = s.Snap(f.terrain, p.data(), p.size(), got.data());
    errors[t] = s.last_error();
  });
  for (int t = 0; t < kThreads; ++t) {
    CHECK(status[t] == Status::kInternalError);
    CHECK(errors[t] == "the joined call failed: snap failed inside the session");
  }
  // The session works again for the members of a later round.
  f.counting->throw_on_snap = false;
  RunMembers(joined, kThreads, [&](int t, TerrainSession& s) {
    const std::vector<Vec3> p = PointsOf(t, 1);
    std::vector<Foothold> got(p.size());
    status[t] = s.Snap(f.terrain, p.data(), p.size(), got.data());
  });
  for (int t = 0; t < kThreads; ++t) CHECK(status[t] == Status::kOk);
}
