#include "footfall/viewer/draw_list.h"

#include <stb/stb_easy_font.h>

#include <cmath>

namespace footfall::viewer {

void DrawList::Box(const glm::vec3& lo, const glm::vec3& hi, Rgba color) {
  const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z},
                          {lo.x, hi.y, lo.z}, {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z},
                          {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  static const int kEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                    {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  for (const auto& e : kEdges) Line(c[e[0]], c[e[1]], color);
}

void DrawList::Arrow(const glm::vec3& from, const glm::vec3& to, float head, Rgba color) {
  Line(from, to, color);
  const glm::vec3 d = to - from;
  const float len = glm::length(d);
  if (len <= 0) return;
  const glm::vec3 dir = d / len;
  glm::vec3 side = glm::cross(dir, glm::vec3(0, 1, 0));
  if (glm::length(side) < 1e-3f) side = glm::cross(dir, glm::vec3(1, 0, 0));
  side = glm::normalize(side);
  const glm::vec3 up = glm::cross(side, dir);
  const glm::vec3 base = to - dir * head;
  Line(to, base + side * head * 0.5f, color);
  Line(to, base - side * head * 0.5f, color);
  Line(to, base + up * head * 0.5f, color);
  Line(to, base - up * head * 0.5f, color);
}

void DrawList::Cross(const glm::vec3& p, float half, Rgba color) {
  Line(p - glm::vec3(half, 0, 0), p + glm::vec3(half, 0, 0), color);
  Line(p - glm::vec3(0, half, 0), p + glm::vec3(0, half, 0), color);
  Line(p - glm::vec3(0, 0, half), p + glm::vec3(0, 0, half), color);
}

void DrawList::Rect(float x0, float y0, float x1, float y1, Rgba color) {
  Triangle({x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, color);
  Triangle({x0, y0, 0}, {x1, y1, 0}, {x0, y1, 0}, color);
}

namespace {

// `text` as stb_easy_font can draw it: printable ASCII as it is, any other character (a
// control, a NUL, or a code point beyond ASCII in UTF-8) as one '?'. The font looks bytes up in
// a table of printable ASCII (other bytes read outside it) and stops at a NUL.
std::string EasyFontText(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    const bool continues =
        (c & 0xC0) == 0x80 && i > 0 && static_cast<unsigned char>(text[i - 1]) >= 0x80;
    if (c >= 32 && c < 127) {
      out += static_cast<char>(c);
    } else if (!continues) {
      out += '?';
    }
  }
  return out;
}

}  // namespace

void DrawList::Text(float x, float y, const std::string& text, float scale, Rgba color) {
  // stb_easy_font emits quads of 4 vertices, 16 bytes each (x, y, z floats and a colour).
  struct QuadVertex {
    float x, y, z;
    unsigned char c[4];
  };
  std::string copy = EasyFontText(text);
  std::vector<QuadVertex> buffer(copy.size() * 70 + 64);
  unsigned char rgba[4] = {color.r, color.g, color.b, color.a};
  const int quads = stb_easy_font_print(0, 0, copy.data(), rgba, buffer.data(),
                                        static_cast<int>(buffer.size() * sizeof(QuadVertex)));
  for (int q = 0; q < quads; ++q) {
    const QuadVertex* v = &buffer[static_cast<size_t>(q) * 4];
    glm::vec3 p[4];
    for (int i = 0; i < 4; ++i) p[i] = {x + v[i].x * scale, y + v[i].y * scale, 0};
    Triangle(p[0], p[1], p[2], color);
    Triangle(p[0], p[2], p[3], color);
  }
}

float DrawList::TextWidth(const std::string& text, float scale) {
  std::string copy = EasyFontText(text);
  return static_cast<float>(stb_easy_font_width(copy.data())) * scale;
}

}  // namespace footfall::viewer
