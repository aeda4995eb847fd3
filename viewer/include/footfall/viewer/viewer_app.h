// The footfall-view program: options, the window and its input, headless screenshots, and the
// live follower of a footfalld.
#pragma once

#include <string>
#include <vector>

#include "footfall/import/terrain_loader.h"
#include "footfall/terrain/vec3.h"
#include "footfall/viewer/view_up.h"

namespace footfall::viewer {

struct ViewerOptions {
  std::string terrain;  // a terrain file ("" for none)
  TerrainLoadOptions load;
  std::vector<std::string> queries;  // "next X Y Z DX DY DZ", "snap X Y Z", "normal X Y Z"
  double tolerance = 0;              // [Units: wu] next: candidate radius; 0 = step length
  std::string walk;                  // a walk JSON file ("" for none)
  std::string server;                // HOST:PORT of footfalld, with `live`
  bool live = false;
  int live_wait = 0;               // screenshot: wait for this many live queries first
  double timeout_s = 10;           // [Units: s] bound on every wait for the server
  std::string screenshot;          // render one frame to this PNG and exit
  int width = 1280, height = 800;  // [Units: px] window or image size
  bool has_frame = false;
  double frame = 0;        // walk frame to show (default: the first)
  std::string dump_state;  // write what is drawn as JSON here
  bool height_colors = false;
  bool show_cells = false;
  bool has_camera = false;
  bool frame_walk = false;  // frame the walk's keys at the start, not everything (W)
  double sole_length = -1;  // [Units: wu] draw the feet's soles this long (0: none;
                            // negative: each foot track's foot_length, as the walk has it)
  Vec3 eye, target;         // world space, with has_camera
  ViewUp up;                // the world axis shown up (the camera's up)
};

// Runs the viewer. Prints errors as "footfall-view: ..." on stderr and returns the exit code:
// 0 success, 1 a failure (file, server, display), 2 a bad option value.
int RunViewer(const ViewerOptions& options);

}  // namespace footfall::viewer
