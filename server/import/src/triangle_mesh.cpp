#include "footfall/import/triangle_mesh.h"

#include <algorithm>

namespace footfall {

Vec3 TriangleCross(const TriangleMesh& mesh, size_t t) {
  const auto& tri = mesh.triangles[t];
  const Vec3& a = mesh.vertices[tri[0]];
  return Cross(mesh.vertices[tri[1]] - a, mesh.vertices[tri[2]] - a);
}

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

void MeshBounds(const TriangleMesh& mesh, Vec3* lo, Vec3* hi) {
  if (mesh.vertices.empty()) {
    *lo = *hi = Vec3{};
    return;
  }
  *lo = *hi = mesh.vertices[0];
  for (const Vec3& v : mesh.vertices) {
    lo->x = std::min(lo->x, v.x), lo->y = std::min(lo->y, v.y), lo->z = std::min(lo->z, v.z);
    hi->x = std::max(hi->x, v.x), hi->y = std::max(hi->y, v.y), hi->z = std::max(hi->z, v.z);
  }
}

size_t RemoveDegenerateTriangles(TriangleMesh* mesh, double relative_epsilon) {
  Vec3 lo, hi;
  MeshBounds(*mesh, &lo, &hi);
  const double limit = relative_epsilon * Length2(hi - lo);
  size_t kept = 0;
  for (size_t t = 0; t < mesh->triangles.size(); ++t) {
    const auto& tri = mesh->triangles[t];
    const bool repeated = tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2];
    if (repeated || !(0.5 * Length(TriangleCross(*mesh, t)) > limit)) continue;
    mesh->triangles[kept++] = tri;
  }
  const size_t removed = mesh->triangles.size() - kept;
  mesh->triangles.resize(kept);
  return removed;
}

}  // namespace footfall
