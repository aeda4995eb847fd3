#define GL_GLEXT_PROTOTYPES 1
#include "footfall/viewer/renderer.h"

#include <GL/glcorearb.h>

#include <algorithm>
#include <cstddef>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace footfall::viewer {
namespace {

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec4 a_color;
layout(location = 2) in float a_size;
uniform mat4 u_mvp;
uniform float u_point_scale;
uniform float u_pixel_scale;
out vec4 v_color;
void main() {
  gl_Position = u_mvp * vec4(a_position, 1.0);
  v_color = a_color;
  gl_PointSize = a_size > 0.0 ? max(a_size * u_pixel_scale, 1.0)
                              : clamp(-a_size * u_point_scale / max(gl_Position.w, 1e-30), 1.0, 64.0);
}
)";

const char* kFragmentShader = R"(#version 330 core
in vec4 v_color;
out vec4 o_color;
void main() { o_color = v_color; }
)";

bool Compile(GLuint shader, const char* source, std::string* error) {
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok) return true;
  char log[1024] = {0};
  glGetShaderInfoLog(shader, sizeof log, nullptr, log);
  *error = std::string("shader compile failed: ") + log;
  return false;
}

}  // namespace

struct Renderer::Gl {
  GLuint program = 0, vao = 0, stream = 0, terrain = 0;
  GLint mvp = -1, point_scale = -1, pixel_scale = -1;
  // Sizes given in pixels (markers) times this: 1 in a view of kFullMarkerPixels and more
  // across, less in a smaller one, where full-size markers covered the scene.
  float marker_scale = 1;
  GLsizei terrain_count = 0;

  ~Gl() {
    if (stream) glDeleteBuffers(1, &stream);
    if (terrain) glDeleteBuffers(1, &terrain);
    if (vao) glDeleteVertexArrays(1, &vao);
    if (program) glDeleteProgram(program);
  }

  void Attributes(GLuint buffer) {
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, buffer);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(DrawVertex),
                          reinterpret_cast<void*>(offsetof(DrawVertex, position)));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(DrawVertex),
                          reinterpret_cast<void*>(offsetof(DrawVertex, color)));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, sizeof(DrawVertex),
                          reinterpret_cast<void*>(offsetof(DrawVertex, size)));
  }

  void Draw(GLenum mode, const std::vector<DrawVertex>& v) {
    if (v.empty()) return;
    Attributes(stream);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(DrawVertex)), v.data(),
                 GL_STREAM_DRAW);
    glDrawArrays(mode, 0, static_cast<GLsizei>(v.size()));
  }

  void Use(const glm::mat4& mvp_matrix, float scale) {
    glUseProgram(program);
    glUniformMatrix4fv(mvp, 1, GL_FALSE, glm::value_ptr(mvp_matrix));
    glUniform1f(point_scale, scale);
    glUniform1f(pixel_scale, marker_scale);
  }
};

Renderer::Renderer() = default;
Renderer::~Renderer() = default;

bool Renderer::Init(std::string* error) {
  gl_ = std::make_unique<Gl>();
  const GLuint vs = glCreateShader(GL_VERTEX_SHADER);
  const GLuint fs = glCreateShader(GL_FRAGMENT_SHADER);
  const bool compiled = Compile(vs, kVertexShader, error) && Compile(fs, kFragmentShader, error);
  if (compiled) {
    gl_->program = glCreateProgram();
    glAttachShader(gl_->program, vs);
    glAttachShader(gl_->program, fs);
    glLinkProgram(gl_->program);
  }
  glDeleteShader(vs);
  glDeleteShader(fs);
  if (!compiled) return false;
  GLint linked = 0;
  glGetProgramiv(gl_->program, GL_LINK_STATUS, &linked);
  if (!linked) {
    char log[1024] = {0};
    glGetProgramInfoLog(gl_->program, sizeof log, nullptr, log);
    *error = std::string("shader link failed: ") + log;
    return false;
  }
  gl_->mvp = glGetUniformLocation(gl_->program, "u_mvp");
  gl_->point_scale = glGetUniformLocation(gl_->program, "u_point_scale");
  gl_->pixel_scale = glGetUniformLocation(gl_->program, "u_pixel_scale");
  glGenVertexArrays(1, &gl_->vao);
  glGenBuffers(1, &gl_->stream);
  glGenBuffers(1, &gl_->terrain);
  glEnable(GL_PROGRAM_POINT_SIZE);
  return true;
}

