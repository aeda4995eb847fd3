#include "footfall/viewer/camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace footfall::viewer {
namespace {
constexpr float kMaxPitch = 1.55f;  // just under 89 degrees
}

void OrbitCamera::Frame(const glm::vec3& lo, const glm::vec3& hi) {
  target_ = 0.5f * (lo + hi);
  radius_ = std::max(0.5f * glm::length(hi - lo), 0.5f);
  const float half_fov = glm::radians(kFovYDegrees) * 0.5f;
  // The bounding sphere just fits the vertical field of view (so all of the box does).
  distance_ = radius_ / std::sin(half_fov) * 1.02f;
}

void OrbitCamera::LookAt(const glm::vec3& eye, const glm::vec3& target) {
  target_ = target;
  const glm::vec3 d = eye - target;
  distance_ = std::max(glm::length(d), 1e-4f);
  pitch_ = std::clamp(std::asin(std::clamp(d.y / distance_, -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
  yaw_ = std::atan2(d.x, d.z);
  radius_ = std::max(radius_, distance_);
}

void OrbitCamera::Orbit(float yaw_delta, float pitch_delta) {
  yaw_ += yaw_delta;
  pitch_ = std::clamp(pitch_ + pitch_delta, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::Pan(float dx_fraction, float dy_fraction) {
  const glm::mat4 view = View();
  const glm::vec3 right(view[0][0], view[1][0], view[2][0]);
  const glm::vec3 up(view[0][1], view[1][1], view[2][1]);
  const float height = 2 * distance_ * std::tan(glm::radians(kFovYDegrees) * 0.5f);
  target_ += (-dx_fraction * right + dy_fraction * up) * height;
}

void OrbitCamera::Zoom(float factor) { distance_ = std::max(distance_ * factor, 1e-4f); }

glm::vec3 OrbitCamera::Eye() const {
  const glm::vec3 dir(std::cos(pitch_) * std::sin(yaw_), std::sin(pitch_),
                      std::cos(pitch_) * std::cos(yaw_));
  return target_ + distance_ * dir;
}

glm::mat4 OrbitCamera::View() const { return glm::lookAt(Eye(), target_, glm::vec3(0, 1, 0)); }

glm::mat4 OrbitCamera::Projection(float aspect) const {
  const float reach = distance_ + 2 * radius_;
  const float near_plane = std::max(reach * 1e-4f, 1e-4f);
  return glm::perspective(glm::radians(kFovYDegrees), aspect, near_plane, reach * 2);
}

bool OrbitCamera::Project(const glm::vec3& p, int width, int height, glm::vec2* pixel) const {
  const glm::vec4 clip =
      Projection(static_cast<float>(width) / static_cast<float>(height)) * View() * glm::vec4(p, 1);
  if (clip.w <= 0) return false;
  const glm::vec2 ndc(clip.x / clip.w, clip.y / clip.w);
  *pixel = glm::vec2((ndc.x * 0.5f + 0.5f) * static_cast<float>(width),
                     (0.5f - ndc.y * 0.5f) * static_cast<float>(height));
  return true;
}

}  // namespace footfall::viewer
