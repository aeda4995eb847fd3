#include "footfall/viewer/camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace footfall::viewer {
namespace {

constexpr double kMaxPitch = 1.55;      // just under 89 degrees
constexpr double kNearRatio = 1e-5;     // the nearest the near plane comes: far * this
constexpr double kMinDepthSpan = 0.01;  // far - near >= far * this (float depth stays exact)
// Boxes around the eye keep in view what lies up to this many times their own far side.
constexpr double kAroundReach = 100;
constexpr double kMinZoom = 1e-4;  // Zoom brings the eye no nearer the target
constexpr double kMaxZoom = 1e15;  // nor farther ([Units: render units])

// The unit vector along d and its length, without the underflow of squaring tiny components.
glm::dvec3 UnitAndLength(const glm::dvec3& d, double* length) {
  const double m = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
  if (!(m > 0)) {
    *length = 0;
    return glm::dvec3(0, 0, 1);
  }
  const glm::dvec3 u = d / m;
  const double n = glm::length(u);
  *length = m * n;
  return u / n;
}

}  // namespace

void OrbitCamera::PlaceEye() {
  const glm::dvec3 dir(std::cos(pitch_) * std::sin(yaw_), std::sin(pitch_),
                       std::cos(pitch_) * std::cos(yaw_));
  eye_ = target_ + distance_ * dir;
}

void OrbitCamera::Frame(const glm::dvec3& lo, const glm::dvec3& hi, double min_radius,
                        double aspect, double top_band, double bottom_band) {
  target_ = 0.5 * (lo + hi);
  // (At least 0.5 units, whatever the scene: a terrain a few centimetres across was a dot.)
  const double radius = std::max(0.5 * glm::length(hi - lo), min_radius);
  // The bounding sphere just fits the clear part of the view, vertically and horizontally (so
  // all of the box does). (It filled the whole height: tall terrain reached under the overlay,
  // and a window narrower than high cut the sides off.)
  // The clear part in normalized device y: its middle and half height.
  const double top = 1 - 2 * std::clamp(top_band, 0.0, 0.45);
  const double bottom = -1 + 2 * std::clamp(bottom_band, 0.0, 0.45);
  const double middle = 0.5 * (top + bottom), half = 0.5 * (top - bottom);
  const double t = std::tan(glm::radians(kFovYDegrees) * 0.5);
  const double centre = std::atan(middle * t);  // the angle the centre is seen at, below/above
  const double half_angle =
      std::min({std::atan((middle + half) * t) - centre, centre - std::atan((middle - half) * t),
                std::atan(std::max(aspect, 0.05) * t)});
  distance_ = radius / std::sin(half_angle) * 1.02;
  PlaceEye();
  // The centre shown at `middle`: the target (and the eye) lowered by as much in the view.
  const glm::dmat4 view = View();
  const glm::dvec3 up(view[0][1], view[1][1], view[2][1]);
  const glm::dvec3 shift = -up * (middle * t * distance_);
  target_ += shift;
  eye_ += shift;
}

bool OrbitCamera::LookAt(const glm::dvec3& eye, const glm::dvec3& target) {
  target_ = target;
  double length = 0;
  const glm::dvec3 d = UnitAndLength(eye - target, &length);
  distance_ = length;
  const double pitch = std::asin(std::clamp(d.y, -1.0, 1.0));
  pitch_ = std::clamp(pitch, -kMaxPitch, kMaxPitch);
  yaw_ = std::atan2(d.x, d.z);
  if (pitch_ == pitch) {
    eye_ = eye;
    return true;
  }
  PlaceEye();
  return false;
}

void OrbitCamera::Orbit(double yaw_delta, double pitch_delta) {
  yaw_ += yaw_delta;
  pitch_ = std::clamp(pitch_ + pitch_delta, -kMaxPitch, kMaxPitch);
  PlaceEye();
}

void OrbitCamera::Pan(double dx_fraction, double dy_fraction) {
  const glm::dmat4 view = View();
  const glm::dvec3 right(view[0][0], view[1][0], view[2][0]);
  const glm::dvec3 up(view[0][1], view[1][1], view[2][1]);
  const double height = 2 * distance_ * std::tan(glm::radians(kFovYDegrees) * 0.5);
  const glm::dvec3 shift = (-dx_fraction * right + dy_fraction * up) * height;
  target_ += shift;
  eye_ += shift;
}