void Renderer::SetTerrain(const std::vector<DrawVertex>& points) {
  glBindBuffer(GL_ARRAY_BUFFER, gl_->terrain);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(points.size() * sizeof(DrawVertex)),
               points.data(), GL_STATIC_DRAW);
  gl_->terrain_count = static_cast<GLsizei>(points.size());
}

void Renderer::Begin(int width, int height, Rgba background) {
  constexpr float kFullMarkerPixels = 320;
  gl_->marker_scale =
      std::min(1.0f, static_cast<float>(std::min(width, height)) / kFullMarkerPixels);
  glViewport(0, 0, width, height);
  glClearColor(background.r / 255.0f, background.g / 255.0f, background.b / 255.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
}

void Renderer::DrawTerrain(const glm::mat4& view_projection, float point_scale) {
  if (gl_->terrain_count == 0) return;
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  gl_->Use(view_projection, point_scale);
  gl_->Attributes(gl_->terrain);
  glDrawArrays(GL_POINTS, 0, gl_->terrain_count);
}

void Renderer::DrawScene(const DrawList& list, const glm::mat4& view_projection, float point_scale,
                         bool depth_test) {
  if (depth_test) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
  } else {
    glDisable(GL_DEPTH_TEST);
  }
  gl_->Use(view_projection, point_scale);
  gl_->Draw(GL_TRIANGLES, list.triangles());
  gl_->Draw(GL_LINES, list.lines());
  gl_->Draw(GL_POINTS, list.points());
}

void Renderer::DrawScreen(const DrawList& list, int width, int height) {
  glDisable(GL_DEPTH_TEST);
  const glm::mat4 pixels =
      glm::ortho(0.0f, static_cast<float>(width), static_cast<float>(height), 0.0f, -1.0f, 1.0f);
  gl_->Use(pixels, 1);
  gl_->Draw(GL_TRIANGLES, list.triangles());
  gl_->Draw(GL_LINES, list.lines());
  gl_->Draw(GL_POINTS, list.points());
}

void MaxImageSize(bool offscreen, int* width, int* height, std::string* source) {
  GLint viewport[2] = {0, 0}, renderbuffer = 0;
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, viewport);
  *width = viewport[0], *height = viewport[1];
  *source =
      "GL_MAX_VIEWPORT_DIMS " + std::to_string(viewport[0]) + "x" + std::to_string(viewport[1]);
  if (offscreen) {
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &renderbuffer);
    *width = std::min(*width, static_cast<int>(renderbuffer));
    *height = std::min(*height, static_cast<int>(renderbuffer));
    *source = "GL_MAX_RENDERBUFFER_SIZE " + std::to_string(renderbuffer) + ", " + *source;
  }
}

OffscreenTarget::OffscreenTarget() = default;

OffscreenTarget::~OffscreenTarget() {
  if (depth_) glDeleteRenderbuffers(1, &depth_);
  if (color_) glDeleteRenderbuffers(1, &color_);
  if (framebuffer_) glDeleteFramebuffers(1, &framebuffer_);
}

bool OffscreenTarget::Create(int width, int height, std::string* error) {
  width_ = width, height_ = height;
  while (glGetError() != GL_NO_ERROR) {
  }
  glGenFramebuffers(1, &framebuffer_);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
  glGenRenderbuffers(1, &color_);
  glBindRenderbuffer(GL_RENDERBUFFER, color_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
  glGenRenderbuffers(1, &depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  // (Out of memory, the framebuffer was "incomplete (status 36054)".)
  if (glGetError() == GL_OUT_OF_MEMORY) {
    *error = "the OpenGL has not the memory for a " + std::to_string(width) + "x" +
             std::to_string(height) + " image";
    return false;
  }
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    *error = "the OpenGL could not make a " + std::to_string(width) + "x" + std::to_string(height) +
             " offscreen image (framebuffer status " + std::to_string(status) +
             (status == GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT ? ", an incomplete attachment: "
                                                               "out of memory?)"
                                                             : ")");
    return false;
  }
  return true;
}

void OffscreenTarget::Read(std::vector<uint8_t>* rgba) const {
  // Read bottom row first, then turned over in place (no second copy of a large image).
  const size_t row = static_cast<size_t>(width_) * 4;
  rgba->resize(row * static_cast<size_t>(height_));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, rgba->data());
  for (size_t top = 0, bottom = static_cast<size_t>(height_); top + 1 < bottom; ++top) {
    --bottom;
    std::swap_ranges(rgba->begin() + static_cast<std::ptrdiff_t>(top * row),
                     rgba->begin() + static_cast<std::ptrdiff_t>((top + 1) * row),
                     rgba->begin() + static_cast<std::ptrdiff_t>(bottom * row));
  }
}

}  // namespace footfall::viewer
