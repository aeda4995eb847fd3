// Where a walk's feet and body are at a given frame, for drawing and playback.
#pragma once

#include <string>

#include "footfall/steps/walk.h"

namespace footfall::viewer {

struct TrackPose {
  Vec3 position;  // world space
  Vec3 normal{0, 1, 0};
  Quat rotation;          // body tracks, and feet that carry rotations (AddFootRotations)
  bool swinging = false;  // feet: between a start and an end key
};

// The pose of `track` at `frame` (animation frames, may be fractional). A swing from a start
// key through a mid key to an end key follows the quadratic arc through those three points;
// elsewhere positions are interpolated linearly (a planted foot keeps its place). Rotations
// (bodies', and feet's that have them) are interpolated spherically between neighbouring keys.
// Before the first key and after the last the track holds still. The track must have at least one
// key.
TrackPose PoseAt(const WalkTrack& track, double frame);

// A point of the quadratic arc through start (t = 0), mid (t = 0.5) and end (t = 1).
Vec3 ArcPoint(const Vec3& start, const Vec3& mid, const Vec3& end, double t);

// The first and last key frames over all tracks; {0, 0} for a walk without keys.
void FrameRange(const Walk& walk, double* first, double* last);

// A frame as the overlay and messages show it: in plain digits with at most 3 decimals, trailing
// zeros dropped ("1000000010.5", "0.667"; six significant digits wrote frame 1000010 as
// "1.00001e+06"); from 1e15 on, with an exponent ("1e+300", "1.000000000000001e+15").
std::string FrameText(double frame);
// A frame as FrameText writes it, with more decimals where it takes them to read back as
// `frame` (messages quoting a frame against a range: "--frame 0.9999 is outside 1-49", never
// "--frame 1 is outside 1-49"); in the shortest form with an exponent where no decimals do.
std::string ExactFrameText(double frame);

}  // namespace footfall::viewer
