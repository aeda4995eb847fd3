// DrawList: points, lines and triangles collected on the CPU for one frame, in the style of
// Recast's duDebugDraw: scene code describes what to draw, the GL renderer (renderer.h) draws
// it. Scene lists are in render space; screen lists are in pixels (x right, y down).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace footfall::viewer {

struct Rgba {
  uint8_t r = 255, g = 255, b = 255, a = 255;
};

struct DrawVertex {
  glm::vec3 position;
  Rgba color;
  // Points only: > 0 a size in pixels; < 0 a size in world units (-size), shrinking with
  // distance like a surface splat.
  float size = 1;
};

class DrawList {
 public:
  void Point(const glm::vec3& p, Rgba color, float size_px) {
    points_.push_back({p, color, size_px});
  }
  void Line(const glm::vec3& a, const glm::vec3& b, Rgba color) {
    lines_.push_back({a, color, 1}), lines_.push_back({b, color, 1});
  }
  void Triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, Rgba color) {
    triangles_.push_back({a, color, 1}), triangles_.push_back({b, color, 1});
    triangles_.push_back({c, color, 1});
  }
  // The 12 edges of the axis-aligned box [lo, hi].
  void Box(const glm::vec3& lo, const glm::vec3& hi, Rgba color);
  // A line from `from` to `to` with a head of length `head` (same units) at `to`.
  void Arrow(const glm::vec3& from, const glm::vec3& to, float head, Rgba color);
  // A small axis cross of half size `half` at p.
  void Cross(const glm::vec3& p, float half, Rgba color);
  // Screen lists: an axis-aligned rectangle from (x0, y0) to (x1, y1) [Units: px].
  void Rect(float x0, float y0, float x1, float y1, Rgba color);
  // Screen lists: text with its top-left corner at (x, y), `scale` pixels per font unit. The
  // built-in font (stb_easy_font) is ASCII, about 6 x 12 font units a character; any other
  // character (a control, a NUL, a line break, a UTF-8 code point beyond ASCII) is drawn as '?'.
  void Text(float x, float y, const std::string& text, float scale, Rgba color);
  // The width of `text` in pixels at `scale`.
  static float TextWidth(const std::string& text, float scale);

  const std::vector<DrawVertex>& points() const { return points_; }
  const std::vector<DrawVertex>& lines() const { return lines_; }
  const std::vector<DrawVertex>& triangles() const { return triangles_; }
  void Clear() { points_.clear(), lines_.clear(), triangles_.clear(); }

 private:
  std::vector<DrawVertex> points_, lines_, triangles_;
};

}  // namespace footfall::viewer
