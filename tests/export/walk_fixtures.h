// Walks built in code for the exporter tests: a biped with start/mid/end foot keys and a turning
// body, and a two-character crowd. Frames start at 1, as in Maya.
#pragma once

#include <string>
#include <vector>

#include "footfall/steps/walk.h"

namespace footfall {
namespace test {

// A rotation of `degrees` about +Y (Maya's up), as a unit quaternion.
Quat YawQuat(double degrees);

// fps 24. Tracks: foot "L" (2 steps, 6 keys at frames 1..37), foot "R" (2 steps; its first end
// and second start share frame 25, so 5 distinct frames), "body" (5 keys turning 0, 60, 150,
// 170, 190 degrees about +Y; the 60-degree key is not unit length and the 170-degree key has
// its sign flipped).
Walk BipedWalk();

// fps 30. Characters "ant 1" and "ant-2", each with feet "L1", "R1" and a "body" (3 keys each),
// offset 2 units apart along X.
Walk CrowdWalk();

// CrowdWalk with `extra` more keys on every track, one a frame after its last, the i-th moved
// 1/3 + 0.001 i units along X from it (bodies keep their last rotation).
Walk LongCrowdWalk(int extra);

// BipedWalk at real-world coordinates, near (5e5, 120, -3e5) as in a UTM terrain: every key
// moved by (500000.0004, 120.0007, -300000.0009) plus 1.3 mm * its index along (1, 1, -1), so
// keys differ by millimetres that a float at 5e5 (a step of 1/32) cannot hold.
Walk FarWalk();

// fps 24. A body (keys at frames 1, 13 and 25 turning 0, 90 and 90 degrees about +Y, the
// 90-degree one with its sign flipped) and one foot "L" whose keys (frames 1, 7, 13, 19, 25)
// have the normals (0, 1, 0), (0, 1, 0), (0.6, 0.8, 0), zero and (0, -2, 0). Each foot key
// oriented as the exports' foot_rotations key it has the up and forward of TiltedFootAxes.
Walk TiltedFootWalk();
struct FootAxes {
  Vec3 up, forward;  // unit, world space
};
std::vector<FootAxes> TiltedFootAxes();

// `v` rotated by `q` (any non-zero length).
Vec3 Rotated(const Quat& q, const Vec3& v);

// A scratch file path unique to this process: <tmp>/footfall_export_<pid>_<name>.
std::string ScratchPath(const std::string& name);

}  // namespace test
}  // namespace footfall
