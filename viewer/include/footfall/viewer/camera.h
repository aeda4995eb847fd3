// OrbitCamera: a perspective camera circling a target point, y up, in render space (world
// space minus the scene origin, so float vertices stay precise far from the world origin).
// The camera itself is kept in double precision: an eye beside the scene may look at a target
// up to 1e15 away (--camera) and still be placed to the unit.
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace footfall::viewer {

// An axis-aligned box in render space: one drawn thing (the terrain, a walk, a query).
struct RenderBox {
  glm::dvec3 lo, hi;
};

class OrbitCamera {
 public:
  // Vertical field of view. [Units: degrees]
  static constexpr double kFovYDegrees = 45.0;

  // Looks at the box [lo, hi] (render space) from the current direction, far enough to see
  // all of it in a viewport of this aspect ratio (width / height) between bands left to
  // overlays at its top and bottom (fractions of its height, [0, 0.45]); the target is moved
  // off the box's centre so that it shows in the middle of what is clear. A box whose bounding
  // sphere is smaller than `min_radius` (> 0, render units) is framed as a sphere of that
  // radius around its centre.
  void Frame(const glm::dvec3& lo, const glm::dvec3& hi, double min_radius, double aspect = 1,
             double top_band = 0, double bottom_band = 0);
  // Places the eye and the target (render space). eye != target. The eye is kept as given
  // unless the view is within a degree of vertical, which is tilted to 89 degrees about the
  // target: then returns false.
  bool LookAt(const glm::dvec3& eye, const glm::dvec3& target);

  // Turns around the target. [Units: radians] Pitch stays within (-89, 89) degrees.
  void Orbit(double yaw_delta, double pitch_delta);
  // Moves the eye and the target in the view plane by a fraction of the view height at the
  // target.
  void Pan(double dx_fraction, double dy_fraction);
  // Multiplies the distance to the target by `factor` (> 0), within [1e-4, 1e15].
  void Zoom(double factor);

  const glm::dvec3& eye() const { return eye_; }
  const glm::dvec3& target() const { return target_; }
  double distance() const { return distance_; }
  // A unit vector from the eye toward the target.
  glm::dvec3 Forward() const;
  glm::dmat4 View() const;
  // Perspective projection for a viewport of this aspect ratio (width / height), its near and
  // far planes chosen from the depths of `boxes` (render space: each drawn thing) seen from the
  // eye, whatever the target's distance. The near plane is the nearest box's (boxes around the
  // eye: 1e-5 of the farthest box's far side, or of 100 times the nearest far side of the boxes
  // around the eye if less), the
  // far plane the farthest box's, but at most 1e5 times the near plane: what lies farther is
  // clipped, never what is near (a query 1e9 away left the terrain under the eye beyond the
  // near plane), nor what lies just past the terrain under the eye. (Depth is 24-bit: a box
  // reaching from the eye to far keeps about 1/170 of far as its depth resolution at far.)
  glm::dmat4 Projection(double aspect, const std::vector<RenderBox>& boxes) const;

  // Projects a render-space point to pixels of a width x height image (x right, y down, origin
  // at the top-left pixel corner). Returns false for points behind the eye.
  bool Project(const glm::dvec3& p, int width, int height, glm::dvec2* pixel) const;

 private:
  // Places the eye at `distance_` from the target along yaw and pitch.
  void PlaceEye();

  glm::dvec3 target_{0, 0, 0};
  glm::dvec3 eye_{0, 0, 10};
  double distance_ = 10;  // [Units: render units] |eye - target|
  double yaw_ = 0.6;      // [Units: radians] around +y, 0 looks along -z
  double pitch_ = 0.6;    // [Units: radians] above the horizon
};

}  // namespace footfall::viewer
