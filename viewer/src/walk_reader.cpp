#include "footfall/viewer/walk_reader.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace footfall::viewer {
namespace {

using nlohmann::json;

// Thrown inside the reader only, with the JSON path of the bad value.
struct WalkError {
  std::string where, what;
};

[[noreturn]] void Bad(const std::string& where, const std::string& what) {
  throw WalkError{where, what};
}

double Number(const json& j, const std::string& where) {
  if (!j.is_number() || !std::isfinite(j.get<double>())) Bad(where, "expected a finite number");
  return j.get<double>();
}

Vec3 ReadVec3(const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) Bad(where, "expected an array of 3 finite numbers");
  return {Number(j[0], where + "[0]"), Number(j[1], where + "[1]"), Number(j[2], where + "[2]")};
}

Quat ReadQuat(const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 4)
    Bad(where, "expected an array of 4 finite numbers [qx, qy, qz, qw]");
  Quat q{Number(j[0], where + "[0]"), Number(j[1], where + "[1]"), Number(j[2], where + "[2]"),
         Number(j[3], where + "[3]")};
  const double n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (n < 1e-9) Bad(where, "expected a non-zero quaternion");
  return {q.x / n, q.y / n, q.z / n, q.w / n};
}

std::string String(const json& j, const std::string& where) {
  if (!j.is_string()) Bad(where, "expected a string");
  return j.get<std::string>();
}

KeyPhase ReadPhase(const std::string& text, const std::string& where) {
  if (text == "start") return KeyPhase::kStart;
  if (text == "mid") return KeyPhase::kMid;
  if (text == "end") return KeyPhase::kEnd;
  if (text.empty() || text == "none") return KeyPhase::kNone;
  Bad(where, "unknown phase '" + text + "' (expected start, mid or end)");
}

Walk ReadWalk(const json& root) {
  if (!root.is_object()) Bad("(top level)", "expected an object with \"fps\" and \"tracks\"");
  Walk walk;
  if (root.contains("fps")) walk.fps = Number(root["fps"], "fps");
  if (!(walk.fps > 0)) Bad("fps", "expected a number > 0");
  if (root.contains("stopped") && !root["stopped"].is_null())
    walk.stopped = String(root["stopped"], "stopped");
  if (!root.contains("tracks")) Bad("tracks", "missing");
  const json& tracks = root["tracks"];
  if (!tracks.is_array()) Bad("tracks", "expected an array of tracks");
  for (size_t t = 0; t < tracks.size(); ++t) {
    const std::string tw = "tracks[" + std::to_string(t) + "]";
    const json& jt = tracks[t];
    if (!jt.is_object()) Bad(tw, "expected an object");
    WalkTrack track;
    if (!jt.contains("name")) Bad(tw + ".name", "missing");
    track.name = String(jt["name"], tw + ".name");
    if (jt.contains("character") && !jt["character"].is_null())
      track.character = String(jt["character"], tw + ".character");
    const std::string kind = jt.contains("kind") ? String(jt["kind"], tw + ".kind") : "foot";
    if (kind == "foot") {
      track.kind = TrackKind::kFoot;
    } else if (kind == "body") {
      track.kind = TrackKind::kBody;
    } else {
      Bad(tw + ".kind", "unknown kind '" + kind + "' (expected foot or body)");
    }
    if (!jt.contains("keys") || !jt["keys"].is_array()) Bad(tw + ".keys", "expected an array");
    const json& keys = jt["keys"];
    for (size_t k = 0; k < keys.size(); ++k) {
      const std::string kw = tw + ".keys[" + std::to_string(k) + "]";
      const json& jk = keys[k];
      if (!jk.is_object()) Bad(kw, "expected an object");
      WalkKey key;
      if (!jk.contains("frame")) Bad(kw + ".frame", "missing");
      key.frame = Number(jk["frame"], kw + ".frame");
      if (!track.keys.empty() && key.frame < track.keys.back().frame)
        Bad(kw + ".frame", "frames must ascend (" + std::to_string(key.frame) + " after " +
                               std::to_string(track.keys.back().frame) + ")");
      if (jk.contains("phase") && !jk["phase"].is_null())
        key.phase = ReadPhase(String(jk["phase"], kw + ".phase"), kw + ".phase");
      if (!jk.contains("position")) Bad(kw + ".position", "missing");
      key.position = ReadVec3(jk["position"], kw + ".position");
      if (jk.contains("normal")) key.normal = ReadVec3(jk["normal"], kw + ".normal");
      if (jk.contains("rotation")) key.rotation = ReadQuat(jk["rotation"], kw + ".rotation");
      track.keys.push_back(key);
    }
    walk.tracks.push_back(std::move(track));
  }
  return walk;
}

}  // namespace

Status ReadWalkJson(const std::string& path, Walk* out, std::string* error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *error = path + ": cannot open walk file";
    return Status::kIoError;
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  json root;
  try {
    root = json::parse(text);
  } catch (const json::parse_error& e) {
    // Turn the byte offset into line:column.
    size_t line = 1, column = 1;
    const size_t end = std::min(text.size(), e.byte > 0 ? static_cast<size_t>(e.byte - 1) : 0);
    for (size_t i = 0; i < end; ++i) {
      if (text[i] == '\n') ++line, column = 1;
      else ++column;
    }
    std::string what = e.what();
    const size_t colon = what.find("parse error");
    if (colon != std::string::npos) what = what.substr(colon);
    *error = path + ":" + std::to_string(line) + ":" + std::to_string(column) +
             ": malformed JSON: " + what;
    return Status::kParseError;
  }
  try {
    *out = ReadWalk(root);
  } catch (const WalkError& e) {
    *error = path + ": " + e.where + ": " + e.what;
    return Status::kParseError;
  }
  return Status::kOk;
}

}  // namespace footfall::viewer
