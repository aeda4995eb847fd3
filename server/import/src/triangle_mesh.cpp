#include "footfall/import/triangle_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace footfall {
namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

double SurfaceArea(const TriangleMesh& mesh) {
  double area = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) area += 0.5 * Length(TriangleCross(mesh, t));
  return area;
}

std::vector<Vec3> VertexNormals(const TriangleMesh& mesh) {
  std::vector<Vec3> normals(mesh.vertices.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3 n = TriangleCross(mesh, t);  // length = 2 * area: area weighting for free
    for (uint32_t v : mesh.triangles[t]) normals[v] += n;
  }
  for (Vec3& n : normals) {
    const double length = Length(n);
    n = length > 0 ? n / length : Vec3{};
  }
  return normals;
}

CornerNormals::CornerNormals(const TriangleMesh& mesh, double crease_deg)
    : mesh_(mesh),
      cos_crease_(crease_deg >= 180 ? -2.0 : std::cos(std::max(crease_deg, 0.0) * kPi / 180)),
      position_(CoincidentVertexIds(mesh.vertices)) {
  first_.assign(mesh.vertices.size() + 1, 0);
  for (const auto& tri : mesh.triangles)
    for (uint32_t v : tri) ++first_[position_[v] + 1];
  for (size_t v = 0; v < mesh.vertices.size(); ++v) first_[v + 1] += first_[v];
  around_.resize(first_.back());
  std::vector<uint32_t> next(first_.begin(), first_.end() - 1);
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (uint32_t v : mesh.triangles[t]) around_[next[position_[v]]++] = static_cast<uint32_t>(t);
}

std::array<Vec3, 3> CornerNormals::Of(size_t t) const {
  const Vec3 cross = TriangleCross(mesh_, t);
  const double length = Length(cross);
  std::array<Vec3, 3> out{};
  if (!(length > 0)) return out;
  const Vec3 face = cross / length;
  for (int k = 0; k < 3; ++k) {
    const uint32_t v = position_[mesh_.triangles[t][k]];
    Vec3 sum;
    for (uint32_t i = first_[v]; i < first_[v + 1]; ++i) {
      const Vec3 n = TriangleCross(mesh_, around_[i]);  // length = 2 * area: area weighting
      const double l = Length(n);
      if (l > 0 && Dot(n, face) >= cos_crease_ * l) sum += n;
    }
    const double l = Length(sum);
    out[k] = l > 0 ? sum / l : face;
  }
  return out;
}

std::vector<uint32_t> CoincidentVertexIds(const std::vector<Vec3>& vertices) {
  std::vector<uint32_t> order(vertices.size()), id(vertices.size());
  for (uint32_t v = 0; v < order.size(); ++v) order[v] = v;
  auto less = [&](uint32_t a, uint32_t b) {
    const Vec3 &p = vertices[a], &q = vertices[b];
    if (p.x != q.x) return p.x < q.x;
    if (p.y != q.y) return p.y < q.y;
    if (p.z != q.z) return p.z < q.z;
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  for (size_t i = 0; i < order.size(); ++i) {
    const bool same = i > 0 && vertices[order[i]] == vertices[order[i - 1]];
    id[order[i]] = same ? id[order[i - 1]] : order[i];
  }
  return id;
}

namespace {

// Union-find over vertices: the root of each vertex's set.
class VertexSets {
 public:
  explicit VertexSets(size_t vertices) : parent_(vertices) {
    for (uint32_t v = 0; v < parent_.size(); ++v) parent_[v] = v;
  }
  uint32_t Root(uint32_t v) {
    while (parent_[v] != v) v = parent_[v] = parent_[parent_[v]];
    return v;
  }
  void Join(uint32_t a, uint32_t b) {
    a = Root(a), b = Root(b);
    if (a != b) parent_[b] = a;
  }

 private:
  std::vector<uint32_t> parent_;
};

constexpr uint32_t kNoShell = std::numeric_limits<uint32_t>::max();

// Per triangle, the shell closed by the mesh's own vertex indices it belongs to (the root vertex
// of a part connected through shared vertices whose every directed edge (a, b) has its twin
// (b, a)), or kNoShell.
std::vector<uint32_t> ShellsByIndex(const TriangleMesh& mesh) {
  VertexSets sets(mesh.vertices.size());
  for (const auto& tri : mesh.triangles) sets.Join(tri[0], tri[1]), sets.Join(tri[0], tri[2]);
  std::vector<uint64_t> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const auto& tri : mesh.triangles)
    for (int k = 0; k < 3; ++k) edges.push_back(uint64_t{tri[k]} << 32 | tri[(k + 1) % 3]);
  std::sort(edges.begin(), edges.end());
  std::vector<uint8_t> open(mesh.vertices.size(), 0);  // per part (its root vertex)
  for (const uint64_t e : edges)
    if (!std::binary_search(edges.begin(), edges.end(), e << 32 | e >> 32))
      open[sets.Root(static_cast<uint32_t>(e >> 32))] = 1;
  std::vector<uint32_t> shell(mesh.triangles.size());
  for (size_t t = 0; t < shell.size(); ++t) {
    const uint32_t r = sets.Root(mesh.triangles[t][0]);
    shell[t] = open[r] ? kNoShell : r;
  }
  return shell;
}

}  // namespace

