// footfall-view's window, input and frame loop (GLFW), headless screenshots and live mode.
#define GLFW_INCLUDE_NONE
#include "footfall/viewer/viewer_app.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <fstream>
#include <iostream>
#include <mutex>
#include <new>
#include <thread>

#include "footfall/client/recent_queries.h"
#include "footfall/steps/walk_json.h"
#include "footfall/terrain/ascii.h"
#include "footfall/terrain/output_file.h"
#include "footfall/terrain/text_stream.h"
#include "footfall/viewer/png_writer.h"
#include "footfall/viewer/renderer.h"
#include "footfall/viewer/scene.h"
#include "footfall/viewer/walk_pose.h"

namespace footfall::viewer {
namespace {

using Clock = std::chrono::steady_clock;

int Fail(const std::string& message, int code = 1) {
  std::cerr << "footfall-view: " << message << '\n';
  return code;
}

std::string g_glfw_error;  // the last GLFW error, for messages

void OnGlfwError(int, const char* description) { g_glfw_error = description ? description : ""; }

// `text` as lines no wider than `max_width` pixels at `scale`: its items (parts between
// `separator`s) joined while they fit; an item wider than a line is broken at its spaces, and
// a word wider than a line between its characters (one a line, at least, in a window narrower
// than a character). Line breaks and tabs count as spaces.
std::vector<std::string> WrapText(std::string text, const std::string& separator, float scale,
                                  float max_width) {
  for (char& c : text) {
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  }
  max_width = std::max(max_width, DrawList::TextWidth("W", scale));
  auto fits = [&](const std::string& s) { return DrawList::TextWidth(s, scale) <= max_width; };
  std::vector<std::string> lines;
  std::string line;
  for (size_t begin = 0; begin < text.size();) {
    size_t end = text.find(separator, begin);
    if (end == std::string::npos) end = text.size();
    std::string item = text.substr(begin, end - begin);
    begin = end + separator.size();
    if (item.empty()) continue;
    const std::string joined = line.empty() ? item : line + separator + item;
    if (fits(joined)) {
      line = joined;
      continue;
    }
    if (!line.empty()) lines.push_back(line);
    line.clear();
    if (separator != " " && !fits(item)) {
      std::vector<std::string> words = WrapText(item, " ", scale, max_width);
      line = words.back();
      words.pop_back();
      lines.insert(lines.end(), words.begin(), words.end());
      continue;
    }
    while (!item.empty() && !fits(item)) {
      size_t n = 1;
      while (n < item.size() && fits(item.substr(0, n + 1))) ++n;
      // (Not inside a UTF-8 sequence: its bytes are one character.)
      while (n < item.size() && (static_cast<unsigned char>(item[n]) & 0xC0) == 0x80) ++n;
      lines.push_back(item.substr(0, n));
      item.erase(0, n);
    }
    line = item;
  }
  if (!line.empty() || lines.empty()) lines.push_back(line);
  return lines;
}

// Polls footfalld on its own thread so a slow or vanished server never stalls drawing.
class LiveFollower {
 public:
  explicit LiveFollower(const RpcOptions& options) : feed_(options) {}
  ~LiveFollower() { Stop(); }

  // Connects and skips past queries; false (see error()) when the server cannot be reached.
  bool Start() {
    if (feed_.Start() != Status::kOk) {
      error_ = feed_.last_error();
      return false;
    }
    start_after_ = feed_.after();
    thread_ = std::thread([this] { Run(); });
    return true;
  }

  void Stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

  // Moves the queries received since the last call into *out.
  void Take(std::vector<RecentQuery>* out) {
    std::lock_guard<std::mutex> lock(mutex_);
    out->insert(out->end(), pending_.begin(), pending_.end());
    pending_.clear();
  }

  std::string status() {
    std::lock_guard<std::mutex> lock(mutex_);
    return status_;
  }
  const std::string& error() const { return error_; }
  uint64_t start_after() const { return start_after_; }
  std::string Address() const { return feed_.Address(); }

