// The C ABI over TerrainSession. Nothing may throw across it: every entry point catches.
#include "footfall/client/footfall_c.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "footfall/client/terrain_session.h"
#include "footfall/steps/character.h"
#include "footfall/steps/generate_request.h"
#include "footfall/steps/generator.h"
#include "footfall/steps/walk_json.h"
#include "footfall/terrain/c_locale.h"
#include "footfall/terrain/shown_text.h"

struct ffc_session {
  // Calls on one session from several threads take turns (the sessions below are not
  // thread-safe).
  std::mutex mutex;
  std::unique_ptr<footfall::TerrainSession> session;
  // Guards `error` alone, so ffc_last_error answers at once while another thread's call (a load
  // of minutes) holds `mutex`.
  mutable std::mutex error_mutex;
  std::string error;  // written through SetError
  // A fixed reason, set where memory has run out (SetFixedError), and cleared by SetError.
  const char* fixed_error = nullptr;
  int32_t walk_stop = FF_C_OK;  // why the last walk stopped early (ffc_walk_stop)
};

namespace {

using footfall::Foothold;
using footfall::Status;

constexpr double kMaxTimeout = 1e6;    // seconds, as footfall's --timeout
constexpr double kMinTimeout = 0.001;  // seconds, as footfall's --timeout: shorter ones (below
                                       // 1 us, none at all) fail every call

// [Units: bytes] the longest reason ffc_last_error gives (a path of PATH_MAX and its message fit).
constexpr size_t kMaxError = 8192;

// `text` as ffc_last_error promises it: one line of well-formed UTF-8 of at most kMaxError
// bytes. Reasons quote names, paths and request text as the caller gave them: their line breaks
// and other control characters (C0, DEL, C1, U+2028, U+2029) and bytes that are not UTF-8 are
// shown as '?'; a longer reason is cut on a whole character and ends "... (N bytes)".
std::string OneLine(const std::string& text) {
  const std::string tail_room = "... (" + std::to_string(text.size()) + " bytes)";
  const size_t limit = text.size() > kMaxError ? kMaxError - tail_room.size() : kMaxError;
  std::string out;
  out.reserve(std::min(text.size(), kMaxError));
  size_t i = 0;
  while (i < text.size()) {
    const size_t n = footfall::Utf8SequenceLength(text, i);
    const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[i + k]); };
    const bool control =
        n == 0 || footfall::IsControlCharacter(text, i, n) ||
        (n == 3 && byte(0) == 0xe2 && byte(1) == 0x80 && (byte(2) == 0xa8 || byte(2) == 0xa9));
    const size_t width = control ? 1 : n;
    if (out.size() + width > limit) break;
    if (control)
      out += '?';
    else
      out.append(text, i, n);
    i += n == 0 ? 1 : n;
  }
  if (i < text.size()) out += tail_room;
  return out;
}

void SetError(ffc_session* s, std::string text) {
  std::lock_guard<std::mutex> lock(s->error_mutex);
  s->error = std::move(text);
  s->fixed_error = nullptr;
}

// SetError without allocating, for the handlers of running out of memory: making the reason's
// string could throw there, out of an extern "C" function, and abort the host.
void SetFixedError(ffc_session* s, const char* text) noexcept {
  std::lock_guard<std::mutex> lock(s->error_mutex);
  s->error.clear();
  s->fixed_error = text;
}

int32_t Result(ffc_session* s, Status status) {
  if (status != Status::kOk) SetError(s, s->session->last_error());
  return static_cast<int32_t>(status);
}

int32_t BadArgument(ffc_session* s, const char* what) {
  if (s) SetError(s, what);
  return FF_C_INVALID_ARGUMENT;
}

void Copy(const Foothold& f, ffc_foothold* out) {
  out->status = static_cast<int32_t>(f.status);
  out->index = f.index;
  out->point[0] = f.point.x, out->point[1] = f.point.y, out->point[2] = f.point.z;
  out->normal[0] = f.normal.x, out->normal[1] = f.normal.y, out->normal[2] = f.normal.z;
}