MeshTurnover TurnOutward(TriangleMesh* mesh, const Vec3& up) {
  MeshTurnover out;
  const size_t n = mesh->triangles.size();
  if (n == 0) return out;
  // Shells closed by their own vertices are judged each on its own, whatever they touch: two
  // crates stacked, or one on the ground, meet at positions but are not one shell.
  const std::vector<uint32_t> own_shell = ShellsByIndex(*mesh);
  // The other faces' topology by position: a soup's faces meet where their corners coincide.
  const std::vector<uint32_t> id = CoincidentVertexIds(mesh->vertices);
  auto corner = [&](const std::array<uint32_t, 3>& tri, int k) { return id[tri[k]]; };
  // Their connected parts: triangles sharing a vertex (union-find over vertices).
  VertexSets sets(mesh->vertices.size());
  auto root = [&](uint32_t v) { return sets.Root(v); };
  for (size_t t = 0; t < n; ++t) {
    if (own_shell[t] != kNoShell) continue;
    const auto& tri = mesh->triangles[t];
    sets.Join(corner(tri, 0), corner(tri, 1)), sets.Join(corner(tri, 0), corner(tri, 2));
  }
  // Each triangle's part: its own shell's root vertex, or past the vertices its part's root.
  const size_t vertices = mesh->vertices.size();
  auto part = [&](size_t t) -> size_t {
    if (own_shell[t] != kNoShell) return own_shell[t];
    return vertices + root(corner(mesh->triangles[t], 0));
  };
  // A part is closed when each of its directed edges (a, b) has its twin (b, a).
  std::vector<uint64_t> edges;
  edges.reserve(3 * n);
  for (size_t t = 0; t < n; ++t) {
    if (own_shell[t] != kNoShell) continue;
    const auto& tri = mesh->triangles[t];
    for (int k = 0; k < 3; ++k)
      edges.push_back(uint64_t{corner(tri, k)} << 32 | corner(tri, (k + 1) % 3));
  }
  std::sort(edges.begin(), edges.end());
  std::vector<uint64_t> lone;  // edges without their twin
  for (const uint64_t e : edges) {
    const uint64_t twin = e << 32 | e >> 32;
    if (!std::binary_search(edges.begin(), edges.end(), twin)) lone.push_back(e);
  }
  // A lone edge matched the other way by a chain of lone edges through corners on it is no
  // opening: a T-junction, where a zero-area triangle was left out (a concave face's straight
  // corner, as ear clipping leaves it, or a corner of one face modelled on another's edge). A
  // corner is on the edge when the triangle it makes with the edge is degenerate as
  // IsDegenerateTriangle judges it, its height at most kOnEdge of the edge (coordinates written
  // with six decimals, as most exporters write them, put a modelled corner that far off). A
  // corner with more than kMaxLoneOut lone edges leaving it (a hub of an open fan) is passed
  // through by none, which keeps the search linear.
  constexpr size_t kMaxLoneOut = 8;
  constexpr double kOnEdge = 1e-5;
  std::vector<uint8_t> matched(lone.size(), 0);
  auto from = [&](uint32_t v) {  // the lone edges starting at v
    return std::equal_range(lone.begin(), lone.end(), uint64_t{v} << 32,
                            [](uint64_t x, uint64_t y) { return (x >> 32) < (y >> 32); });
  };
  std::vector<size_t> chain;
  for (size_t i = 0; i < lone.size(); ++i) {
    const uint32_t a = static_cast<uint32_t>(lone[i] >> 32), b = static_cast<uint32_t>(lone[i]);
    const Vec3 &pa = mesh->vertices[a], &pb = mesh->vertices[b];
    const Vec3 ab = pb - pa;
    chain.clear();
    // Each step goes to a corner strictly nearer a along the edge: the chain cannot loop.
    for (uint32_t at = b; at != a;) {
      const auto [first, last] = from(at);
      if (static_cast<size_t>(last - first) > kMaxLoneOut) break;
      bool stepped = false;
      for (auto it = first; it != last && !stepped; ++it) {
        const uint32_t next = static_cast<uint32_t>(*it);
        const Vec3& pn = mesh->vertices[next];
        const bool on =
            next == a || (IsDegenerateTriangle(pa, pn, pb, kOnEdge) && Dot(pn - pa, ab) > 0 &&
                          Dot(pn - pa, ab) < Dot(mesh->vertices[at] - pa, ab));
        if (on) chain.push_back(static_cast<size_t>(it - lone.begin())), at = next, stepped = true;
      }
      if (!stepped) break;
    }
    if (!chain.empty() && static_cast<uint32_t>(lone[chain.back()]) == a) {
      matched[i] = 1;
      for (const size_t c : chain) matched[c] = 1;
    }
  }
  std::vector<uint8_t> open(2 * vertices, 0);  // per part
  for (size_t i = 0; i < lone.size(); ++i)
    if (!matched[i]) open[vertices + root(static_cast<uint32_t>(lone[i] >> 32))] = 1;
  // Six times each closed part's volume, about its root vertex (less cancellation); the open
  // parts' area-weighted normal and area.
  std::vector<double> volume(2 * vertices, 0);
  std::vector<uint8_t> counted(2 * vertices, 0);
  Vec3 open_sum;
  double open_area = 0;
  for (size_t t = 0; t < n; ++t) {
    const auto& tri = mesh->triangles[t];
    const size_t r = part(t);
    if (open[r]) {
      const Vec3 c = TriangleCross(*mesh, t);
      open_sum += c, open_area += Length(c), ++out.open_faces;
      continue;
    }
    if (!counted[r]) counted[r] = 1, ++out.closed_shells;
    const Vec3& o = mesh->vertices[r < vertices ? r : r - vertices];
    volume[r] += Dot(mesh->vertices[tri[0]] - o,
                     Cross(mesh->vertices[tri[1]] - o, mesh->vertices[tri[2]] - o));
  }
  for (size_t r = 0; r < 2 * vertices; ++r)
    if (counted[r] && volume[r] < 0) ++out.inside_out_shells;
  out.open_faced_down = open_area > 0 && Dot(open_sum, up) < -0.25 * open_area * Length(up);
  for (size_t t = 0; t < n; ++t) {
    auto& tri = mesh->triangles[t];
    const size_t r = part(t);
    if (open[r] ? out.open_faced_down : volume[r] < 0)
      std::swap(tri[1], tri[2]), ++out.turned_faces;
  }
  return out;
}