 private:
  void Run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
      lock.unlock();
      std::vector<RecentQuery> got;
      const Status s = feed_.Poll(&got);
      lock.lock();
      pending_.insert(pending_.end(), got.begin(), got.end());
      status_ = s == Status::kOk ? "connected" : "disconnected: " + feed_.last_error();
      wake_.wait_for(lock, std::chrono::milliseconds(s == Status::kOk ? 100 : 500),
                     [this] { return stop_; });
    }
  }

  RecentQueryFeed feed_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::vector<RecentQuery> pending_;
  std::string status_ = "connected";
  std::string error_;
  uint64_t start_after_ = 0;
};

struct App {
  const ViewerOptions& options;
  Scene scene;
  ViewState view;
  OrbitCamera camera;
  std::unique_ptr<Renderer> renderer;  // lives while the GL context does
  std::unique_ptr<LiveFollower> live;
  GLFWwindow* window = nullptr;
  bool playing = false;
  bool terrain_dirty = true;
  // The overlay's lines of text as last drawn (pixels: top-left corner and width).
  struct HudLine {
    std::string text;
    float x, y, width;
  };
  std::vector<HudLine> hud_lines;
  // How far the overlay's bands reach into the window from its top and from its bottom, as
  // last laid out. [Units: px]
  float hud_top = 0, hud_bottom = 0;
  int frame_width = 1, frame_height = 1;  // the viewport last framed for [Units: px]
  bool follow_live = false;               // frame the live queries as they arrive
  // Mouse drag state.
  bool rotating = false, panning = false;
  double last_x = 0, last_y = 0;

  explicit App(const ViewerOptions& o) : options(o) {}

  // Frames everything drawn in a width x height viewport, clear of the overlay's bands.
  void FrameAll(int width, int height) {
    width = std::max(width, 1), height = std::max(height, 1);
    DrawList layout;
    DrawOverlay(width, height, &layout);  // measures the bands
    glm::dvec3 lo, hi;
    scene.FrameBounds(view, &lo, &hi);
    camera.Frame(lo, hi, scene.MinFrameRadius(), static_cast<double>(width) / height,
                 (hud_top + 4) / height, (hud_bottom + 4) / height);
  }

  // Frames the walk's keys alone, or everything when the walk has none.
  void FrameWalk(int width, int height) {
    width = std::max(width, 1), height = std::max(height, 1);
    glm::dvec3 lo, hi;
    if (!scene.WalkFrameBounds(&lo, &hi)) {
      FrameAll(width, height);
      return;
    }
    DrawList layout;
    DrawOverlay(width, height, &layout);  // measures the bands
    camera.Frame(lo, hi, scene.MinFrameRadius(), static_cast<double>(width) / height,
                 (hud_top + 4) / height, (hud_bottom + 4) / height);
  }

  // Frames everything (the walk with --frame-walk), or looks as --camera says.
  void PlaceCamera(int width, int height) {
    frame_width = width, frame_height = height;
    // With nothing loaded, the live queries are the scene: framed as they arrive, until the
    // camera is moved.
    follow_live = live && !scene.has_loaded() && !options.has_camera;
    if (options.frame_walk)
      FrameWalk(width, height);
    else
      FrameAll(width, height);
    if (options.has_camera)
      camera.LookAt(scene.ToRenderDouble(options.eye), scene.ToRenderDouble(options.target));
  }

  void SetFrame(double frame) {
    view.frame = std::clamp(frame, scene.first_frame(), scene.last_frame());
  }

  std::string HelpText() const {
    TextStream s;
    s << "drag: orbit   right-drag: pan   wheel: zoom   F: frame all   C: colour ("
      << (view.color == ColorMode::kNormal ? "normal" : "height") << ")   G: cells ("
      << (view.show_cells ? "on" : "off") << ")";
    if (scene.has_walk())
      s << "   W: frame walk   space: play   left/right: frame   Home/End: first/last";
    s << "   Esc: quit";
    return s.str();
  }

  std::string InfoText() {
    TextStream s;
    if (scene.has_terrain())
      s << "terrain " << options.terrain << " (" << scene.grid().size() << " samples)   ";
    if (!scene.queries().empty()) s << "queries " << scene.queries().size() << "   ";
    if (live) {
      s << "live " << live->Address() << ": " << scene.live_received() << " received ("
        << live->status() << ")   ";
    }
    if (scene.has_walk()) s << "walk " << options.walk;
    return s.str();
  }

