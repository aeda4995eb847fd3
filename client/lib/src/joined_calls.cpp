#include "footfall/client/joined_calls.h"

#include <algorithm>
#include <cstring>
#include <new>
#include <string>

namespace footfall {

enum class JoinedKind { kSnap, kNormal, kNext };

struct JoinedCalls::Request {
  Request(JoinedKind k, TerrainHandle t, double tol, const Vec3* p, const StepQuery* q, size_t n,
          Foothold* o)
      : kind(k), terrain(t), tolerance(tol), points(p), queries(q), count(n), out(o) {}
  JoinedKind kind;
  TerrainHandle terrain;
  double tolerance;  // kNext
  const Vec3* points;
  const StepQuery* queries;
  size_t count;
  Foothold* out;
  // Set by the call that carries it.
  bool done = false;
  Status status = Status::kOk;
  std::string error;
  bool out_of_memory = false;  // its call failed for want of memory: error unset
};

class JoinedCalls::Member final : public TerrainSession {
 public:
  explicit Member(JoinedCalls& joined) : joined_(joined) {}
  ~Member() override { joined_.Leave(); }

  Status LoadFile(const std::string& path, const TerrainLoadOptions& options,
                  TerrainHandle* out) override {
    return Direct([&](TerrainSession& s) { return s.LoadFile(path, options, out); });
  }
  Status LoadServerFile(const std::string& path, const TerrainLoadOptions& options,
                        TerrainHandle* out) override {
    return Direct([&](TerrainSession& s) { return s.LoadServerFile(path, options, out); });
  }
  Status LoadSamples(const RawSamples& samples, const std::string& name,
                     TerrainHandle* out) override {
    return Direct([&](TerrainSession& s) { return s.LoadSamples(samples, name, out); });
  }
  Status Info(TerrainHandle terrain, TerrainInfo* out) override {
    return Direct([&](TerrainSession& s) { return s.Info(terrain, out); });
  }
  Status Unload(TerrainHandle terrain) override {
    return Direct([&](TerrainSession& s) { return s.Unload(terrain); });
  }
  Status Ping() override {
    return Direct([&](TerrainSession& s) { return s.Ping(); });
  }
  Status Snap(TerrainHandle terrain, const Vec3* points, size_t count, Foothold* out) override {
    return Joined(Request(JoinedKind::kSnap, terrain, 0, points, nullptr, count, out));
  }
  Status Normal(TerrainHandle terrain, const Vec3* points, size_t count, Foothold* out) override {
    return Joined(Request(JoinedKind::kNormal, terrain, 0, points, nullptr, count, out));
  }
  Status Next(TerrainHandle terrain, const StepQuery* queries, size_t count, double tolerance,
              Foothold* out) override {
    return Joined(Request(JoinedKind::kNext, terrain, tolerance, nullptr, queries, count, out));
  }
  std::string Describe() const override { return joined_.session_.Describe(); }
  bool InProcess() const override { return joined_.session_.InProcess(); }

 private:
  template <typename Fn>
  Status Direct(Fn&& fn) {
    std::lock_guard<std::mutex> lock(joined_.direct_);
    const Status s = fn(joined_.session_);
    if (s != Status::kOk) last_error_ = joined_.session_.last_error();
    return s;
  }
  Status Joined(Request r) {
    if (r.count == 0) {  // nothing to join: the session answers it alone (a terrain it lacks)
      return Direct([&r](TerrainSession& s) {
        return r.kind == JoinedKind::kNext     ? s.Next(r.terrain, r.queries, 0, r.tolerance, r.out)
               : r.kind == JoinedKind::kNormal ? s.Normal(r.terrain, r.points, 0, r.out)
                                               : s.Snap(r.terrain, r.points, 0, r.out);
      });
    }
    joined_.Ask(&r);
    if (r.status == Status::kOk) return r.status;
    return Fail(r.status, r.out_of_memory ? "out of memory joining the queries of several "
                                            "characters into one call"
                                          : std::move(r.error));
  }

