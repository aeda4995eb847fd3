// Scene: everything the viewer shows, without GL: the terrain samples and their grid, the
// queries (command line and live), and a walk. It turns itself into DrawLists for a frame and
// describes what it drew as JSON (the state dump used by tests).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "footfall/client/recent_queries.h"
#include "footfall/import/terrain_loader.h"
#include "footfall/steps/walk.h"
#include "footfall/terrain/grid.h"
#include "footfall/viewer/camera.h"
#include "footfall/viewer/draw_list.h"
#include "footfall/viewer/json_text.h"
#include "footfall/viewer/query_view.h"
#include "footfall/viewer/view_up.h"

namespace footfall::viewer {

enum class ColorMode { kNormal, kHeight };

// What the user toggles while viewing.
struct ViewState {
  double frame = 0;  // walk playback frame
  ColorMode color = ColorMode::kNormal;
  bool show_cells = false;  // occupied grid cells as wireframe boxes
};

// The colours the viewer uses, so tests and docs can name them.
namespace colors {
constexpr Rgba kBackground{28, 30, 36, 255};
constexpr Rgba kChosen{255, 0, 255, 255};     // the sample a query chose
constexpr Rgba kCandidate{255, 214, 0, 255};  // next: samples meeting the conditions
constexpr Rgba kExamined{150, 150, 170, 255};
constexpr Rgba kFoot{0, 200, 255, 255};     // the query point / foot
constexpr Rgba kIdeal{255, 255, 255, 255};  // foot + direction
constexpr Rgba kArrow{255, 140, 0, 255};
constexpr Rgba kCell{110, 110, 130, 255};
constexpr Rgba kQueryCell{230, 230, 90, 160};
constexpr Rgba kBody{240, 240, 240, 255};
}  // namespace colors

// The colour of foot track `i` of a walk (cycles through a palette free of the query colours).
Rgba FootColor(size_t track_index);

class Scene {
 public:
  // Loads a terrain file (any format of terrain_loader.h) and builds its grid.
  Status LoadTerrain(const std::string& path, const TerrainLoadOptions& options,
                     std::string* error);
  // Answers a query on the terrain's grid and keeps it for drawing. kInvalidArgument without
  // a terrain.
  Status AddQuery(const QuerySpec& spec, std::string* error);
  // Reads a footfall-walk JSON file (footfall/steps/walk_json.h); body rotations are
  // normalised for drawing.
  Status LoadWalk(const std::string& path, std::string* error);
  // Each foot's sole is drawn its track's foot_length long (the walk's own; none where it is
  // 0) along its forward and its track's foot_width wide (a third of its length where the track
  // has none), centred on the foot: at its pose, and dimmed at
  // every planted key (its footprints). SetSoleLength(length) draws every foot's sole `length`
  // long instead (0: none); a negative length goes back to the walk's own. Feet whose walk
  // carries no rotations are turned as `footfall generate --foot-rotations` turns them
  // (AddFootRotations). [Units: wu]
  void SetSoleLength(double length);
  // How many of the walk's planted foot keys (start and end) lie farther than `limit` from
  // every terrain sample, of *planted: a walk made on another terrain shows as many. 0 without
  // a terrain or a walk.
  size_t PlantedKeysOffTerrain(double limit, size_t* planted) const;
  // Adds queries received from footfalld, traced on the local grid when there is one. Keeps
  // the newest `kMaxLive`.
  void AddLive(const std::vector<RecentQuery>& queries);
  static constexpr size_t kMaxLive = 256;

  // Sets the world axis the view stands on (default +y): render space turns it onto +y.
  void SetUp(const ViewUp& up);
  const ViewUp& up() const { return up_; }
  // Fixes the render-space origin at the centre of what is loaded. Call once after loading.
  void Finalize();

  bool has_terrain() const { return !terrain_path_.empty(); }
  bool has_walk() const { return !walk_path_.empty(); }
  bool has_walk_keys() const { return has_walk_keys_; }
  // Whether anything was loaded (a terrain, queries or a walk), not only received live.
  bool has_loaded() const { return has_bounds_; }
  const TerrainGrid& grid() const { return grid_; }
  const Walk& walk() const { return walk_; }
  double first_frame() const { return first_frame_; }
  double last_frame() const { return last_frame_; }
  size_t live_received() const { return live_received_; }
  // Live queries the local terrain answered otherwise (asked on another terrain of footfalld).
  size_t live_other_terrain() const { return live_other_terrain_; }
  const std::vector<QueryView>& queries() const { return queries_; }
  const std::vector<QueryView>& live() const { return live_; }

