#include "footfall/viewer/scene.h"

#include <algorithm>
#include <cmath>

#include "footfall/steps/foot_rotations.h"
#include "footfall/steps/walk_json.h"
#include "footfall/viewer/walk_pose.h"

namespace footfall::viewer {
namespace {

uint8_t Byte(double v) { return static_cast<uint8_t>(std::clamp(v, 0.0, 1.0) * 255.0 + 0.5); }

Rgba NormalColor(const Vec3& n) {
  return {Byte(n.x * 0.5 + 0.5), Byte(n.y * 0.5 + 0.5), Byte(n.z * 0.5 + 0.5), 255};
}

// A blue - teal - green - sand - white ramp over t in [0, 1].
Rgba HeightColor(double t) {
  static const double kStops[5][3] = {{0.15, 0.25, 0.65},
                                      {0.10, 0.60, 0.60},
                                      {0.30, 0.70, 0.25},
                                      {0.80, 0.70, 0.40},
                                      {0.97, 0.97, 0.97}};
  t = std::clamp(t, 0.0, 1.0) * 4;
  const int i = std::min(static_cast<int>(t), 3);
  const double f = t - i;
  return {Byte(kStops[i][0] + (kStops[i + 1][0] - kStops[i][0]) * f),
          Byte(kStops[i][1] + (kStops[i + 1][1] - kStops[i][1]) * f),
          Byte(kStops[i][2] + (kStops[i + 1][2] - kStops[i][2]) * f), 255};
}

void Grow(const Vec3& p, Vec3* lo, Vec3* hi, bool* any) {
  if (!*any) {
    *lo = *hi = p;
    *any = true;
    return;
  }
  lo->x = std::min(lo->x, p.x), lo->y = std::min(lo->y, p.y), lo->z = std::min(lo->z, p.z);
  hi->x = std::max(hi->x, p.x), hi->y = std::max(hi->y, p.y), hi->z = std::max(hi->z, p.z);
}

// The radius of the ring drawn around a next query's ideal point. [Units: wu]
double RingRadius(const QueryView& q) {
  return q.trace.radius > 0     ? q.trace.radius
         : q.spec.tolerance > 0 ? q.spec.tolerance
                                : Length(q.spec.direction);
}

}  // namespace

void Scene::QueryBounds(const QueryView& q, Vec3* lo, Vec3* hi) const {
  bool any = false;
  Grow(q.spec.point, lo, hi, &any);
  if (q.spec.op == QueryOp::kNext) {
    const Vec3 ideal = q.spec.point + q.spec.direction;
    const double r = RingRadius(q);
    // The ring, and the arrow's head (as long as DrawQuery draws it, spread to half that).
    const double head = std::max(Length(q.spec.direction) * 0.15, spacing_);
    for (const double d : {r, head}) {
      Grow(ideal - Vec3{d, d, d}, lo, hi, &any);
      Grow(ideal + Vec3{d, d, d}, lo, hi, &any);
    }
  }
  if (q.traced) {
    for (const uint32_t cell : q.trace.cells) {
      Vec3 cell_lo, cell_hi;
      grid_.CellBox(cell, &cell_lo, &cell_hi);
      Grow(cell_lo, lo, hi, &any);
      Grow(cell_hi, lo, hi, &any);
    }
  }
  if (q.result.status == Status::kOk) Grow(q.result.point, lo, hi, &any);
}

void Scene::GrowDrawn(const QueryView& q) {
  Vec3 lo, hi;
  QueryBounds(q, &lo, &hi);
  Grow(lo, &drawn_lo_, &drawn_hi_, &has_drawn_);
  Grow(hi, &drawn_lo_, &drawn_hi_, &has_drawn_);
}

Rgba FootColor(size_t track_index) {
  static const Rgba kPalette[] = {{255, 80, 40, 255},   {40, 130, 255, 255},  {60, 220, 60, 255},
                                  {255, 150, 200, 255}, {150, 100, 255, 255}, {0, 230, 230, 255}};
  return kPalette[track_index % (sizeof kPalette / sizeof kPalette[0])];
}

Status Scene::LoadTerrain(const std::string& path, const TerrainLoadOptions& options,
                          std::string* error) {
  RawSamples samples;
  Status s = footfall::LoadTerrain(path, options, &samples, error);
  if (s != Status::kOk) return s;
  s = ValidateAndNormalize(&samples, error);
  if (s != Status::kOk) {
    *error = path + ": " + *error;
    return s;
  }
  TerrainGrid grid;
  s = TerrainGrid::Build(samples, GridOptions{}, &grid, error);
  if (s != Status::kOk) {
    *error = path + ": " + *error;
    return s;
  }
  samples_ = std::move(samples);
  grid_ = std::move(grid);
  terrain_path_ = path;
  const GridStats& st = grid_.stats();
  if (st.spacing > 0) spacing_ = st.spacing;
  bool any_sample = false;
  for (const Vec3& p : samples_.points) {
    Grow(p, &lo_, &hi_, &has_bounds_);
    Grow(p, &terrain_lo_, &terrain_hi_, &any_sample);
  }
  bool any_cell = false;
  for (const uint32_t cell : grid_.OccupiedCells()) {
    Vec3 lo, hi;
    grid_.CellBox(cell, &lo, &hi);
    Grow(lo, &cells_lo_, &cells_hi_, &any_cell);
    Grow(hi, &cells_lo_, &cells_hi_, &any_cell);
  }
  return Status::kOk;
}

Status Scene::AddQuery(const QuerySpec& spec, std::string* error) {
  if (!has_terrain()) {
    *error = "a query needs a terrain (--terrain FILE)";
    return Status::kInvalidArgument;
  }
  queries_.push_back(RunQuery(grid_, spec));
  const QueryView& q = queries_.back();
  Grow(q.spec.point, &lo_, &hi_, &has_bounds_);
  Grow(q.trace.ideal, &lo_, &hi_, &has_bounds_);
  GrowDrawn(q);
  return Status::kOk;
}

Status Scene::LoadWalk(const std::string& path, std::string* error) {
  Walk walk;
  const Status s = ReadWalkJson(path, &walk, error);
  if (s != Status::kOk) return s;
  // The reader keeps rotations as written (non-zero); poses and axes want unit quaternions.
  for (WalkTrack& t : walk.tracks) {
    for (Quat& q : t.rotations) q = Normalized(q);
  }
  walk_ = std::move(walk);
  walk_path_ = path;
  FrameRange(walk_, &first_frame_, &last_frame_);
  for (const WalkTrack& t : walk_.tracks) {
    for (const WalkKey& k : t.keys) {
      Grow(k.position, &lo_, &hi_, &has_bounds_);
      Grow(k.position, &walk_lo_, &walk_hi_, &has_walk_keys_);
    }
  }
  sole_reach_ = 0;
  FitSoles();
  return Status::kOk;
}

void Scene::SetSoleLength(double length) {
  sole_length_ = length;
  FitSoles();
}

double Scene::SoleLength(const WalkTrack& track) const {
  if (track.kind != TrackKind::kFoot) return 0;
  return sole_length_ >= 0 ? sole_length_ : track.foot_length;
}

void Scene::FitSoles() {
  double longest = 0;
  for (const WalkTrack& t : walk_.tracks) longest = std::max(longest, SoleLength(t));
  if (!(longest > 0)) return;
  AddFootRotations(&walk_);  // (a track's own rotations are kept)
  // The soles reach half their length past the feet's keys: framed and kept between the clip
  // planes with them. (Grown by what the bounds lack: a second call does not grow them twice.)
  if (!has_walk_keys_ || !(0.5 * longest > sole_reach_)) return;
  const double grow = 0.5 * longest - sole_reach_;
  sole_reach_ = 0.5 * longest;
  const Vec3 reach{grow, grow, grow};
  for (const Vec3& corner : {walk_lo_ - reach, walk_hi_ + reach}) {
    Grow(corner, &lo_, &hi_, &has_bounds_);
    Grow(corner, &walk_lo_, &walk_hi_, &has_walk_keys_);
  }
}

size_t Scene::PlantedKeysOffTerrain(double limit, size_t* planted) const {
  *planted = 0;
  if (!has_terrain() || !has_walk()) return 0;
  size_t off = 0;
  for (const WalkTrack& t : walk_.tracks) {
    if (t.kind != TrackKind::kFoot) continue;
    for (const WalkKey& k : t.keys) {
      if (k.phase != KeyPhase::kStart && k.phase != KeyPhase::kEnd) continue;
      ++*planted;
      const Foothold h = grid_.Snap(k.position);
      off += h.status != Status::kOk || Distance(h.point, k.position) > limit;
    }
  }
  return off;
}

namespace {

// Whether p is finite and within +-kMaxKeyCoordinate, as anything drawn must be.
bool WithinDrawingRange(const Vec3& p) {
  return std::fabs(p.x) <= kMaxKeyCoordinate && std::fabs(p.y) <= kMaxKeyCoordinate &&
         std::fabs(p.z) <= kMaxKeyCoordinate;
}

}  // namespace

void Scene::AddLive(const std::vector<RecentQuery>& queries) {
  for (const RecentQuery& q : queries) {
    // A query footfalld refused (a point beyond its reach, a step of 1e200) has nothing to draw,
    // as --query refuses it: its ideal point put the camera at NaN, and the view stayed blank.
    const bool drawable = q.result.status != Status::kInvalidArgument &&
                          WithinDrawingRange(q.point) &&
                          (q.op != QueryOp::kNext || WithinDrawingRange(q.point + q.direction));
    if (!drawable) {
      ++live_received_;
      continue;
    }
    // With nothing loaded, the first query drawn is the origin of render space: at the world's
    // origin, queries at map coordinates (5e6) were drawn from floats half a unit apart, away
    // from where the camera and the dump put them.
    if (!has_bounds_ && !live_centred_) origin_ = q.point, live_centred_ = true;
    live_.push_back(FromRecent(q, has_terrain() ? &grid_ : nullptr));
    GrowDrawn(live_.back());
    ++live_received_;
    live_other_terrain_ += live_.back().other_terrain;
  }
  if (live_.size() > kMaxLive)
    live_.erase(live_.begin(), live_.begin() + static_cast<long>(live_.size() - kMaxLive));
}

void Scene::Finalize() {
  // Centred on the terrain, else the walk: vertices are floats about the origin, and a query
  // 1e9 away moved it there, leaving the terrain's samples 64 units apart.
  origin_ = has_terrain()    ? 0.5 * (terrain_lo_ + terrain_hi_)
            : has_walk_keys_ ? 0.5 * (walk_lo_ + walk_hi_)
            : has_bounds_    ? 0.5 * (lo_ + hi_)
                             : Vec3{};
  if (has_bounds_) {
    Grow(lo_, &drawn_lo_, &drawn_hi_, &has_drawn_);
    Grow(hi_, &drawn_lo_, &drawn_hi_, &has_drawn_);
  }
  // Without samples, size markers after the scene: a walk of a few centimetres, metres or
  // kilometres. (At least 1 mm: a walk of 4 cm had markers of a tenth of its size.)
  if (!has_terrain() && has_bounds_) {
    const double diagonal = Distance(lo_, hi_);
    spacing_ = diagonal > 0 ? diagonal / 300 : 1e-3;
  }
}

double Scene::MarkerUnit() const {
  const double diagonal = has_bounds_ ? Distance(lo_, hi_) : 0;
  return std::max(spacing_, std::min(0.02, diagonal / 300));
}

void Scene::SetUp(const ViewUp& up) { up_ = up, to_render_ = RenderRotation(up); }

glm::vec3 Scene::ToRender(const Vec3& world) const { return glm::vec3(ToRenderDouble(world)); }

glm::dvec3 Scene::ToRenderDouble(const Vec3& world) const {
  const Vec3 r = world - origin_;
  return to_render_ * glm::dvec3(r.x, r.y, r.z);
}

Vec3 Scene::ToWorld(const glm::dvec3& render) const {
  const glm::dvec3 r = glm::transpose(to_render_) * render;
  return origin_ + Vec3{r.x, r.y, r.z};
}

glm::vec3 Scene::ToRenderDirection(const Vec3& world) const {
  return glm::vec3(to_render_ * glm::dvec3(world.x, world.y, world.z));
}

RenderBox Scene::ToRenderBox(const Vec3& lo, const Vec3& hi) const {
  const glm::dvec3 a = ToRenderDouble(lo), b = ToRenderDouble(hi);
  return {glm::min(a, b), glm::max(a, b)};
}

void Scene::RenderBounds(glm::dvec3* lo, glm::dvec3* hi) const {
  if (!has_bounds_) {
    *lo = glm::dvec3(-0.5), *hi = glm::dvec3(0.5);
    return;
  }
  const RenderBox box = ToRenderBox(lo_, hi_);
  *lo = box.lo, *hi = box.hi;
}

void Scene::FrameBounds(const ViewState& view, glm::dvec3* lo, glm::dvec3* hi) const {
  if (!has_drawn_) {
    RenderBounds(lo, hi);
    return;
  }
  // (The loaded bounds alone: a candidate ring, a chosen sample's normal or the body's axes
  // could lie outside the picture.)
  Vec3 world_lo = drawn_lo_, world_hi = drawn_hi_;
  if (view.show_cells && has_terrain()) {
    bool any = true;
    Grow(cells_lo_, &world_lo, &world_hi, &any);
    Grow(cells_hi_, &world_lo, &world_hi, &any);
  }
  const RenderBox box = ToRenderBox(world_lo, world_hi);
  *lo = box.lo, *hi = box.hi;
  // Markers drawn from points: a query's cross and normal (4 spacings), a walk's body axes and
  // foot normals (8 marker units).
  double margin = 0;
  if (!queries_.empty() || !live_.empty()) margin = 4 * spacing_;
  if (has_walk()) margin = std::max(margin, 8 * MarkerUnit());
  *lo -= glm::dvec3(margin), *hi += glm::dvec3(margin);
}

bool Scene::WalkFrameBounds(glm::dvec3* lo, glm::dvec3* hi) const {
  if (!has_walk_keys_) return false;
  const RenderBox box = ToRenderBox(walk_lo_, walk_hi_);
  // Room for the feet's points and crosses; the longer markers (the body's axes, 8 units of a
  // coarse terrain's spacing: 4 m on 50 cm samples) may reach out of the picture, which shows
  // the walk.
  const double margin = 2 * MarkerUnit();
  *lo = box.lo - glm::dvec3(margin), *hi = box.hi + glm::dvec3(margin);
  return true;
}

std::vector<RenderBox> Scene::DrawnBoxes() const {
  std::vector<RenderBox> boxes;
  // Room for markers drawn around points (normals and body axes up to 8 sample spacings long,
  // crosses, arrow heads) and for the grid cells around the samples.
  const double markers = 16 * MarkerUnit() + (has_terrain() ? grid_.stats().cell_size : 0);
  auto add = [&](const Vec3& lo, const Vec3& hi) {
    RenderBox box = ToRenderBox(lo, hi);
    const double margin = 0.05 * glm::length(box.hi - box.lo) + markers;
    box.lo -= glm::dvec3(margin), box.hi += glm::dvec3(margin);
    boxes.push_back(box);
  };
  if (has_terrain()) add(cells_lo_, cells_hi_);
  if (has_walk_keys_) add(walk_lo_, walk_hi_);
  for (const std::vector<QueryView>* list : {&queries_, &live_}) {
    for (const QueryView& q : *list) {
      Vec3 lo, hi;
      QueryBounds(q, &lo, &hi);
      add(lo, hi);
    }
  }
  if (boxes.empty()) {
    RenderBox all;
    RenderBounds(&all.lo, &all.hi);
    boxes.push_back(all);
  }
  return boxes;
}

std::vector<DrawVertex> Scene::TerrainPoints(ColorMode mode) const {
  std::vector<DrawVertex> out;
  out.reserve(samples_.size());
  // Heights along the up: render space's y. (The terrain's, not a far query's.)
  const RenderBox range = ToRenderBox(terrain_lo_, terrain_hi_);
  const double h0 = range.lo.y, h1 = range.hi.y;
  const float size = -static_cast<float>(spacing_ * 1.6);  // world-sized splats
  for (size_t i = 0; i < samples_.size(); ++i) {
    const Vec3& p = samples_.points[i];
    const Rgba c = mode == ColorMode::kNormal
                       ? NormalColor(samples_.normals[i])
                       : HeightColor(h1 > h0 ? (ToRenderDouble(p).y - h0) / (h1 - h0) : 0.5);
    out.push_back({ToRender(p), c, size});
  }
  return out;
}

void Scene::DrawQuery(const QueryView& q, bool latest, DrawList* depth_tested,
                      DrawList* on_top) const {
  const float unit = static_cast<float>(spacing_);
  if (q.traced) {
    for (uint32_t cell : q.trace.cells) {
      Vec3 lo, hi;
      grid_.CellBox(cell, &lo, &hi);
      depth_tested->Box(ToRender(lo), ToRender(hi), colors::kQueryCell);
    }
    for (uint32_t i : q.trace.examined_samples) {
      if (i < samples_.size()) on_top->Point(ToRender(samples_.points[i]), colors::kExamined, 3);
    }
    for (uint32_t i : q.trace.candidates) {
      if (i < samples_.size()) on_top->Point(ToRender(samples_.points[i]), colors::kCandidate, 5);
    }
  }
  const glm::vec3 foot = ToRender(q.spec.point);
  const float marker = latest ? 1.0f : 0.6f;
  on_top->Point(foot, colors::kFoot, 11 * marker);
  on_top->Cross(foot, unit * 2, colors::kFoot);
  if (q.spec.op == QueryOp::kNext) {
    const glm::vec3 ideal = ToRender(q.spec.point + q.spec.direction);
    const float step = static_cast<float>(Length(q.spec.direction));
    on_top->Arrow(foot, ideal, std::max(step * 0.15f, unit), colors::kArrow);
    on_top->Point(ideal, colors::kIdeal, 8 * marker);
    // The candidate radius, as a ring in the horizontal plane around the ideal point.
    const float radius = static_cast<float>(RingRadius(q));
    const int kSegments = 48;
    for (int i = 0; i < kSegments; ++i) {
      const float a0 = 6.2831853f * static_cast<float>(i) / kSegments;
      const float a1 = 6.2831853f * static_cast<float>(i + 1) / kSegments;
      on_top->Line(ideal + radius * glm::vec3(std::cos(a0), 0, std::sin(a0)),
                   ideal + radius * glm::vec3(std::cos(a1), 0, std::sin(a1)),
                   Rgba{255, 255, 255, 90});
    }
  }
  if (q.result.status == Status::kOk) {
    const glm::vec3 chosen = ToRender(q.result.point);
    const glm::vec3 from =
        q.spec.op == QueryOp::kNext ? ToRender(q.spec.point + q.spec.direction) : foot;
    on_top->Line(from, chosen, colors::kChosen);
    on_top->Line(chosen, chosen + (unit * 4) * ToRenderDirection(q.result.normal), colors::kChosen);
    on_top->Point(chosen, colors::kChosen, 15 * marker);
  }
}

void Scene::DrawWalk(const ViewState& view, DrawList* on_top) const {
  size_t foot_index = 0;
  std::vector<glm::vec3> body_path;
  const float unit = static_cast<float>(MarkerUnit());
  for (const WalkTrack& track : walk_.tracks) {
    if (track.keys.empty()) continue;
    if (track.kind == TrackKind::kBody) {
      for (const WalkKey& k : track.keys) body_path.push_back(ToRender(k.position));
      for (size_t i = 1; i < body_path.size(); ++i)
        on_top->Line(body_path[i - 1], body_path[i], Rgba{200, 200, 200, 160});
      body_path.clear();
      const TrackPose pose = PoseAt(track, view.frame);
      const glm::vec3 p = ToRender(pose.position);
      on_top->Point(p, colors::kBody, 12);
      // The body's axes: x red, y green, z blue.
      const Quat& q = pose.rotation;
      const glm::vec3 axes[3] = {{1 - 2 * (q.y * q.y + q.z * q.z), 2 * (q.x * q.y + q.w * q.z),
                                  2 * (q.x * q.z - q.w * q.y)},
                                 {2 * (q.x * q.y - q.w * q.z), 1 - 2 * (q.x * q.x + q.z * q.z),
                                  2 * (q.y * q.z + q.w * q.x)},
                                 {2 * (q.x * q.z + q.w * q.y), 2 * (q.y * q.z - q.w * q.x),
                                  1 - 2 * (q.x * q.x + q.y * q.y)}};
      const Rgba axis_colors[3] = {{255, 60, 60, 255}, {60, 255, 60, 255}, {60, 60, 255, 255}};
      for (int a = 0; a < 3; ++a) {
        const Vec3 axis{axes[a].x, axes[a].y, axes[a].z};
        on_top->Line(p, p + ToRenderDirection(axis) * (unit * 8), axis_colors[a]);
      }
      continue;
    }
    const Rgba color = FootColor(foot_index++);
    const Rgba dim{static_cast<uint8_t>(color.r / 2 + 40), static_cast<uint8_t>(color.g / 2 + 40),
                   static_cast<uint8_t>(color.b / 2 + 40), 255};
    const auto& keys = track.keys;
    const bool turned = track.rotations.size() == keys.size();
    // The sole's outline about the foot at `at`, turned by `q`: its track's foot_width wide, or
    // a third of its length where the track has none.
    const double sole_length = SoleLength(track);
    const double sole_width = track.foot_width > 0 ? track.foot_width : sole_length / 3;
    auto sole = [&](const Vec3& at, const Quat& q, const Rgba& c) {
      const Vec3 forward = Rotate(q, Vec3{0, 0, 1}) * (0.5 * sole_length);
      const Vec3 side = Rotate(q, Vec3{1, 0, 0}) * (0.5 * sole_width);
      const glm::vec3 corners[4] = {ToRender(at + forward + side), ToRender(at + forward - side),
                                    ToRender(at - forward - side), ToRender(at - forward + side)};
      for (int i = 0; i < 4; ++i) on_top->Line(corners[i], corners[(i + 1) % 4], c);
    };
    if (sole_length > 0 && turned) {
      for (size_t i = 0; i < keys.size(); ++i)
        if (keys[i].phase != KeyPhase::kMid) sole(keys[i].position, track.rotations[i], dim);
    }
    for (size_t i = 0; i < keys.size(); ++i) {
      const WalkKey& k = keys[i];
      if (k.phase == KeyPhase::kEnd || k.phase == KeyPhase::kStart || k.phase == KeyPhase::kNone)
        on_top->Point(ToRender(k.position), dim, 7);  // a foothold
      if (SwingStartsAt(keys, i)) {
        const int kSegments = 16;
        glm::vec3 prev = ToRender(k.position);
        for (int s = 1; s <= kSegments; ++s) {
          const glm::vec3 next =
              ToRender(ArcPoint(k.position, keys[i + 1].position, keys[i + 2].position,
                                static_cast<double>(s) / kSegments));
          on_top->Line(prev, next, dim);
          prev = next;
        }
        on_top->Point(ToRender(keys[i + 1].position), dim, 4);
      }
    }
    const TrackPose pose = PoseAt(track, view.frame);
    const glm::vec3 p = ToRender(pose.position);
    on_top->Line(p, p + ToRenderDirection(pose.normal) * (unit * 6), color);
    // A foot that carries its orientation (--foot-rotations): its forward, dimmed.
    if (turned)
      on_top->Line(p, p + ToRenderDirection(Rotate(pose.rotation, Vec3{0, 0, 1})) * (unit * 6),
                   dim);
    if (sole_length > 0 && turned) sole(pose.position, pose.rotation, color);
    on_top->Point(p, color, 16);
  }
}

void Scene::Draw(const ViewState& view, DrawList* depth_tested, DrawList* on_top) const {
  if (view.show_cells && has_terrain()) {
    for (uint32_t cell : grid_.OccupiedCells()) {
      Vec3 lo, hi;
      grid_.CellBox(cell, &lo, &hi);
      depth_tested->Box(ToRender(lo), ToRender(hi), colors::kCell);
    }
  }
  for (size_t i = 0; i < live_.size(); ++i)
    DrawQuery(live_[i], i + 1 == live_.size(), depth_tested, on_top);
  for (const QueryView& q : queries_) DrawQuery(q, true, depth_tested, on_top);
  if (has_walk()) DrawWalk(view, on_top);
}

void Scene::Describe(const ViewState& view, const OrbitCamera& camera, int width, int height,
                     const LiveSource* source, JsonText* out) const {
  JsonText& j = *out;
  auto vec3 = [&](const Vec3& v) {
    j.BeginArray();
    j.Value(v.x), j.Value(v.y), j.Value(v.z);
    j.End();
  };
  auto pixel = [&](const Vec3& world) {
    glm::dvec2 px(0, 0);
    const bool front = camera.Project(ToRenderDouble(world), width, height, &px);
    j.Key("pixel").BeginArray();
    j.Value(static_cast<float>(px.x)), j.Value(static_cast<float>(px.y));
    j.End();
    j.Key("visible").Value(front && px.x >= 0 && px.y >= 0 && px.x < width && px.y < height);
  };
  auto query = [&](const QueryView& q) {
    j.BeginObject();
    j.Key("query").Value(FormatQueryText(q.spec));
    j.Key("op").Value(QueryOpName(q.spec.op));
    if (q.live) j.Key("sequence").Value(static_cast<uint64_t>(q.sequence));
    if (q.spec.op == QueryOp::kNext) j.Key("radius").Value(RingRadius(q));
    j.Key("status").Value(StatusName(q.result.status));
    j.Key("found").Value(q.result.status == Status::kOk);
    if (q.result.status == Status::kOk) {
      j.Key("index").Value(static_cast<uint64_t>(q.result.index));
      j.Key("point"), vec3(q.result.point);
      pixel(q.result.point);
    }
    if (q.live) j.Key("other_terrain").Value(q.other_terrain);
    j.Key("traced").Value(q.traced);
    if (q.traced) {
      j.Key("cells").Value(static_cast<uint64_t>(q.trace.cells.size()));
      j.Key("examined").Value(static_cast<uint64_t>(q.trace.examined_samples.size()));
      j.Key("candidates").Value(static_cast<uint64_t>(q.trace.candidates.size()));
    }
    j.End();
  };
  j.Key("image").BeginObject();
  j.Key("width").Value(width);
  j.Key("height").Value(height);
  j.End();
  j.Key("camera").BeginObject();
  j.Key("eye"), vec3(ToWorld(camera.eye()));
  j.Key("target"), vec3(ToWorld(camera.target()));
  j.Key("up"), vec3(UpVector(up_));
  j.Key("fov_y_degrees").Value(OrbitCamera::kFovYDegrees);
  j.End();
  j.Key("color_mode").Value(view.color == ColorMode::kNormal ? "normal" : "height");
  j.Key("show_cells").Value(view.show_cells);
  j.Key("terrain");
  if (has_terrain()) {
    const GridStats& st = grid_.stats();
    j.BeginObject();
    j.Key("path").Value(terrain_path_);
    j.Key("samples").Value(static_cast<uint64_t>(st.samples));
    j.Key("bounds_min"), vec3(st.bounds_min);
    j.Key("bounds_max"), vec3(st.bounds_max);
    j.Key("occupied_cells").Value(static_cast<uint64_t>(st.occupied_cells));
    j.End();
  } else {
    j.Null();
  }
  j.Key("queries").BeginArray();
  for (const QueryView& q : queries_) query(q);
  j.End();
  j.Key("live").BeginObject();
  j.Key("received").Value(static_cast<uint64_t>(live_received_));
  j.Key("queries").BeginArray();
  for (const QueryView& q : live_) query(q);
  j.End();
  if (source) {
    j.Key("server").Value(source->address);
    j.Key("after").Value(source->after);
  }
  j.End();
  j.Key("walk");
  if (!has_walk()) {
    j.Null();
    return;
  }
  j.BeginObject();
  j.Key("path").Value(walk_path_);
  j.Key("fps").Value(walk_.fps);
  j.Key("frame").Value(view.frame);
  j.Key("first_frame").Value(first_frame_);
  j.Key("last_frame").Value(last_frame_);
  j.Key("tracks").BeginArray();
  size_t foot_index = 0;
  for (const WalkTrack& t : walk_.tracks) {
    if (t.keys.empty()) continue;
    const TrackPose pose = PoseAt(t, view.frame);
    j.BeginObject();
    j.Key("name").Value(t.name);
    if (!t.character.empty()) j.Key("character").Value(t.character);  // a crowd's or a scene's
    j.Key("kind").Value(t.kind == TrackKind::kFoot ? "foot" : "body");
    j.Key("position"), vec3(pose.position);
    pixel(pose.position);
    if (t.kind == TrackKind::kFoot) {
      const Rgba c = FootColor(foot_index++);
      j.Key("color").BeginArray();
      j.Value(c.r), j.Value(c.g), j.Value(c.b);
      j.End();
      j.Key("swinging").Value(pose.swinging);
      // The sole drawn about it (SetSoleLength), when one is.
      if (SoleLength(t) > 0 && t.rotations.size() == t.keys.size()) {
        j.Key("sole_length").Value(SoleLength(t));
        j.Key("sole_width").Value(t.foot_width > 0 ? t.foot_width : SoleLength(t) / 3);
      }
    }
    if (t.kind == TrackKind::kBody || t.rotations.size() == t.keys.size()) {
      const Quat& q = pose.rotation;
      j.Key("rotation").BeginArray();
      j.Value(q.x), j.Value(q.y), j.Value(q.z), j.Value(q.w);
      j.End();
    }
    j.End();
  }
  j.End();
  j.End();
}

}  // namespace footfall::viewer