  // Draws one frame into the bound framebuffer.
  void Render(int width, int height) {
    if (terrain_dirty) {
      renderer->SetTerrain(scene.TerrainPoints(view.color));
      terrain_dirty = false;
    }
    // The camera in double (its target may lie 1e15 away), the product in float for GL.
    const double aspect = static_cast<double>(width) / static_cast<double>(std::max(height, 1));
    const glm::dmat4 projection = camera.Projection(aspect, scene.DrawnBoxes());
    const glm::mat4 view_projection(projection * camera.View());
    const float point_scale = static_cast<float>(height * projection[1][1] * 0.5);
    renderer->Begin(width, height, colors::kBackground);
    renderer->DrawTerrain(view_projection, point_scale);
    DrawList depth_tested, on_top, screen;
    scene.Draw(view, &depth_tested, &on_top);
    renderer->DrawScene(depth_tested, view_projection, point_scale, true);
    renderer->DrawScene(on_top, view_projection, point_scale, false);
    DrawOverlay(width, height, &screen);
    renderer->DrawScreen(screen, width, height);
  }

  void DrawOverlay(int width, int height, DrawList* screen) {
    hud_lines.clear();
    const float scale = width >= 900 ? 1.5f : 1.0f;
    const float line = 12 * scale;
    const Rgba text{230, 230, 230, 255};
    // Every line of text is wrapped to the window, 6 px from its edges, and recorded.
    const float max_width = static_cast<float>(width) - 12;
    auto draw_lines = [&](float x, float top, const std::vector<std::string>& lines) {
      for (size_t i = 0; i < lines.size(); ++i) {
        const float y = top + static_cast<float>(i) * line;
        screen->Text(x, y, lines[i], scale, text);
        hud_lines.push_back({lines[i], x, y, DrawList::TextWidth(lines[i], scale)});
      }
    };
    std::vector<std::string> info = WrapText(InfoText(), "   ", scale, max_width);
    // The help line, wrapped at its item separators.
    std::vector<std::string> lines = WrapText(HelpText(), "   ", scale, max_width);
    // A window too small for every line keeps the scene in view: the help is left out, and
    // each band keeps what fits in a quarter of the height (at 300 x 80 the bands met, and no
    // terrain was drawn).
    const size_t quarter = static_cast<size_t>(std::max(0.0f, 0.25f * height - 10) / line);
    // The walk's frame line, and why it stopped, in full: wrapped over as many lines as it
    // takes, counted with the others (a stopped walk's lines covered the scene in windows just
    // too large for the bands' limit, counted without them).
    constexpr float kTimelineX = 10, kTimelineHeight = 20;
    std::vector<std::string> frame_lines;
    if (scene.has_walk()) {
      TextStream f;
      f << "frame " << FrameText(view.frame) << " of " << FrameText(scene.first_frame()) << " to "
        << FrameText(scene.last_frame()) << " at " << scene.walk().fps << " fps"
        << (playing ? "  (playing)" : "");
      if (!scene.walk().stopped.empty()) f << "   stopped: " << scene.walk().stopped;
      frame_lines = WrapText(f.str(), "   ", scale, static_cast<float>(width) - 2 * kTimelineX);
    }
    const bool tight = static_cast<float>(info.size() + lines.size() + frame_lines.size()) * line +
                           20 + (scene.has_walk() ? kTimelineHeight : 0) >
                       0.5f * height;
    if (tight) {
      lines.clear();
      info.resize(std::min(info.size(), quarter));
    }
    hud_top = info.empty() ? 0 : static_cast<float>(info.size()) * line + 6;
    if (hud_top > 0) screen->Rect(0, 0, static_cast<float>(width), hud_top, Rgba{0, 0, 0, 140});
    draw_lines(6, 4, info);
    float top = static_cast<float>(height);
    if (!lines.empty()) {
      top -= static_cast<float>(lines.size()) * line + 6;
      screen->Rect(0, top - 4, static_cast<float>(width), static_cast<float>(height),
                   Rgba{0, 0, 0, 140});
      draw_lines(6, top, lines);
    }
    hud_bottom = lines.empty() ? 0 : static_cast<float>(height) - (top - 4);
    if (scene.has_walk() && (!tight || quarter > 0)) {
      // The timeline: a bar over the walk's frames with a marker at the current frame.
      const float bar_y = top - 14;
      const float x0 = kTimelineX, x1 = static_cast<float>(width) - kTimelineX;
      screen->Rect(x0, bar_y, x1, bar_y + 6, Rgba{90, 90, 100, 220});
      const double span = std::max(scene.last_frame() - scene.first_frame(), 1e-9);
      const float t = static_cast<float>((view.frame - scene.first_frame()) / span);
      const float mx = x0 + (x1 - x0) * std::clamp(t, 0.0f, 1.0f);
      screen->Rect(mx - 3, bar_y - 5, mx + 3, bar_y + 11, Rgba{255, 255, 255, 255});
      if (tight) frame_lines.resize(std::min(frame_lines.size(), quarter));
      const float frame_top = bar_y - static_cast<float>(frame_lines.size()) * line - 6;
      draw_lines(x0, frame_top, frame_lines);
      hud_bottom = static_cast<float>(height) - frame_top;
    }
  }