  // World space to render space (world minus the origin, turned so that the up is +y): in
  // float for vertices, in double for the camera; and back. ToRenderDirection turns a
  // direction alone.
  glm::vec3 ToRender(const Vec3& world) const;
  glm::dvec3 ToRenderDouble(const Vec3& world) const;
  Vec3 ToWorld(const glm::dvec3& render) const;
  glm::vec3 ToRenderDirection(const Vec3& world) const;
  // The render-space box of the world-space box [lo, hi].
  RenderBox ToRenderBox(const Vec3& lo, const Vec3& hi) const;
  // The render-space bounds of everything loaded (a unit box when nothing is): what the
  // camera frames.
  void RenderBounds(glm::dvec3* lo, glm::dvec3* hi) const;
  // The render-space bounds of everything a frame of `view` draws: what is loaded, the live
  // queries received, the candidate rings, arrows, cells and markers around them: what the
  // camera frames.
  void FrameBounds(const ViewState& view, glm::dvec3* lo, glm::dvec3* hi) const;
  // The render-space bounds of the walk's keys, with room for the feet's markers: what the
  // camera frames to show the walk alone. False, and nothing set, when the walk has no keys.
  bool WalkFrameBounds(glm::dvec3* lo, glm::dvec3* hi) const;
  // The render-space boxes of what is drawn, one for the terrain (its cells), one for the walk
  // and one per query and live query, each with room for the markers around it (rings,
  // normals, cells): the camera keeps them between its clip planes.
  std::vector<RenderBox> DrawnBoxes() const;

  // The terrain samples as world-sized points in render space, coloured by `mode`.
  std::vector<DrawVertex> TerrainPoints(ColorMode mode) const;
  // Terrain splat size. [Units: wu]
  double SampleSpacing() const { return spacing_; }
  // The length unit of the walk's markers (body axes, foot normals): the sample spacing, and
  // at least 2 cm in a scene of 6 m or more (1/300 of its diagonal in a smaller one). [Units: wu]
  double MarkerUnit() const;
  // The smallest radius the camera frames: a few sample spacings. [Units: wu]
  double MinFrameRadius() const { return 2 * spacing_; }

  // Fills `depth_tested` (grid cells) and `on_top` (queries, walk) for one frame.
  void Draw(const ViewState& view, DrawList* depth_tested, DrawList* on_top) const;

  // The live server a frame's live queries come from, for Describe.
  struct LiveSource {
    std::string address;
    uint64_t after = 0;  // the first sequence number followed
  };
  // Writes what a frame shows as the members of the object open in *out (left open for the
  // caller's own members), with pixel positions for a width x height image seen by `camera`.
  void Describe(const ViewState& view, const OrbitCamera& camera, int width, int height,
                const LiveSource* source, JsonText* out) const;

 private:
  void DrawQuery(const QueryView& q, bool latest, DrawList* depth_tested, DrawList* on_top) const;
  void DrawWalk(const ViewState& view, DrawList* on_top) const;
  // The length a foot track's sole is drawn (SetSoleLength). [Units: wu]
  double SoleLength(const WalkTrack& track) const;
  // Turns the feet (AddFootRotations) and grows the walk's bounds by half the longest sole,
  // once some sole is drawn.
  void FitSoles();
  // The world-space box of a query's points, its arrow, cells and candidate ring.
  void QueryBounds(const QueryView& q, Vec3* lo, Vec3* hi) const;
  // Grows the drawn bounds by QueryBounds(q).
  void GrowDrawn(const QueryView& q);

  std::string terrain_path_, walk_path_;
  RawSamples samples_;
  TerrainGrid grid_;
  double spacing_ = 0.1;
  std::vector<QueryView> queries_, live_;
  size_t live_received_ = 0;
  size_t live_other_terrain_ = 0;
  Walk walk_;
  double sole_length_ = -1;  // SetSoleLength (negative: each track's foot_length)
  double sole_reach_ = 0;    // how far the walk's bounds were grown for soles (FitSoles)
  double first_frame_ = 0, last_frame_ = 0;
  Vec3 origin_;
  ViewUp up_;
  glm::dmat3 to_render_{1.0};  // RenderRotation(up_)
  bool live_centred_ = false;  // origin_ moved to the first live query (nothing loaded)
  Vec3 lo_, hi_;
  bool has_bounds_ = false;
  Vec3 drawn_lo_, drawn_hi_;  // lo_, hi_ and what only adds to the picture (world space)
  bool has_drawn_ = false;
  Vec3 cells_lo_, cells_hi_;      // the occupied grid cells' bounds (world space)
  Vec3 terrain_lo_, terrain_hi_;  // the terrain samples' bounds (world space)
  Vec3 walk_lo_, walk_hi_;        // the walk's keys' bounds (world space)
  bool has_walk_keys_ = false;
};

}  // namespace footfall::viewer