  JoinedCalls& joined_;
};

JoinedCalls::JoinedCalls(TerrainSession& session) : session_(session) {}
JoinedCalls::~JoinedCalls() = default;

std::unique_ptr<TerrainSession> JoinedCalls::Join() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // So that Ask and RunCall never allocate to hold requests.
    waiting_.reserve(static_cast<size_t>(members_) + 1);
    call_.reserve(static_cast<size_t>(members_) + 1);
    ++members_;
  }
  try {
    return std::make_unique<Member>(*this);
  } catch (...) {
    Leave();
    throw;
  }
}

size_t JoinedCalls::calls() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return calls_;
}

void JoinedCalls::Ask(Request* r) {
  std::unique_lock<std::mutex> lock(mutex_);
  waiting_.push_back(r);
  if (waiting_.size() == static_cast<size_t>(members_)) RunCall();
  answered_.wait(lock, [r] { return r->done; });
}

void JoinedCalls::Leave() {
  std::lock_guard<std::mutex> lock(mutex_);
  --members_;
  if (!waiting_.empty() && waiting_.size() == static_cast<size_t>(members_)) RunCall();
}

bool JoinedCalls::SameCall(const Request* a, const Request* b) {
  return a->kind == b->kind && a->terrain == b->terrain &&
         (a->kind != JoinedKind::kNext ||
          std::memcmp(&a->tolerance, &b->tolerance, sizeof(double)) == 0);
}

namespace {

// *text = head + what, or false when memory for it ran out.
bool SetText(std::string* text, const char* head, const char* what) noexcept {
  try {
    *text = std::string(head) + what;
    return true;
  } catch (...) {
    return false;
  }
}

}  // namespace

void JoinedCalls::RunCall() {
  std::lock_guard<std::mutex> direct(direct_);
  // The call of the oldest waiting request, with every waiting request that can share it. The
  // members answered ask again behind those left waiting, so that all members fall into step.
  Request* lead = waiting_.front();
  std::vector<Request*>& call = call_;  // reserved by Join
  call.clear();
  for (Request* r : waiting_)
    if (SameCall(lead, r)) call.push_back(r);
  Status status = Status::kOk;
  std::string error;
  bool out_of_memory = false;
  try {
    size_t total = 0;
    for (const Request* r : call) total += r->count;
    answers_.resize(total);
    if (lead->kind == JoinedKind::kNext) {
      queries_.clear();
      for (const Request* r : call)
        queries_.insert(queries_.end(), r->queries, r->queries + r->count);
      status =
          session_.Next(lead->terrain, queries_.data(), total, lead->tolerance, answers_.data());
    } else {
      points_.clear();
      for (const Request* r : call) points_.insert(points_.end(), r->points, r->points + r->count);
      status = lead->kind == JoinedKind::kSnap
                   ? session_.Snap(lead->terrain, points_.data(), total, answers_.data())
                   : session_.Normal(lead->terrain, points_.data(), total, answers_.data());
    }
    ++calls_;
    if (status != Status::kOk) error = session_.last_error();
  } catch (const std::bad_alloc&) {
    status = Status::kLimitExceeded;
    out_of_memory = true;
  } catch (const std::exception& e) {
    // Any other failure of the shared session ends this call for every member in it, said as
    // such: escaping, it left the other members waiting for ever.
    status = Status::kInternalError;
    out_of_memory = !SetText(&error, "the joined call failed: ", e.what());
  } catch (...) {
    status = Status::kInternalError;
    out_of_memory = !SetText(&error, "the joined call failed: ", "an unknown exception");
  }
  size_t at = 0;
  for (Request* r : call) {
    if (status == Status::kOk) std::copy_n(answers_.begin() + at, r->count, r->out);
    at += r->count;
    r->status = status;
    r->out_of_memory = out_of_memory;
    if (status != Status::kOk && !out_of_memory) {
      try {
        r->error = error;
      } catch (const std::bad_alloc&) {
        r->out_of_memory = true;
      }
    }
    r->done = true;
  }
  waiting_.erase(
      std::remove_if(waiting_.begin(), waiting_.end(), [](const Request* r) { return r->done; }),
      waiting_.end());
  answered_.notify_all();
}

}  // namespace footfall
