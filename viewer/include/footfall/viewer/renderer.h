// Renderer: draws DrawLists with OpenGL 3.3 core. The only GL code of footfall besides the
// window in viewer_app.cpp. Every call needs the context it was initialised in to be current.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "footfall/viewer/draw_list.h"

namespace footfall::viewer {

class Renderer {
 public:
  Renderer();
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Compiles the shaders and creates the buffers. False with a message on failure.
  bool Init(std::string* error);

  // Keeps `points` (render space) in a static buffer drawn by DrawTerrain.
  void SetTerrain(const std::vector<DrawVertex>& points);

  // Clears the bound framebuffer's width x height viewport to `background`. Sizes given in
  // pixels (markers) are drawn smaller in a view under 320 pixels across, in proportion.
  void Begin(int width, int height, Rgba background);
  // Draws the static terrain points, depth tested.
  void DrawTerrain(const glm::mat4& view_projection, float point_scale);
  // Draws a render-space list. `point_scale` turns world point sizes into pixels (pixels per
  // world unit at clip w = 1). Depth-tested lists hide behind the terrain; others draw on top.
  void DrawScene(const DrawList& list, const glm::mat4& view_projection, float point_scale,
                 bool depth_test);
  // Draws a pixel-space list on top of everything.
  void DrawScreen(const DrawList& list, int width, int height);

 private:
  struct Gl;
  std::unique_ptr<Gl> gl_;
};

// The largest image the current context draws into whole [Units: px]: GL_MAX_VIEWPORT_DIMS,
// and for an offscreen target GL_MAX_RENDERBUFFER_SIZE too. *source names the limits and
// their values, for messages.
void MaxImageSize(bool offscreen, int* width, int* height, std::string* source);

// A framebuffer object of fixed size to render into without a visible window.
class OffscreenTarget {
 public:
  OffscreenTarget();
  ~OffscreenTarget();
  OffscreenTarget(const OffscreenTarget&) = delete;
  OffscreenTarget& operator=(const OffscreenTarget&) = delete;

  // Creates an RGBA8 colour and 24-bit depth target of width x height (within MaxImageSize)
  // and binds it. False with a message when the GL cannot (out of memory).
  bool Create(int width, int height, std::string* error);
  // Reads the pixels back as RGBA rows, top row first. Throws std::bad_alloc.
  void Read(std::vector<uint8_t>* rgba) const;

 private:
  unsigned framebuffer_ = 0, color_ = 0, depth_ = 0;
  int width_ = 0, height_ = 0;
};

}  // namespace footfall::viewer
