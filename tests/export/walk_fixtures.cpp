#include "walk_fixtures.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>

namespace footfall {
namespace test {
namespace {

WalkKey FootKey(double frame, KeyPhase phase, Vec3 position) {
  WalkKey key;
  key.frame = frame;
  key.phase = phase;
  key.position = position;
  return key;
}

void AddBodyKey(WalkTrack* body, double frame, Vec3 position, Quat rotation) {
  WalkKey key;
  key.frame = frame;
  key.position = position;
  body->keys.push_back(key);
  body->rotations.push_back(rotation);
}

WalkTrack Track(const std::string& name, const std::string& character, TrackKind kind) {
  WalkTrack track;
  track.name = name;
  track.character = character;
  track.kind = kind;
  return track;
}

}  // namespace

Quat YawQuat(double degrees) {
  const double half = degrees * 3.14159265358979323846 / 360.0;
  return {0, std::sin(half), 0, std::cos(half)};
}

Walk BipedWalk() {
  Walk walk;
  walk.fps = 24;
  WalkTrack left = Track("L", "", TrackKind::kFoot);
  left.keys = {FootKey(1, KeyPhase::kStart, {-0.1, 0, 0}),
               FootKey(7, KeyPhase::kMid, {-0.1, 0.15, 0.25}),
               FootKey(13, KeyPhase::kEnd, {-0.1, 0.02, 0.5}),
               FootKey(25, KeyPhase::kStart, {-0.1, 0.02, 0.5}),
               FootKey(31, KeyPhase::kMid, {-0.1, 0.2, 0.75}),
               FootKey(37, KeyPhase::kEnd, {-0.1, 0.05, 1.0})};
  WalkTrack right = Track("R", "", TrackKind::kFoot);
  right.keys = {FootKey(13, KeyPhase::kStart, {0.1, 0, 0}),
                FootKey(19, KeyPhase::kMid, {0.1, 0.15, 0.25}),
                FootKey(25, KeyPhase::kEnd, {0.1, 0.01, 0.5}),
                FootKey(25, KeyPhase::kStart, {0.1, 0.01, 0.5}),
                FootKey(31, KeyPhase::kMid, {0.1, 0.18, 0.75}),
                FootKey(37, KeyPhase::kEnd, {0.1, 0.03, 1.0})};
  WalkTrack body = Track("body", "", TrackKind::kBody);
  Quat q60 = YawQuat(60);
  q60 = {q60.x * 2, q60.y * 2, q60.z * 2, q60.w * 2};
  Quat q170 = YawQuat(170);
  q170 = {-q170.x, -q170.y, -q170.z, -q170.w};
  AddBodyKey(&body, 1, {0, 0.9, 0}, YawQuat(0));
  AddBodyKey(&body, 13, {0, 0.91, 0.25}, q60);
  AddBodyKey(&body, 25, {0, 0.92, 0.5}, YawQuat(150));
  AddBodyKey(&body, 31, {0, 0.93, 0.6}, q170);
  AddBodyKey(&body, 37, {0, 0.94, 0.75}, YawQuat(190));
  walk.tracks = {left, right, body};
  return walk;
}

Vec3 Rotated(const Quat& q_in, const Vec3& v) {
  const double n = std::sqrt(q_in.x * q_in.x + q_in.y * q_in.y + q_in.z * q_in.z + q_in.w * q_in.w);
  const double x = q_in.x / n, y = q_in.y / n, z = q_in.z / n, w = q_in.w / n;
  const Vec3 t{2 * (y * v.z - z * v.y), 2 * (z * v.x - x * v.z), 2 * (x * v.y - y * v.x)};
  return {v.x + w * t.x + y * t.z - z * t.y, v.y + w * t.y + z * t.x - x * t.z,
          v.z + w * t.z + x * t.y - y * t.x};
}

Walk TiltedFootWalk() {
  Walk walk;
  walk.fps = 24;
  WalkTrack left = Track("L", "", TrackKind::kFoot);
  left.keys = {FootKey(1, KeyPhase::kStart, {0, 0, 0}), FootKey(7, KeyPhase::kMid, {0, 0.2, 0.3}),
               FootKey(13, KeyPhase::kEnd, {0.1, 0, 0.6}),
               FootKey(19, KeyPhase::kMid, {0.4, 0.2, 0.6}),
               FootKey(25, KeyPhase::kEnd, {0.7, 0, 0.6})};
  const Vec3 normals[] = {{0, 1, 0}, {0, 1, 0}, {0.6, 0.8, 0}, {0, 0, 0}, {0, -2, 0}};
  for (size_t k = 0; k < left.keys.size(); ++k) left.keys[k].normal = normals[k];
  WalkTrack body = Track("body", "", TrackKind::kBody);
  const Quat q90 = YawQuat(90);
  AddBodyKey(&body, 1, {0, 0.9, 0}, YawQuat(0));
  AddBodyKey(&body, 13, {0, 0.9, 0.5}, {-q90.x, -q90.y, -q90.z, -q90.w});
  AddBodyKey(&body, 25, {0.5, 0.9, 0.6}, q90);
  walk.tracks = {left, body};
  return walk;
}

std::vector<FootAxes> TiltedFootAxes() {
  const double h = std::sqrt(0.5);
  // Frame 1: facing +Z. Frame 7: halfway through the body's turn, facing 45 degrees. Frame 13:
  // facing +X, tilted onto (0.6, 0.8, 0) about Z, so its forward dips to (0.8, -0.6, 0). Frame
  // 19: no normal, the body's frame. Frame 25: upside down, half a turn about its left (-Z).
  return {{{0, 1, 0}, {0, 0, 1}},
          {{0, 1, 0}, {h, 0, h}},
          {{0.6, 0.8, 0}, {0.8, -0.6, 0}},
          {{0, 1, 0}, {1, 0, 0}},
          {{0, -1, 0}, {-1, 0, 0}}};
}

Walk CrowdWalk() {
  Walk walk;
  walk.fps = 30;
  const char* characters[] = {"ant 1", "ant-2"};
  for (int c = 0; c < 2; ++c) {
    const double x = 2.0 * c;
    WalkTrack l1 = Track("L1", characters[c], TrackKind::kFoot);
    l1.keys = {FootKey(1, KeyPhase::kStart, {x - 0.1, 0, 0}),
               FootKey(5, KeyPhase::kMid, {x - 0.1, 0.1, 0.1}),
               FootKey(9, KeyPhase::kEnd, {x - 0.1, 0, 0.2})};
    WalkTrack r1 = Track("R1", characters[c], TrackKind::kFoot);
    r1.keys = {FootKey(9, KeyPhase::kStart, {x + 0.1, 0, 0}),
               FootKey(13, KeyPhase::kMid, {x + 0.1, 0.1, 0.1}),
               FootKey(17, KeyPhase::kEnd, {x + 0.1, 0, 0.2})};
    WalkTrack body = Track("body", characters[c], TrackKind::kBody);
    AddBodyKey(&body, 1, {x, 0.3, 0}, YawQuat(0));
    AddBodyKey(&body, 9, {x, 0.3, 0.05}, YawQuat(10));
    AddBodyKey(&body, 17, {x, 0.3, 0.1}, YawQuat(20));
    walk.tracks.push_back(l1);
    walk.tracks.push_back(r1);
    walk.tracks.push_back(body);
  }
  return walk;
}

Walk FarWalk() {
  Walk walk = BipedWalk();
  const Vec3 shift{500000.0004, 120.0007, -300000.0009};
  for (WalkTrack& track : walk.tracks) {
    for (size_t i = 0; i < track.keys.size(); ++i) {
      const double mm = 0.0013 * static_cast<double>(i);
      track.keys[i].position = track.keys[i].position + shift + Vec3{mm, mm, -mm};
    }
  }
  return walk;
}

Walk LongCrowdWalk(int extra) {
  Walk walk = CrowdWalk();
  for (WalkTrack& track : walk.tracks) {
    const WalkKey last = track.keys.back();
    const Quat turn = track.Rotation(track.keys.size() - 1);
    for (int i = 1; i <= extra; ++i) {
      WalkKey key = last;
      key.frame = last.frame + i;
      key.position.x += 1.0 / 3.0 + 1e-3 * i;
      track.keys.push_back(key);
      if (track.kind == TrackKind::kBody) track.rotations.push_back(turn);
    }
  }
  return walk;
}

std::string ScratchPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("footfall_export_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

}  // namespace test
}  // namespace footfall