void OrbitCamera::Zoom(double factor) {
  distance_ =
      std::clamp(distance_ * factor, std::min(distance_, kMinZoom), std::max(distance_, kMaxZoom));
  PlaceEye();
}

glm::dvec3 OrbitCamera::Forward() const {
  // From yaw and pitch, not from eye - target: defined however near the two are.
  return -glm::dvec3(std::cos(pitch_) * std::sin(yaw_), std::sin(pitch_),
                     std::cos(pitch_) * std::cos(yaw_));
}

glm::dmat4 OrbitCamera::View() const {
  // glm::lookAt's basis, from the direction itself: eye + Forward() rounds far from the origin
  // (at 1e15 a unit of precision is 0.125: the view turned by up to 5 degrees).
  const glm::dvec3 f = glm::normalize(Forward());
  const glm::dvec3 s = glm::normalize(glm::cross(f, glm::dvec3(0, 1, 0)));
  const glm::dvec3 u = glm::cross(s, f);
  glm::dmat4 m(1);
  for (int i = 0; i < 3; ++i) m[i][0] = s[i], m[i][1] = u[i], m[i][2] = -f[i];
  m[3][0] = -glm::dot(s, eye_), m[3][1] = -glm::dot(u, eye_), m[3][2] = glm::dot(f, eye_);
  return m;
}

glm::dmat4 OrbitCamera::Projection(double aspect, const std::vector<RenderBox>& boxes) const {
  const glm::dvec3 forward = Forward();
  double near_plane = HUGE_VAL, far_plane = -HUGE_VAL;
  double around_far = HUGE_VAL;  // the nearest far side of the boxes around the eye
  for (const RenderBox& box : boxes) {
    // The depths of the box's corners along the view direction.
    double nearest = HUGE_VAL, farthest = -HUGE_VAL;
    for (int i = 0; i < 8; ++i) {
      const glm::dvec3 corner(i & 1 ? box.hi.x : box.lo.x, i & 2 ? box.hi.y : box.lo.y,
                              i & 4 ? box.hi.z : box.lo.z);
      const double depth = glm::dot(corner - eye_, forward);
      nearest = std::min(nearest, depth);
      farthest = std::max(farthest, depth);
    }
    if (!(farthest > 0)) continue;  // behind the eye: nothing of it is drawn
    far_plane = std::max(far_plane, farthest * 1.001);
    // Wholly in front: from its nearest corner. Around the eye: set below.
    if (nearest > 0)
      near_plane = std::min(near_plane, nearest * 0.999);
    else
      around_far = std::min(around_far, farthest * 1.001);
  }
  const double fov = glm::radians(kFovYDegrees);
  // Everything behind the eye: nothing to draw, any planes will do.
  if (!(far_plane > 0)) return glm::perspective(fov, aspect, 1.0, 2.0);
  // Around the eye: as near as depth allows of what is drawn up to kAroundReach times the
  // nearest far side of the boxes around the eye (from that far side itself, a walk just past
  // the terrain under the eye was clipped; from everything's, a query 1e9 away, whose box
  // reaches round the eye too, clipped that terrain).
  if (around_far < HUGE_VAL)
    near_plane = std::min(near_plane, std::min(far_plane, kAroundReach * around_far) * kNearRatio);
  far_plane = std::min(far_plane, near_plane / kNearRatio);
  near_plane = std::min(near_plane, far_plane * (1 - kMinDepthSpan));
  return glm::perspective(fov, aspect, near_plane, far_plane);
}

bool OrbitCamera::Project(const glm::dvec3& p, int width, int height, glm::dvec2* pixel) const {
  // Clip x and y do not depend on the depth planes: any will do.
  const double aspect = static_cast<double>(width) / static_cast<double>(height);
  const glm::dmat4 projection = glm::perspective(glm::radians(kFovYDegrees), aspect, 1.0, 2.0);
  const glm::dvec4 clip = projection * View() * glm::dvec4(p, 1);
  if (clip.w <= 0) return false;
  const glm::dvec2 ndc(clip.x / clip.w, clip.y / clip.w);
  *pixel = glm::dvec2((ndc.x * 0.5 + 0.5) * width, (0.5 - ndc.y * 0.5) * height);
  return true;
}

}  // namespace footfall::viewer
