// A scene's characters walked one after the other in process, or at once over RPC with their
// queries joined (scene.h: GenerateSceneWalks).
#include <algorithm>
#include <memory>
#include <new>
#include <system_error>
#include <thread>

#include "footfall/client/joined_calls.h"
#include "footfall/steps/scene.h"

namespace footfall {
namespace {

// GenerateWalk for one scene character, its failures (an exception too) kept in *w.
void WalkOne(TerrainSession& session, TerrainHandle terrain, const Character& character,
             const GenerateOptions& options, SceneWalk* w) {
  w->walked = true;
  try {
    w->status = GenerateWalk(session, terrain, character, options, &w->walk, &w->error);
  } catch (const std::bad_alloc&) {
    w->walk = Walk{};
    w->status = Status::kLimitExceeded;
    w->out_of_memory = true;
  } catch (const std::exception& e) {
    w->walk = Walk{};
    w->status = Status::kInternalError;
    w->error = std::string("unexpected error: ") + e.what();
  } catch (...) {
    w->walk = Walk{};
    w->status = Status::kInternalError;
    w->error = "unexpected error";
  }
}

// Characters [begin, end) at once, each on a thread of its own with a member of one
// JoinedCalls. A character whose thread cannot start walks afterwards on this thread.
void WalkJoined(TerrainSession& session, TerrainHandle terrain,
                const std::vector<const Character*>& characters,
                const std::vector<GenerateOptions>& options, size_t begin, size_t end,
                std::vector<SceneWalk>* out) {
  JoinedCalls joined(session);
  // Every member joins before any queries: a round starts when all members are waiting.
  std::vector<std::unique_ptr<TerrainSession>> members;
  for (size_t i = begin; i < end; ++i) members.push_back(joined.Join());
  std::vector<std::thread> threads;
  size_t started = begin;
  try {
    threads.reserve(end - begin);
    for (; started < end; ++started) {
      TerrainSession* member = members[started - begin].get();
      threads.emplace_back([&, member, started] {
        WalkOne(*member, terrain, *characters[started], options[started], &(*out)[started]);
        members[started - begin].reset();  // leaves the rounds
      });
    }
  } catch (const std::system_error&) {
  } catch (const std::bad_alloc&) {
  }
  // The members without a thread leave, so that the others' rounds run without them.
  for (size_t i = started; i < end; ++i) members[i - begin].reset();
  for (std::thread& t : threads) t.join();
  for (size_t i = started; i < end; ++i)
    WalkOne(session, terrain, *characters[i], options[i], &(*out)[i]);
}

}  // namespace

void GenerateSceneWalks(TerrainSession& session, TerrainHandle terrain,
                        const std::vector<const Character*>& characters,
                        const std::vector<GenerateOptions>& options, std::vector<SceneWalk>* out) {
  out->clear();
  out->resize(characters.size());
  if (session.InProcess() || characters.size() < 2) {
    for (size_t i = 0; i < characters.size(); ++i) {
      WalkOne(session, terrain, *characters[i], options[i], &(*out)[i]);
      if ((*out)[i].out_of_memory) break;  // (nothing is written then)
    }
    return;
  }
  for (size_t begin = 0; begin < characters.size(); begin += kJoinedSceneCharacters)
    WalkJoined(session, terrain, characters, options, begin,
               std::min(characters.size(), begin + kJoinedSceneCharacters), out);
}

}  // namespace footfall