  void PullLive() {
    if (!live) return;
    std::vector<RecentQuery> got;
    live->Take(&got);
    if (got.empty()) return;
    const size_t other_before = scene.live_other_terrain();
    // The camera stays where it is in the world if the first live query moves render space's
    // origin (nothing loaded): a --camera given moved with it, by the query's coordinates.
    const Vec3 origin = scene.ToWorld(glm::dvec3(0));
    const Vec3 eye = scene.ToWorld(camera.eye()), target = scene.ToWorld(camera.target());
    scene.AddLive(got);
    if (scene.ToWorld(glm::dvec3(0)) != origin)
      camera.LookAt(scene.ToRenderDouble(eye), scene.ToRenderDouble(target));
    if (other_before == 0 && scene.live_other_terrain() > 0)
      std::cerr << "footfall-view: note: live queries answered otherwise than " << options.terrain
                << " answers them were asked on another terrain of the server: drawn with the "
                   "server's answer alone, without cells and candidates\n";
    // (The camera framed the unit box before any query came: a blank picture.)
    if (follow_live) FrameAll(frame_width, frame_height);
  }

  bool WriteDump(int width, int height) {
    if (options.dump_state.empty()) return true;
    Scene::LiveSource source;
    if (live) source.address = live->Address(), source.after = live->start_after();
    JsonText j;
    j.BeginObject();
    scene.Describe(view, camera, width, height, live ? &source : nullptr, &j);
    j.Key("hud").BeginArray();
    for (const HudLine& l : hud_lines) {
      j.BeginObject();
      j.Key("text").Value(l.text);
      j.Key("x").Value(l.x);
      j.Key("y").Value(l.y);
      j.Key("width").Value(l.width);
      j.End();
    }
    j.End();
    j.End();
    std::string message;
    if (ReplaceFile(options.dump_state, j.text() + '\n', &message) != Status::kOk) {
      Fail(options.dump_state + ": cannot write the state dump: " + message);
      return false;
    }
    return true;
  }

  static App* From(GLFWwindow* w) { return static_cast<App*>(glfwGetWindowUserPointer(w)); }

  static void OnKey(GLFWwindow* w, int key, int, int action, int) {
    if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
    App* app = From(w);
    switch (key) {
      case GLFW_KEY_ESCAPE:
      case GLFW_KEY_Q:
        glfwSetWindowShouldClose(w, GLFW_TRUE);
        break;
      case GLFW_KEY_F:    // frame all
      case GLFW_KEY_W: {  // frame the walk
        int width = 0, height = 0;
        glfwGetFramebufferSize(w, &width, &height);
        app->frame_width = width, app->frame_height = height;
        if (key == GLFW_KEY_W)
          app->FrameWalk(width, height);
        else
          app->FrameAll(width, height);
        break;
      }
      case GLFW_KEY_C:
        app->view.color =
            app->view.color == ColorMode::kNormal ? ColorMode::kHeight : ColorMode::kNormal;
        app->terrain_dirty = true;
        break;
      case GLFW_KEY_G:
        app->view.show_cells = !app->view.show_cells;
        break;
      case GLFW_KEY_SPACE:
        app->playing = !app->playing;
        break;
      case GLFW_KEY_RIGHT:
        app->playing = false;
        app->SetFrame(std::floor(app->view.frame) + 1);
        break;
      case GLFW_KEY_LEFT:
        app->playing = false;
        app->SetFrame(std::ceil(app->view.frame) - 1);
        break;
      case GLFW_KEY_HOME:
        app->SetFrame(app->scene.first_frame());
        break;
      case GLFW_KEY_END:
        app->SetFrame(app->scene.last_frame());
        break;
      default:
        break;
    }
  }