template <typename Fn>
int32_t Guard(ffc_session* s, Fn&& fn) {
  if (!s) return FF_C_INVALID_ARGUMENT;
  std::lock_guard<std::mutex> lock(s->mutex);
  const footfall::CLocaleScope c_locale;  // the host's locale back on return
  try {
    return fn();
  } catch (const std::bad_alloc&) {
    SetFixedError(s, "out of memory");
    return FF_C_LIMIT_EXCEEDED;
  } catch (const std::length_error&) {
    SetFixedError(s, "too many items for memory");
    return FF_C_LIMIT_EXCEEDED;
  } catch (const std::exception& e) {
    try {
      SetError(s, std::string("internal error: ") + e.what());
    } catch (...) {
      SetFixedError(s, "internal error");
    }
    return FF_C_INTERNAL_ERROR;
  } catch (...) {
    SetFixedError(s, "internal error");
    return FF_C_INTERNAL_ERROR;
  }
}

int32_t PointQuery(ffc_session* s, uint32_t terrain, const double* points, size_t count,
                   ffc_foothold* out, bool normal) {
  return Guard(s, [&]() -> int32_t {
    if (count && (!points || !out)) return BadArgument(s, "points and out must not be NULL");
    std::vector<footfall::Vec3> q(count);
    for (size_t i = 0; i < count; ++i) q[i] = {points[3 * i], points[3 * i + 1], points[3 * i + 2]};
    std::vector<Foothold> answers(count);
    const Status status = normal ? s->session->Normal(terrain, q.data(), count, answers.data())
                                 : s->session->Snap(terrain, q.data(), count, answers.data());
    if (status == Status::kOk)
      for (size_t i = 0; i < count; ++i) Copy(answers[i], &out[i]);
    return Result(s, status);
  });
}

// A malloc'd copy of `text` for the caller to release with ffc_free_string; NULL when no memory.
char* MallocCopy(const std::string& text) {
  char* copy = static_cast<char*>(std::malloc(text.size() + 1));
  if (copy) std::memcpy(copy, text.c_str(), text.size() + 1);
  return copy;
}

// The walk's JSON in one malloc'd, NUL-terminated block, or nullptr when memory runs out. The
// block grows by realloc as the text is built (large blocks move without being copied), so a
// crowd's gigabytes of text are never held twice.
char* MallocWalkJson(const footfall::Walk& walk) {
  char* text = nullptr;
  size_t size = 0, capacity = 0;
  const bool built = footfall::EmitWalkJson(walk, [&](std::string_view piece) {
    if (size + piece.size() + 1 > capacity) {
      const size_t grown = std::max(2 * capacity, size + piece.size() + 1);
      char* more = static_cast<char*>(std::realloc(text, grown));
      if (!more) return false;
      text = more, capacity = grown;
    }
    std::memcpy(text + size, piece.data(), piece.size());
    size += piece.size();
    return true;
  });
  if (!built || !text) {
    std::free(text);
    return nullptr;
  }
  text[size] = '\0';
  return text;
}

// ffc_generate and ffc_generate_with_notes (notes NULL: not wanted).
int32_t Generate(ffc_session* s, uint32_t terrain, const char* request_json, char** walk_json,
                 char** notes) {
  if (walk_json) *walk_json = nullptr;  // on every failure but a walk that stopped early
  if (notes) *notes = nullptr;
  return Guard(s, [&]() -> int32_t {
    s->walk_stop = FF_C_OK;
    if (!request_json || !walk_json)
      return BadArgument(s, "request_json and walk_json must not be NULL");
    footfall::Character character;
    footfall::GenerateOptions options;
    footfall::Walk walk;
    std::string error;
    Status status = footfall::ParseGenerateRequest(request_json, &character, &options, &error);
    if (status == Status::kOk)
      status = footfall::GenerateWalk(*s->session, terrain, character, options, &walk, &error);
    if (status != Status::kOk) {
      SetError(s, error);
      return static_cast<int32_t>(status);
    }
    std::string note_text;
    if (notes)
      for (const std::string& note : walk.notes) note_text += OneLine(note) + '\n';
    char* copy = MallocWalkJson(walk);
    char* note_copy = notes ? MallocCopy(note_text) : nullptr;
    if (!copy || (notes && !note_copy)) {
      std::free(copy), std::free(note_copy);
      SetFixedError(s, "out of memory");
      return FF_C_LIMIT_EXCEEDED;
    }
    *walk_json = copy;
    if (notes) *notes = note_copy;
    if (!walk.stopped.empty()) {  // the keys so far are in *walk_json
      SetError(s, walk.stopped);
      s->walk_stop = walk.session_failed ? FF_C_UNAVAILABLE : FF_C_NO_FOOTHOLD;
      return FF_C_NO_FOOTHOLD;
    }
    return FF_C_OK;
  });
}

}  // namespace