void MeshBounds(const TriangleMesh& mesh, Vec3* lo, Vec3* hi) {
  if (mesh.triangles.empty()) {
    *lo = *hi = Vec3{};
    return;
  }
  *lo = *hi = mesh.vertices[mesh.triangles[0][0]];
  for (const auto& tri : mesh.triangles) {
    for (const uint32_t i : tri) {
      const Vec3& v = mesh.vertices[i];
      lo->x = std::min(lo->x, v.x), lo->y = std::min(lo->y, v.y), lo->z = std::min(lo->z, v.z);
      hi->x = std::max(hi->x, v.x), hi->y = std::max(hi->y, v.y), hi->z = std::max(hi->z, v.z);
    }
  }
}

namespace {

// Ear clipping of a large non-convex polygon in the plane of `normal` (its Newell normal): the
// corners in a ring of links, each ear tested against the reflex corners alone (a triangle
// holding another corner of a simple polygon holds a reflex one), and after each ear only its
// two neighbours change. Returns false when no ear is left (self-intersecting: the rest is
// fanned from its first remaining corner).
bool ClipLargePolygon(const std::vector<Vec3>& vertices, const std::vector<uint32_t>& corners,
                      const Vec3& normal, std::vector<std::array<uint32_t, 3>>* triangles) {
  const size_t n = corners.size();
  const Vec3 origin = vertices[corners[0]];
  std::vector<Vec3> at(n);
  for (size_t i = 0; i < n; ++i) at[i] = vertices[corners[i]] - origin;
  std::vector<size_t> prev(n), next(n);
  for (size_t i = 0; i < n; ++i) prev[i] = (i + n - 1) % n, next[i] = (i + 1) % n;
  std::vector<char> removed(n, 0), reflex(n, 0);
  auto turn = [&](size_t i) {
    const Vec3 &a = at[prev[i]], &b = at[i], &c = at[next[i]];
    return Dot(Cross(b - a, c - b), normal);
  };
  std::vector<size_t> reflexes;  // corners once reflex (a clipped ear's neighbour may turn convex)
  for (size_t i = 0; i < n; ++i)
    if (!(turn(i) > 0)) reflex[i] = 1, reflexes.push_back(i);
  auto is_ear = [&](size_t i) {
    if (reflex[i]) return false;
    const Vec3 &a = at[prev[i]], &b = at[i], &c = at[next[i]];
    for (const size_t j : reflexes) {
      if (removed[j] || !reflex[j] || j == prev[i] || j == next[i]) continue;
      const Vec3& p = at[j];
      if (p == a || p == b || p == c) continue;
      if (Dot(Cross(b - a, p - a), normal) >= 0 && Dot(Cross(c - b, p - b), normal) >= 0 &&
          Dot(Cross(a - c, p - c), normal) >= 0)
        return false;
    }
    return true;
  };
  auto unlink = [&](size_t i) {
    removed[i] = 1;
    next[prev[i]] = next[i], prev[next[i]] = prev[i];
    for (const size_t neighbour : {prev[i], next[i]}) {
      const bool now_reflex = !(turn(neighbour) > 0);
      if (now_reflex && !reflex[neighbour]) reflexes.push_back(neighbour);  // (crossing itself)
      reflex[neighbour] = now_reflex;
    }
  };
  size_t left = n, cursor = 1 % n, tried = 0;
  const double flattest = 1e-9;
  while (left > 3) {
    if (is_ear(cursor)) {
      triangles->push_back({corners[prev[cursor]], corners[cursor], corners[next[cursor]]});
      const size_t after = next[cursor];
      unlink(cursor);
      --left, cursor = after, tried = 0;
      // Drop the corners no longer reflex from the list now and then (it only shrinks).
      if (reflexes.size() > 64 && left * 2 < reflexes.size()) {
        reflexes.erase(std::remove_if(reflexes.begin(), reflexes.end(),
                                      [&](size_t j) { return removed[j] || !reflex[j]; }),
                       reflexes.end());
      }
      continue;
    }
    cursor = next[cursor];
    if (++tried <= left) continue;
    // A whole round without an ear: a straight corner (collinear with its neighbours, as
    // rounding leaves it) goes without a triangle, else the polygon crosses itself.
    size_t flat = n;
    for (size_t i = cursor, k = 0; k < left && flat == n; ++k, i = next[i]) {
      const double scale =
          Length(at[i] - at[prev[i]]) * Length(at[next[i]] - at[i]) * Length(normal);
      if (!(scale > 0) || std::fabs(turn(i)) <= flattest * scale) flat = i;
    }
    if (flat == n) {
      std::vector<uint32_t> rest;
      for (size_t i = cursor, k = 0; k < left; ++k, i = next[i]) rest.push_back(corners[i]);
      for (size_t i = 2; i < rest.size(); ++i)
        triangles->push_back({rest[0], rest[i - 1], rest[i]});
      return false;
    }
    cursor = next[flat];
    unlink(flat);
    --left, tried = 0;
  }
  triangles->push_back({corners[prev[cursor]], corners[cursor], corners[next[cursor]]});
  return true;
}

}  // namespace

