// TriangleMesh: an indexed triangle mesh in world space, the common form of every polygon file and
// height map before it is resampled into terrain samples (mesh_sampler.h).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "footfall/terrain/vec3.h"

namespace footfall {

struct TriangleMesh {
  std::vector<Vec3> vertices;                      // world space [(x, y, z)], all finite
  std::vector<std::array<uint32_t, 3>> triangles;  // counter-clockwise seen from the outside
};

// Twice the area of triangle t times its unit normal: Cross(b - a, c - a). [Units: wu^2]
inline Vec3 TriangleCross(const TriangleMesh& mesh, size_t t) {
  const auto& tri = mesh.triangles[t];
  const Vec3& a = mesh.vertices[tri[0]];
  return Cross(mesh.vertices[tri[1]] - a, mesh.vertices[tri[2]] - a);
}

// Sum of the triangle areas. [Units: wu^2]
double SurfaceArea(const TriangleMesh& mesh);

// Per-vertex unit normals: the area-weighted mean of the incident triangles' normals. A vertex with
// no triangle, or whose triangle normals cancel, gets (0, 0, 0).
std::vector<Vec3> VertexNormals(const TriangleMesh& mesh);

// Smooth-shading normals that keep sharp edges, per triangle corner: corner k of triangle t
// gets the area-weighted mean normal of the triangles with a corner at its position (its
// vertex, or another at the same place: a soup or a mesh split at seams is smoothed as the
// surface it models) whose normals lie within `crease_deg` of t's (t's own included). Faces
// meeting at a sharper edge (a stair's nose, a block's rim, a wall's foot) keep their own
// normals right up to it, as a modelling package shades them with auto smooth; gentler edges (a
// terrain's facets) are smoothed over. crease_deg >= 180 gives, on a mesh whose vertices are
// all at distinct positions, the plain vertex normals of VertexNormals; 0 the face normals.
class CornerNormals {
 public:
  // Keeps a reference to `mesh`, which must outlive this and not change.
  CornerNormals(const TriangleMesh& mesh, double crease_deg);
  // The unit normals at the corners of triangle t, in its vertex order (the face's normal at a
  // corner whose neighbours' normals cancel; (0, 0, 0) for a degenerate triangle).
  std::array<Vec3, 3> Of(size_t t) const;

 private:
  const TriangleMesh& mesh_;
  double cos_crease_;
  std::vector<uint32_t> position_;  // per vertex: CoincidentVertexIds
  std::vector<uint32_t> first_;     // per position's id + 1: offsets into around_
  std::vector<uint32_t> around_;    // the triangles with a corner at each position
};

// For each vertex, the lowest index of a vertex at exactly the same position: the mesh's
// topology when vertices are split at seams (a triangle soup, or a mesh exported with its faces'
// own copies of their corners, as split normals or texture seams leave it). O(n log n).
std::vector<uint32_t> CoincidentVertexIds(const std::vector<Vec3>& vertices);

// What TurnOutward turned over.
struct MeshTurnover {
  size_t closed_shells = 0;      // connected parts that are closed
  size_t inside_out_shells = 0;  // ... of them enclosing a negative volume: turned over
  size_t open_faces = 0;         // faces of the open parts, taken together
  bool open_faced_down = false;  // ... turned over, as they faced down
  size_t turned_faces = 0;       // faces turned over in all
};

// Turns the faces of a mesh wound the wrong way over (reverses their winding), so that normals
// face out of each closed shell (a part connected through its own vertex indices and closed by
// them, whatever it touches; else a connected part, vertices at the same position joined as in
// CoincidentVertexIds, whose every edge is used once in each
// direction, or matched the other way by a chain of edges through corners on it within 1e-5 of
// its length, a T-junction: turned when the volume it encloses is negative) and up out of the open
// parts, a terrain: turned, all together, when the component along `up` of their area-weighted
// normals sums to less than -1/4 of their area (they face down, a steep flight of stairs' treads
// included; rooms, caves and walls, whose faces face every way, are left alone). A closed room
// modelled facing in cannot be told from an inside-out box: it is turned over.
MeshTurnover TurnOutward(TriangleMesh* mesh, const Vec3& up);

// World-space bounds of the vertices its triangles use (a stray vertex far away widened the
// sampler's cells until a fine separation was refused); both (0, 0, 0) without triangles.
void MeshBounds(const TriangleMesh& mesh, Vec3* lo, Vec3* hi);

// Non-convex polygons of up to this many corners are clipped by a search of every corner for
// each ear (up to n^3 steps, its triangles as before); larger ones keep a list of their reflex
// corners and look at the neighbours of each ear clipped (about n * reflex corners steps).
constexpr size_t kMaxSearchedCorners = 256;
// Non-convex polygons of more corners than this are fanned (clipping would take seconds each).
constexpr size_t kMaxClippedCorners = 16384;

// Triangulates the polygon `corners` (indices into `vertices`, in order around it) by ear
// clipping in the plane of its Newell normal, appending triangles wound as the polygon is to
// *triangles. A convex polygon gives the fan from its first corner (in linear time); a concave
// one is cut along its inside only. Returns false when it fans instead: a polygon without a
// plane (its areas cancel, as a bow tie's), a non-convex one of more than kMaxClippedCorners
// corners, or one where ear clipping finds no ear (self-intersecting: the rest is fanned from
// its first remaining corner).
bool TriangulatePolygon(const std::vector<Vec3>& vertices, const std::vector<uint32_t>& corners,
                        std::vector<std::array<uint32_t, 3>>* triangles);

// True when triangle (a, b, c) has no area to speak of, judged on its own size and position:
// its height over its longest edge is at most `relative_epsilon` times that edge (a collinear
// sliver or a needle), or within the rounding of its coordinates (8 double epsilons of its
// largest |coordinate|). A 1 cm triangle is real at 1e7 from the origin, or in a 100 km mesh.
bool IsDegenerateTriangle(const Vec3& a, const Vec3& b, const Vec3& c,
                          double relative_epsilon = 1e-12);

// Removes triangles repeating a vertex and those IsDegenerateTriangle calls degenerate. Returns
// how many were removed.
size_t RemoveDegenerateTriangles(TriangleMesh* mesh, double relative_epsilon = 1e-12);

// The point of the mesh's surface nearest to q (a vertex for a mesh without triangles; q for an
// empty mesh). A scan of every triangle.
Vec3 NearestSurfacePoint(const TriangleMesh& mesh, const Vec3& q);

// Keeps the triangles whose bounding box meets the box [lo, hi] and the vertices they use
// (renumbered in order of first use). Returns how many triangles were removed.
size_t CropToBox(TriangleMesh* mesh, const Vec3& lo, const Vec3& hi);

}  // namespace footfall