  static void OnButton(GLFWwindow* w, int button, int action, int) {
    App* app = From(w);
    glfwGetCursorPos(w, &app->last_x, &app->last_y);
    if (action == GLFW_PRESS) app->follow_live = false;  // the user takes the camera
    if (button == GLFW_MOUSE_BUTTON_LEFT) app->rotating = action == GLFW_PRESS;
    if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE)
      app->panning = action == GLFW_PRESS;
  }

  static void OnCursor(GLFWwindow* w, double x, double y) {
    App* app = From(w);
    const float dx = static_cast<float>(x - app->last_x);
    const float dy = static_cast<float>(y - app->last_y);
    app->last_x = x, app->last_y = y;
    int width = 1, height = 1;
    glfwGetWindowSize(w, &width, &height);
    if (app->rotating) app->camera.Orbit(-dx * 0.01f, dy * 0.01f);
    if (app->panning)
      app->camera.Pan(dx / static_cast<float>(std::max(height, 1)),
                      dy / static_cast<float>(std::max(height, 1)));
  }

  static void OnScroll(GLFWwindow* w, double, double dy) {
    From(w)->follow_live = false;
    From(w)->camera.Zoom(std::pow(0.9f, static_cast<float>(dy)));
  }

  int Interactive() {
    glfwSetWindowUserPointer(window, this);
    glfwSetKeyCallback(window, OnKey);
    glfwSetMouseButtonCallback(window, OnButton);
    glfwSetCursorPosCallback(window, OnCursor);
    glfwSetScrollCallback(window, OnScroll);
    glfwSwapInterval(1);
    Clock::time_point last = Clock::now();
    while (!glfwWindowShouldClose(window)) {
      glfwPollEvents();
      const Clock::time_point now = Clock::now();
      const double dt = std::chrono::duration<double>(now - last).count();
      last = now;
      if (playing && scene.has_walk()) {
        double f = view.frame + dt * scene.walk().fps;
        if (f > scene.last_frame()) f = scene.first_frame();  // loop
        view.frame = f;
      }
      PullLive();
      int width = 0, height = 0;
      glfwGetFramebufferSize(window, &width, &height);
      if (width > 0 && height > 0) Render(width, height);
      glfwSwapBuffers(window);
    }
    int width = 0, height = 0;
    glfwGetFramebufferSize(window, &width, &height);
    return WriteDump(width, height) ? 0 : 1;
  }

  std::string SizeText() const {
    return std::to_string(options.width) + "x" + std::to_string(options.height);
  }

  int Screenshot() {
    std::string error;
    OffscreenTarget target;
    if (!target.Create(options.width, options.height, &error))
      return Fail("--size " + SizeText() + ": " + error + "; try a smaller --size");
    if (live && options.live_wait > 0) {
      const Clock::time_point deadline =
          Clock::now() + std::chrono::duration_cast<Clock::duration>(
                             std::chrono::duration<double>(options.timeout_s));
      while (scene.live_received() < static_cast<size_t>(options.live_wait)) {
        if (Clock::now() >= deadline) {
          return Fail("live: received " + std::to_string(scene.live_received()) + " of " +
                      std::to_string(options.live_wait) + " queries from " + live->Address() +
                      " within " + std::to_string(options.timeout_s) + " s (" + live->status() +
                      ")");
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        PullLive();
      }
    }
    PullLive();
    // The queries waited for are in the picture: framed with the rest, as F frames them (the
    // camera framed the terrain alone: a query beside it, or on another terrain of the
    // server, was left out), unless --camera places it.
    if (live && options.live_wait > 0 && !options.has_camera)
      FrameAll(options.width, options.height);
    Render(options.width, options.height);
    // The screenshot and the state dump replace their files together, once both are written:
    // a dump that failed left a new picture beside the old dump.
    OutputFileSet outputs;
    try {
      std::vector<uint8_t> rgba;
      target.Read(&rgba);
      if (!WritePng(options.screenshot, options.width, options.height, rgba, &error))
        return Fail(error);
    } catch (const std::bad_alloc&) {
      // (It ended in "footfall-view: std::bad_alloc".)
      const double mib = static_cast<double>(options.width) * options.height * 7 / (1 << 20);
      return Fail("--size " + SizeText() + ": not enough memory to read back and encode the " +
                  "image (about " + std::to_string(static_cast<long long>(mib)) +
                  " MiB); try a smaller --size");
    }
    if (!WriteDump(options.width, options.height)) return 1;
    int code = 0;
    for (const std::string& failure : outputs.Commit()) code = Fail(failure);
    return code;
  }
};

}  // namespace