bool TriangulatePolygon(const std::vector<Vec3>& vertices, const std::vector<uint32_t>& corners,
                        std::vector<std::array<uint32_t, 3>>* triangles) {
  const size_t n = corners.size();
  if (n < 3) return true;
  // Positions relative to the first corner (less cancellation far from the origin).
  const Vec3 origin = vertices[corners[0]];
  auto at = [&](uint32_t v) { return vertices[v] - origin; };
  Vec3 normal;  // Newell's: twice the vector area, robust to non-planar polygons
  for (size_t i = 0; i < n; ++i) {
    const Vec3 p = at(corners[i]), q = at(corners[(i + 1) % n]);
    normal += Vec3{(p.y - q.y) * (p.z + q.z), (p.z - q.z) * (p.x + q.x), (p.x - q.x) * (p.y + q.y)};
  }
  auto fan = [&](const std::vector<uint32_t>& around) {
    for (size_t i = 2; i < around.size(); ++i)
      triangles->push_back({around[0], around[i - 1], around[i]});
  };
  // No plane (a bow tie's areas cancel): nothing to clip in.
  if (!(Length2(normal) > 0) || !IsFinite(normal)) {
    fan(corners);
    return false;
  }
  // Convex (no corner turns against the normal): the fan, in linear time.
  bool convex = true;
  for (size_t i = 0; i < n && convex; ++i) {
    const Vec3 a = at(corners[(i + n - 1) % n]), b = at(corners[i]), c = at(corners[(i + 1) % n]);
    convex = Dot(Cross(b - a, c - b), normal) >= 0;
  }
  if (convex) {
    fan(corners);
    return true;
  }
  if (n > kMaxClippedCorners) {
    fan(corners);
    return false;
  }
  if (n > kMaxSearchedCorners) return ClipLargePolygon(vertices, corners, normal, triangles);
  std::vector<uint32_t> rest(corners);
  bool clipped_all = true;
  while (rest.size() > 3) {
    const size_t m = rest.size();
    // An ear: a convex corner whose triangle holds no other corner (on its edges included).
    // Tried from the second corner on, so that a convex polygon gives the fan of the first.
    size_t ear = m;
    for (size_t step = 0; step < m && ear == m; ++step) {
      const size_t i = (step + 1) % m;
      const Vec3 a = at(rest[(i + m - 1) % m]), b = at(rest[i]), c = at(rest[(i + 1) % m]);
      if (!(Dot(Cross(b - a, c - b), normal) > 0)) continue;
      bool empty = true;
      for (size_t j = 0; j < m && empty; ++j) {
        if (j == i || j == (i + 1) % m || j == (i + m - 1) % m) continue;
        const Vec3 p = at(rest[j]);
        if (p == a || p == b || p == c) continue;
        empty = !(Dot(Cross(b - a, p - a), normal) >= 0 && Dot(Cross(c - b, p - b), normal) >= 0 &&
                  Dot(Cross(a - c, p - c), normal) >= 0);
      }
      if (empty) ear = i;
    }
    // Else a straight corner (collinear with its neighbours, as rounding leaves it): its
    // triangle has no area, and removing it changes no other.
    const double flattest = 1e-9;
    if (ear == m) {
      size_t best = m;
      for (size_t i = 0; i < m; ++i) {
        const Vec3 a = at(rest[(i + m - 1) % m]), b = at(rest[i]), c = at(rest[(i + 1) % m]);
        const double scale = Length(b - a) * Length(c - b) * Length(normal);
        const double turn = std::fabs(Dot(Cross(b - a, c - b), normal));
        if (!(scale > 0) || turn <= flattest * scale) {
          best = i;
          break;
        }
      }
      ear = best;
    }
    if (ear == m) {
      clipped_all = false;  // self-intersecting: fanned below
      break;
    }
    triangles->push_back({rest[(ear + m - 1) % m], rest[ear], rest[(ear + 1) % m]});
    rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(ear));
  }
  fan(rest);
  return clipped_all;
}