extern "C" {

int ffc_abi_version(void) { return FFC_ABI_VERSION; }

// Why the last ffc_open_* on this thread returned NULL (ffc_last_error(NULL) says it), or NULL
// when it did not. Fixed texts: the reason for running out of memory allocates nothing.
static thread_local const char* t_open_refused = nullptr;

ffc_session* ffc_open_embedded(void) {
  std::signal(SIGPIPE, SIG_IGN);
  t_open_refused = nullptr;
  try {
    auto s = std::make_unique<ffc_session>();  // freed if the session cannot be made
    s->session = footfall::MakeEmbeddedSession();
    return s.release();
  } catch (...) {
    t_open_refused = "no session (the last ffc_open_* on this thread ran out of memory)";
    return nullptr;
  }
}

ffc_session* ffc_open_rpc(const char* host, int port, double timeout_s) {
  std::signal(SIGPIPE, SIG_IGN);
  t_open_refused = nullptr;
  auto refuse = [](const char* why) {
    t_open_refused = why;
    return nullptr;
  };
  if (port < 1 || port > 65535)
    return refuse("no session (ffc_open_rpc: the port is outside 1-65535)");
  // NaN, infinite either way, beyond any bound, or too short for any call to be answered.
  if (!std::isfinite(timeout_s) || timeout_s > kMaxTimeout)
    return refuse("no session (ffc_open_rpc: the timeout is NaN, infinite or above 1e6 s)");
  if (timeout_s > 0 && timeout_s < kMinTimeout)
    return refuse(
        "no session (ffc_open_rpc: the timeout is below 0.001 s, too short for any call)");
  try {
    footfall::RpcOptions options;
    if (host && *host && !footfall::ParseHost(host, &options.host))
      return refuse(
          "no session (ffc_open_rpc: the host is no host name or IP address: a port in it, or "
          "brackets around anything but an IPv6 address)");
    options.port = port;
    if (timeout_s > 0) options.call_timeout_s = timeout_s;
    auto s = std::make_unique<ffc_session>();
    s->session = footfall::MakeRpcSession(options);
    return s.release();
  } catch (...) {
    return refuse("no session (the last ffc_open_* on this thread ran out of memory)");
  }
}

void ffc_close(ffc_session* session) { delete session; }

const char* ffc_last_error(const ffc_session* session) {
  if (!session) return t_open_refused ? t_open_refused : "no session";
  // The calling thread's copy: another thread's call may replace the session's meanwhile.
  thread_local std::string copy;
  try {
    std::string error;
    {
      std::lock_guard<std::mutex> lock(session->error_mutex);
      if (session->fixed_error) return session->fixed_error;
      error = session->error;
    }
    copy = OneLine(error);
  } catch (...) {  // no memory for the copy
    return "out of memory for the error text";
  }
  return copy.c_str();
}

const char* ffc_status_name(int32_t status) {
  return footfall::StatusName(static_cast<Status>(status));
}

int32_t ffc_load_file(ffc_session* s, const char* path, double separation, uint32_t* terrain) {
  return Guard(s, [&]() -> int32_t {
    if (!path || !terrain) return BadArgument(s, "path and terrain must not be NULL");
    footfall::TerrainLoadOptions options;
    // (<= 0: the default. A NaN or -infinity is passed on, to be refused as +infinity is: they
    // were taken for the default.)
    options.separation = separation > 0 || !std::isfinite(separation) ? separation : 0;
    return Result(s, s->session->LoadFile(path, options, terrain));
  });
}

int32_t ffc_load_server_file(ffc_session* s, const char* path, double separation,
                             uint32_t* terrain) {
  return Guard(s, [&]() -> int32_t {
    if (!path || !terrain) return BadArgument(s, "path and terrain must not be NULL");
    footfall::TerrainLoadOptions options;
    // (<= 0: the default. A NaN or -infinity is passed on, to be refused as +infinity is: they
    // were taken for the default.)
    options.separation = separation > 0 || !std::isfinite(separation) ? separation : 0;
    return Result(s, s->session->LoadServerFile(path, options, terrain));
  });
}

int32_t ffc_load_samples(ffc_session* s, const double* samples, size_t count, const char* name,
                         uint32_t* terrain) {
  return Guard(s, [&]() -> int32_t {
    if ((count && !samples) || !terrain)
      return BadArgument(s, "samples and terrain must not be NULL");
    footfall::RawSamples raw;
    raw.points.reserve(count), raw.normals.reserve(count);
    for (size_t i = 0; i < count; ++i) {
      const double* v = samples + 6 * i;
      raw.push_back({v[0], v[1], v[2]}, {v[3], v[4], v[5]});
    }
    return Result(s, s->session->LoadSamples(raw, name ? name : "samples", terrain));
  });
}

int32_t ffc_ping(ffc_session* s) {
  return Guard(s, [&]() -> int32_t { return Result(s, s->session->Ping()); });
}

int32_t ffc_unload(ffc_session* s, uint32_t terrain) {
  return Guard(s, [&]() -> int32_t { return Result(s, s->session->Unload(terrain)); });
}

int32_t ffc_info(ffc_session* s, uint32_t terrain, uint64_t* samples, double bounds[6]) {
  return Guard(s, [&]() -> int32_t {
    footfall::TerrainInfo info;
    const Status status = s->session->Info(terrain, &info);
    if (status == Status::kOk) {
      if (samples) *samples = info.stats.samples;
      if (bounds) {
        const auto &lo = info.stats.bounds_min, &hi = info.stats.bounds_max;
        bounds[0] = lo.x, bounds[1] = lo.y, bounds[2] = lo.z;
        bounds[3] = hi.x, bounds[4] = hi.y, bounds[5] = hi.z;
      }
    }
    return Result(s, status);
  });
}

int32_t ffc_snap(ffc_session* s, uint32_t terrain, const double* points, size_t count,
                 ffc_foothold* out) {
  return PointQuery(s, terrain, points, count, out, false);
}

int32_t ffc_normal(ffc_session* s, uint32_t terrain, const double* points, size_t count,
                   ffc_foothold* out) {
  return PointQuery(s, terrain, points, count, out, true);
}

int32_t ffc_next(ffc_session* s, uint32_t terrain, const double* steps, size_t count,
                 double tolerance, ffc_foothold* out) {
  return Guard(s, [&]() -> int32_t {
    if (count && (!steps || !out)) return BadArgument(s, "steps and out must not be NULL");
    std::vector<footfall::StepQuery> q(count);
    for (size_t i = 0; i < count; ++i) {
      const double* v = steps + 6 * i;
      q[i] = {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
    }
    std::vector<Foothold> answers(count);
    const Status status = s->session->Next(terrain, q.data(), count, tolerance, answers.data());
    if (status == Status::kOk)
      for (size_t i = 0; i < count; ++i) Copy(answers[i], &out[i]);
    return Result(s, status);
  });
}

int32_t ffc_generate(ffc_session* s, uint32_t terrain, const char* request_json, char** walk_json) {
  return Generate(s, terrain, request_json, walk_json, nullptr);
}

int32_t ffc_generate_with_notes(ffc_session* s, uint32_t terrain, const char* request_json,
                                char** walk_json, char** notes) {
  return Generate(s, terrain, request_json, walk_json, notes);
}

void ffc_free_string(char* text) { std::free(text); }

int32_t ffc_walk_stop(ffc_session* s) {
  return Guard(s, [&]() -> int32_t { return s->walk_stop; });
}

int32_t ffc_check_character(ffc_session* s, const char* character_json) {
  return Guard(s, [&]() -> int32_t {
    if (!character_json) return BadArgument(s, "character_json must not be NULL");
    footfall::Character character;
    std::string error;
    const Status status = footfall::ParseCharacter(character_json, "character", &character, &error);
    if (status != Status::kOk) SetError(s, error);
    return static_cast<int32_t>(status);
  });
}

}  // extern "C"
