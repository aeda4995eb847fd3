// Writing walk JSON: numbers that read back exactly, keys in ascending frames, a megabyte at a
// time. Reading it is walk_json_read.cpp.
#include "footfall/steps/walk_json.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "footfall/terrain/ordered_text.h"
#include "footfall/terrain/output_file.h"

namespace footfall {
namespace {

using nlohmann::json;

// Shortest text that reads back as the same double; JSON has no NaN/Inf, so those write null
// (the generator never produces them).
void Number(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  if (v == 0) v = 0;  // no "-0"
  char buffer[32];
  const auto r = std::to_chars(buffer, buffer + sizeof buffer, v);
  out.append(buffer, r.ptr);
}

void Vector(std::string& out, const Vec3& v) {
  out += '[';
  Number(out, v.x), out += ',', Number(out, v.y), out += ',', Number(out, v.z);
  out += ']';
}

void String(std::string& out, const std::string& s) {
  out += json(s).dump(-1, ' ', false, json::error_handler_t::replace);  // never throws
}

void Rotation(std::string& out, const Quat& q) {
  out += ",\"rotation\":[";
  Number(out, q.x), out += ',', Number(out, q.y), out += ',';
  Number(out, q.z), out += ',', Number(out, q.w);
  out += ']';
}

const char* KindName(TrackKind kind) { return kind == TrackKind::kFoot ? "foot" : "body"; }

// Which keys of `track` are written, in order: all of them when their frames increase (every
// generated walk), else ascending frames (stable) with only the last of the keys sharing a frame,
// as the glTF and MEL exporters key them, so that the file reads back. `order` is left empty for
// the first case.
void WrittenOrder(const WalkTrack& track, std::vector<size_t>* order) {
  order->clear();
  const auto& keys = track.keys;
  bool increasing = true;
  for (size_t i = 1; i < keys.size() && increasing; ++i)
    increasing = keys[i - 1].frame < keys[i].frame;
  // A NaN frame (written as null, refused on reading) has no place in any order.
  const bool finite = std::all_of(keys.begin(), keys.end(),
                                  [](const WalkKey& k) { return std::isfinite(k.frame); });
  if (!increasing && finite) *order = KeyOrder(track);
}

}  // namespace

namespace {

// A stretch of one track's keys, written on its own: [first, end) of the keys in written order,
// its track's opening with the first key and its closing with the last.
struct KeyRun {
  size_t track, first, end;
};

// Keys in a run: about a megabyte of text (about 150 bytes a key).
constexpr size_t kRunKeys = 7000;

// Appends run `run` of `walk` (its track's keys in `order`, or in place when empty) to `out`,
// exactly as the whole text holds it.
void AppendRun(const Walk& walk, const KeyRun& run, const std::vector<size_t>& order,
               std::string& out) {
  const WalkTrack& t = walk.tracks[run.track];
  const size_t count = order.empty() ? t.keys.size() : order.size();
  // A foot track's orientations, when it carries one per key (AddFootRotations).
  const bool rotated = t.kind == TrackKind::kFoot && t.rotations.size() == t.keys.size();
  if (run.first == 0) {
    out += run.track ? ",\n" : "\n";
    out += "{\"name\":";
    String(out, t.name);
    if (!t.character.empty()) out += ",\"character\":", String(out, t.character);
    out += ",\"kind\":\"";
    out += KindName(t.kind);
    out += '"';
    if (t.kind == TrackKind::kFoot && t.foot_length > 0) {
      out += ",\"foot_length\":";
      Number(out, t.foot_length);
    }
    if (t.kind == TrackKind::kFoot && t.foot_width > 0) {
      out += ",\"foot_width\":";
      Number(out, t.foot_width);
    }
    out += ",\"keys\":[";
  }
  for (size_t i = run.first; i < run.end; ++i) {
    const size_t ki = order.empty() ? i : order[i];
    const WalkKey& k = t.keys[ki];
    out += i ? ",\n " : "\n ";
    out += "{\"frame\":";
    Number(out, k.frame);
    if (t.kind == TrackKind::kFoot) {
      out += ",\"phase\":\"";
      out += PhaseName(k.phase);
      out += "\",\"position\":";
      Vector(out, k.position);
      out += ",\"normal\":";
      Vector(out, k.normal);
      if (rotated) Rotation(out, t.rotations[ki]);
    } else {
      out += ",\"position\":";
      Vector(out, k.position);
      Rotation(out, t.Rotation(ki));
    }
    out += '}';
  }
  if (run.end == count) out += "]}";
}

}  // namespace

bool EmitWalkJson(const Walk& walk, const std::function<bool(std::string_view)>& sink,
                  int threads) {
  // Each track's keys in written order, and the runs they are written in.
  std::vector<std::vector<size_t>> orders(walk.tracks.size());
  std::vector<KeyRun> runs;
  size_t keys = 0;
  for (size_t ti = 0; ti < walk.tracks.size(); ++ti) {
    WrittenOrder(walk.tracks[ti], &orders[ti]);
    const size_t count = orders[ti].empty() ? walk.tracks[ti].keys.size() : orders[ti].size();
    keys += count;
    size_t first = 0;
    do {
      const size_t end = std::min(count, first + kRunKeys);
      runs.push_back({ti, first, end});
      first = end;
    } while (first < count);
  }
  std::string out;
  out += "{\"format\":\"footfall-walk\",\"version\":";
  out += std::to_string(kWalkFormatVersion);
  out += ",\"fps\":";
  Number(out, walk.fps);
  if (!walk.unit.empty()) {
    out += ",\"unit\":";
    String(out, walk.unit);
  }
  out += ",\"stopped\":";
  String(out, walk.stopped);
  out += ",\"tracks\":[";
  // Runs are formatted on several threads at a time (numbers to text is most of the work), and
  // given to the sink in order: the same text on any number of threads. The head goes with the
  // first run, the tail with the last.
  const bool formatted = FormatInOrder(
      runs.size(), keys < 4 * kRunKeys ? 1 : threads,
      [&](size_t r, std::string* text) {
        if (r == 0) *text += out;
        text->reserve(text->size() + kRunKeys * 180);
        AppendRun(walk, runs[r], orders[runs[r].track], *text);
        if (r + 1 == runs.size()) *text += "\n]}\n";
      },
      sink);
  if (!formatted) return false;
  return !runs.empty() || sink(out + "\n]}\n");
}

std::string WalkToJson(const Walk& walk) {
  std::string text;
  size_t keys = 0;
  for (const WalkTrack& t : walk.tracks) keys += t.keys.size();
  text.reserve(256 + keys * 160);  // about 150 bytes a key
  EmitWalkJson(walk, [&text](std::string_view piece) {
    text += piece;
    return true;
  });
  return text;
}

Status WriteWalkJson(const Walk& walk, const std::string& path, std::string* error) {
  // Written as it is built, never whole in memory.
  return ReplaceFile(
      path,
      [&walk](std::FILE* file) {
        return EmitWalkJson(walk, [file](std::string_view piece) {
          return std::fwrite(piece.data(), 1, piece.size(), file) == piece.size();
        });
      },
      error);
}

}  // namespace footfall