bool IsDegenerateTriangle(const Vec3& a, const Vec3& b, const Vec3& c, double relative_epsilon) {
  const double longest =
      std::sqrt(std::max({Length2(b - a), Length2(c - b), Length2(a - c)}));  // [wu]
  double largest = 0;  // [wu] the largest |coordinate|
  for (const Vec3* p : {&a, &b, &c})
    largest = std::max({largest, std::fabs(p->x), std::fabs(p->y), std::fabs(p->z)});
  // Twice the area is the height times the longest edge. Each coordinate is off by up to half
  // an epsilon of itself, which moves the computed cross product by a few epsilons of the
  // largest coordinate times the edge.
  const double rounding = 8 * std::numeric_limits<double>::epsilon() * largest;
  return !(Length(Cross(b - a, c - a)) > longest * (relative_epsilon * longest + rounding));
}

size_t RemoveDegenerateTriangles(TriangleMesh* mesh, double relative_epsilon) {
  size_t kept = 0;
  for (size_t t = 0; t < mesh->triangles.size(); ++t) {
    const auto& tri = mesh->triangles[t];
    const bool repeated = tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2];
    if (repeated || IsDegenerateTriangle(mesh->vertices[tri[0]], mesh->vertices[tri[1]],
                                         mesh->vertices[tri[2]], relative_epsilon))
      continue;
    mesh->triangles[kept++] = tri;
  }
  const size_t removed = mesh->triangles.size() - kept;
  mesh->triangles.resize(kept);
  return removed;
}

