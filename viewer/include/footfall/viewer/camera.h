// OrbitCamera: a perspective camera circling a target point, y up, in render space (world
// space minus the scene origin, so float vertices stay precise far from the world origin).
#pragma once

#include <glm/glm.hpp>

namespace footfall::viewer {

class OrbitCamera {
 public:
  // Vertical field of view. [Units: degrees]
  static constexpr float kFovYDegrees = 45.0f;

  // Looks at the box [lo, hi] (render space) from the current direction, far enough to see
  // all of it. An empty or degenerate box is treated as a 1-unit box around its centre.
  void Frame(const glm::vec3& lo, const glm::vec3& hi);
  // Places the eye and the target (render space). eye != target.
  void LookAt(const glm::vec3& eye, const glm::vec3& target);

  // Turns around the target. [Units: radians] Pitch stays within (-89, 89) degrees.
  void Orbit(float yaw_delta, float pitch_delta);
  // Moves the target in the view plane by a fraction of the view height.
  void Pan(float dx_fraction, float dy_fraction);
  // Multiplies the distance to the target by `factor` (> 0).
  void Zoom(float factor);

  glm::vec3 Eye() const;
  const glm::vec3& target() const { return target_; }
  float distance() const { return distance_; }
  glm::mat4 View() const;
  // Perspective projection for a viewport of this aspect ratio (width / height).
  glm::mat4 Projection(float aspect) const;

  // Projects a render-space point to pixels of a width x height image (x right, y down, origin
  // at the top-left pixel corner). Returns false for points behind the eye.
  bool Project(const glm::vec3& p, int width, int height, glm::vec2* pixel) const;

 private:
  glm::vec3 target_{0, 0, 0};
  float distance_ = 10;
  float yaw_ = 0.6f;    // [Units: radians] around +y, 0 looks along -z
  float pitch_ = 0.6f;  // [Units: radians] above the horizon
  float radius_ = 1;    // the framed box's half diagonal, for the clip planes
};

}  // namespace footfall::viewer