int RunViewer(const ViewerOptions& options) {
  // 1. Check the options and parse every query before opening anything.
  if (options.terrain.empty() && options.walk.empty() && !options.live)
    return Fail("nothing to show: give --terrain FILE, --walk FILE or --server HOST:PORT --live",
                2);
  if (options.live && options.server.empty()) return Fail("--live needs --server HOST:PORT", 2);
  if (!options.server.empty() && !options.live)
    return Fail("--server is used only with --live (the viewer follows a server's queries)", 2);
  if (!options.queries.empty() && options.terrain.empty())
    return Fail("--query needs --terrain FILE (queries run on the local terrain)", 2);
  if (options.live_wait > 0 && options.screenshot.empty())
    return Fail("--live-wait is for --screenshot", 2);
  if (options.has_frame && options.walk.empty())
    return Fail("--frame needs --walk FILE (it picks the frame of the walk to show)", 2);
  // What the viewer writes never replaces what it reads, nor each other.
  const std::pair<const char*, const std::string*> outputs[] = {
      {"--screenshot", &options.screenshot}, {"--dump-state", &options.dump_state}};
  const std::pair<const char*, const std::string*> inputs[] = {{"--terrain", &options.terrain},
                                                               {"--walk", &options.walk}};
  for (const auto& [flag, path] : outputs) {
    if (path->empty()) continue;
    for (const auto& [in_flag, in_path] : inputs)
      if (!in_path->empty() && SameFile(*path, *in_path))
        return Fail(std::string(flag) + " " + *path + " is the " + in_flag +
                        " file; choose another output name",
                    2);
  }
  if (!options.screenshot.empty() && !options.dump_state.empty() &&
      SameFile(options.screenshot, options.dump_state))
    return Fail("--screenshot and --dump-state name the same file; give each its own", 2);
  // A screenshot is a PNG: a name with another extension (shot.jpg) would hold PNG bytes.
  const std::string shot_name = options.screenshot.substr(options.screenshot.rfind('/') + 1);
  const size_t dot = shot_name.rfind('.');
  if (dot != std::string::npos && dot > 0) {
    std::string extension = shot_name.substr(dot);
    for (char& c : extension) c = AsciiLower(c);
    if (extension != ".png")
      return Fail("--screenshot " + options.screenshot +
                      ": expected a .png file name (the screenshot is written as PNG)",
                  2);
  }
  if (options.width <= 0 || options.height <= 0 || options.width > 65536 || options.height > 65536)
    return Fail("--size: width and height must be within 1..65536", 2);
  if (options.has_camera) {
    // (A target 2e19 away put the camera at NaN: a blank image and exit 0.)
    for (const Vec3& p : {options.eye, options.target}) {
      if (!(std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) <= kMaxKeyCoordinate))
        return Fail(
            "--camera: expected the eye and the target within +-1e15 (nothing farther "
            "can be drawn)",
            2);
    }
  }
  std::vector<QuerySpec> specs;
  for (const std::string& text : options.queries) {
    QuerySpec spec;
    std::string error;
    // The syntax of `footfall query`, '#' comments included: one line (a line break was taken
    // for a space, and "snap 1 1 1\nsnap 2 2 2" was "expected 3 numbers, found 7").
    if (text.find_first_of("\r\n") != std::string::npos)
      return Fail(
          "--query: expected one query per --query, on one line (this one holds a line "
          "break)",
          2);
    const std::string query = WithoutComment(text);
    if (query.find_first_not_of(" \t\r\v\f") == std::string::npos)
      return Fail(
          "--query \"" + text + "\": expected snap X Y Z, normal X Y Z or next X Y Z DX DY DZ", 2);
    if (!ParseQueryText(query, &spec, &error)) return Fail("--query \"" + text + "\": " + error, 2);
    // (Drawn, a point 1e300 away put the camera at NaN and gave a blank image.)
    const Vec3& p = spec.point;
    if (!(std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) <= kMaxKeyCoordinate))
      return Fail("--query \"" + text +
                      "\": expected a point within +-1e15 (nothing farther "
                      "can be drawn)",
                  2);
    spec.tolerance = options.tolerance;
    specs.push_back(spec);
  }
  RpcOptions rpc;
  if (options.live) {
    std::string error;
    if (ParseHostPort(options.server, &rpc, &error) != Status::kOk)
      return Fail("--server: " + error, 2);
    rpc.connect_timeout_s = std::min(2.0, options.timeout_s);
    rpc.call_timeout_s = std::min(5.0, options.timeout_s);
  }

  // Both outputs writable before anything is drawn or written: a --dump-state in a missing
  // directory failed after the screenshot had replaced the file at its path.
  for (const auto& [flag, path] : outputs) {
    std::string error;
    if (!path->empty() && CheckWritable(*path, &error) != Status::kOk)
      return Fail(std::string(flag) + ": " + error);
  }

  // 2. Load the terrain, answer the queries, read the walk.
  App app(options);
  std::string error;
  if (!options.terrain.empty() &&
      app.scene.LoadTerrain(options.terrain, options.load, &error) != Status::kOk)
    return Fail(error);
  for (size_t i = 0; i < specs.size(); ++i) {
    if (app.scene.AddQuery(specs[i], &error) != Status::kOk) return Fail(error);
    // A query the engine refuses (a step of 1e200) has nothing to draw: its ideal point put
    // the camera at NaN and gave a blank image.
    if (app.scene.queries().back().result.status == Status::kInvalidArgument)
      return Fail("--query \"" + options.queries[i] + "\": " + QueryOpName(specs[i].op) + ": " +
                      InvalidQueryReason(specs[i].op),
                  2);
  }
  if (!options.walk.empty() && app.scene.LoadWalk(options.walk, &error) != Status::kOk)
    return Fail(error);
  app.scene.SetSoleLength(options.sole_length);
  if (!options.walk.empty()) {
    // A walk of no keys (no tracks, or tracks without keys) draws nothing: say so rather than
    // leave an empty picture unexplained.
    bool any_key = false;
    for (const WalkTrack& track : app.scene.walk().tracks) any_key = any_key || !track.keys.empty();
    if (!any_key)
      std::cerr << "footfall-view: note: " << options.walk << " has no keys: no walk to draw\n";
  }
  {
    // A walk drawn on a terrain it was not made on floats or sinks: say so. (A foot key of a
    // walk made on this terrain is a sample; a grid cell is some 3.5 sample spacings.)
    size_t planted = 0;
    const size_t off =
        app.scene.PlantedKeysOffTerrain(app.scene.grid().stats().cell_size, &planted);
    if (off > 0 && 10 * off > planted) {
      std::cerr << "footfall-view: warning: " << off << " of " << planted
                << " planted foot keys of " << options.walk << " lie more than a grid cell ("
                << app.scene.grid().stats().cell_size << ") from every sample of "
                << options.terrain << ": the walk was made on another terrain?\n";
    }
  }
  app.scene.SetUp(options.up);
  app.scene.Finalize();
  // Told apart in world space but not in render space (about the scene's centre): a target
  // 1e-15 from an eye 5 away lay on it, and the picture was blank.
  if (options.has_camera &&
      app.scene.ToRenderDouble(options.eye) == app.scene.ToRenderDouble(options.target))
    return Fail(
        "--camera: the eye and the target are too near each other to be told apart this far "
        "from the scene's centre; move the target farther from the eye",
        2);
  // An orbit camera keeps its up: a view straight along it is tilted, and said (the eye moved
  // without a word; straight down onto a Z-up DEM is a view people ask for).
  if (options.has_camera && !OrbitCamera().LookAt(app.scene.ToRenderDouble(options.eye),
                                                  app.scene.ToRenderDouble(options.target))) {
    std::cerr << "footfall-view: note: --camera looks within a degree of straight along the up; "
                 "the eye is tilted to 89 degrees about the target (the view keeps --up up)\n";
  }
  app.view.color = options.height_colors ? ColorMode::kHeight : ColorMode::kNormal;
  app.view.show_cells = options.show_cells;
  app.SetFrame(options.has_frame ? options.frame : app.scene.first_frame());
  // (Not for a walk without keys, which is said already: its "range" was 0-0.)
  if (options.has_frame && app.scene.has_walk() && app.scene.has_walk_keys() &&
      (options.frame < app.scene.first_frame() || options.frame > app.scene.last_frame())) {
    std::cerr << "footfall-view: note: --frame " << ExactFrameText(options.frame)
              << " is outside the walk's " << ExactFrameText(app.scene.first_frame()) << " to "
              << ExactFrameText(app.scene.last_frame()) << "; showing "
              << ExactFrameText(app.view.frame) << '\n';
  }

  // 3. Open a window (hidden for screenshots) with an OpenGL 3.3 core context.
  glfwSetErrorCallback(OnGlfwError);
  if (!glfwInit()) {
    return Fail("cannot open a display: " + g_glfw_error +
                " (for headless use: xvfb-run -a footfall-view ... --screenshot out.png)");
  }
  // GL objects go before the context, the context before GLFW; not when an exception is on its
  // way out (memory ran out, maybe within the OpenGL driver, which may then hold its locks for
  // ever: glfwTerminate waited on one): the process ends, and with it the context.
  struct GlfwGuard {
    App* app;
    int unwinding = std::uncaught_exceptions();
    ~GlfwGuard() {
      if (std::uncaught_exceptions() > unwinding) return;
      app->renderer.reset();
      glfwTerminate();
    }
  } guard{&app};
  const bool headless = !options.screenshot.empty();
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, headless ? GLFW_FALSE : GLFW_TRUE);
  app.window = glfwCreateWindow(headless ? 64 : options.width, headless ? 64 : options.height,
                                "footfall-view", nullptr, nullptr);
  if (!app.window) return Fail("cannot create an OpenGL 3.3 core context: " + g_glfw_error);
  glfwMakeContextCurrent(app.window);
  app.renderer = std::make_unique<Renderer>();
  if (!app.renderer->Init(&error)) return Fail(error);
  {
    // (Beyond them, a screenshot failed as "framebuffer incomplete", and a window was drawn in
    // part.)
    int max_width = 0, max_height = 0;
    std::string limits;
    MaxImageSize(headless, &max_width, &max_height, &limits);
    if (options.width > max_width || options.height > max_height)
      return Fail("--size " + app.SizeText() + ": larger than this OpenGL draws, at most " +
                      std::to_string(max_width) + "x" + std::to_string(max_height) + " (" + limits +
                      ")",
                  2);
  }

  // 4. Follow the server, then draw.
  if (options.live) {
    app.live = std::make_unique<LiveFollower>(rpc);
    if (!app.live->Start()) return Fail(app.live->error());
    std::cout << "footfall-view: live: following footfalld at " << app.live->Address()
              << " after query " << app.live->start_after() << std::endl;
  }
  if (headless) {
    app.PlaceCamera(options.width, options.height);
  } else {
    int width = 0, height = 0;
    glfwGetFramebufferSize(app.window, &width, &height);
    app.PlaceCamera(width, height);
  }
  const int code = headless ? app.Screenshot() : app.Interactive();
  if (app.live) app.live->Stop();
  return code;
}

}  // namespace footfall::viewer