namespace {

// The point of triangle abc nearest to p, by the Voronoi region of p (after Ericson, "Real-Time
// Collision Detection", 5.1.5).
Vec3 NearestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = Dot(ab, ap), d2 = Dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = Dot(ab, bp), d4 = Dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = Dot(ab, cp), d6 = Dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

}  // namespace

Vec3 NearestSurfacePoint(const TriangleMesh& mesh, const Vec3& q) {
  Vec3 best = q;
  double best2 = std::numeric_limits<double>::infinity();
  auto consider = [&](const Vec3& p) {
    const double d2 = Length2(p - q);
    if (d2 < best2) best2 = d2, best = p;
  };
  if (mesh.triangles.empty()) {
    for (const Vec3& v : mesh.vertices) consider(v);
    return best;
  }
  for (const auto& tri : mesh.triangles) {
    consider(
        NearestOnTriangle(q, mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]));
  }
  return best;
}

size_t CropToBox(TriangleMesh* mesh, const Vec3& lo, const Vec3& hi) {
  constexpr uint32_t kUnused = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> renumbered(mesh->vertices.size(), kUnused);
  std::vector<Vec3> vertices;
  size_t kept = 0;
  for (size_t t = 0; t < mesh->triangles.size(); ++t) {
    const auto& tri = mesh->triangles[t];
    Vec3 tlo = mesh->vertices[tri[0]], thi = tlo;
    for (uint32_t v : tri) {
      const Vec3& p = mesh->vertices[v];
      tlo = {std::min(tlo.x, p.x), std::min(tlo.y, p.y), std::min(tlo.z, p.z)};
      thi = {std::max(thi.x, p.x), std::max(thi.y, p.y), std::max(thi.z, p.z)};
    }
    if (thi.x < lo.x || thi.y < lo.y || thi.z < lo.z || tlo.x > hi.x || tlo.y > hi.y ||
        tlo.z > hi.z)
      continue;
    std::array<uint32_t, 3> out;
    for (int k = 0; k < 3; ++k) {
      uint32_t& id = renumbered[tri[k]];
      if (id == kUnused) {
        id = static_cast<uint32_t>(vertices.size());
        vertices.push_back(mesh->vertices[tri[k]]);
      }
      out[k] = id;
    }
    mesh->triangles[kept++] = out;
  }
  const size_t removed = mesh->triangles.size() - kept;
  mesh->triangles.resize(kept);
  mesh->vertices.swap(vertices);
  return removed;
}

}  // namespace footfall
