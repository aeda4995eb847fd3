#include "footfall/import/mesh_generators.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace footfall {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A hash of a lattice point and the seed, uniform in [0, 1).
double LatticeValue(int64_t x, int64_t z, uint64_t seed) {
  uint64_t h = seed * 0x9e3779b97f4a7c15ull ^ static_cast<uint64_t>(x) * 0xbf58476d1ce4e5b9ull ^
               static_cast<uint64_t>(z) * 0x94d049bb133111ebull;
  h ^= h >> 31, h *= 0xd6e8feb86659fd93ull, h ^= h >> 32, h *= 0xd6e8feb86659fd93ull, h ^= h >> 32;
  return static_cast<double>(h >> 11) / 9007199254740992.0;
}

// Smoothly interpolated value noise in [0, 1) at (x, z), lattice spacing 1.
double ValueNoise(double x, double z, uint64_t seed) {
  const double fx = std::floor(x), fz = std::floor(z);
  const int64_t ix = static_cast<int64_t>(fx), iz = static_cast<int64_t>(fz);
  auto smooth = [](double t) { return t * t * (3 - 2 * t); };
  const double tx = smooth(x - fx), tz = smooth(z - fz);
  const double a = LatticeValue(ix, iz, seed), b = LatticeValue(ix + 1, iz, seed);
  const double c = LatticeValue(ix, iz + 1, seed), d = LatticeValue(ix + 1, iz + 1, seed);
  return (a + (b - a) * tx) * (1 - tz) + (c + (d - c) * tx) * tz;
}

uint32_t AddVertex(TriangleMesh* mesh, const Vec3& v) {
  mesh->vertices.push_back(v);
  return static_cast<uint32_t>(mesh->vertices.size() - 1);
}

// Two triangles over the quad a b c d (in order around it), wound so they face `outward`.
void AddQuad(TriangleMesh* mesh, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
             const Vec3& outward) {
  const uint32_t ia = AddVertex(mesh, a), ib = AddVertex(mesh, b), ic = AddVertex(mesh, c),
                 id = AddVertex(mesh, d);
  if (Dot(Cross(b - a, c - a), outward) >= 0) {
    mesh->triangles.push_back({ia, ib, ic}), mesh->triangles.push_back({ia, ic, id});
  } else {
    mesh->triangles.push_back({ia, ic, ib}), mesh->triangles.push_back({ia, id, ic});
  }
}

}  // namespace

TriangleMesh MakeStairsMesh(int steps, double rise, double run, double width) {
  TriangleMesh mesh;
  const Vec3 up{0, 1, 0}, back{0, 0, -1};
  AddQuad(&mesh, {0, 0, -3 * run}, {width, 0, -3 * run}, {width, 0, 0}, {0, 0, 0}, up);
  for (int k = 0; k < steps; ++k) {
    const double y0 = k * rise, y1 = y0 + rise, z0 = k * run, z1 = z0 + run;
    AddQuad(&mesh, {0, y0, z0}, {width, y0, z0}, {width, y1, z0}, {0, y1, z0}, back);
    AddQuad(&mesh, {0, y1, z0}, {width, y1, z0}, {width, y1, z1}, {0, y1, z1}, up);
  }
  return mesh;
}

TriangleMesh MakeBlocksMesh(int nx, int nz, int max_height, uint64_t seed) {
  TriangleMesh mesh;
  std::vector<int> height(static_cast<size_t>(std::max(nx, 0)) * std::max(nz, 0));
  for (int k = 0; k < nz; ++k) {
    for (int i = 0; i < nx; ++i) {
      // Piles: noise on a coarse lattice, sharpened, so heights cluster.
      const double n = ValueNoise(i / 3.0, k / 3.0, seed);
      height[static_cast<size_t>(k) * nx + i] = std::clamp(
          static_cast<int>(std::floor((n * 1.6 - 0.4) * (max_height + 1))), 0, max_height);
    }
  }
  auto at = [&](int i, int k) {
    return i < 0 || k < 0 || i >= nx || k >= nz ? 0 : height[static_cast<size_t>(k) * nx + i];
  };
  for (int k = 0; k < nz; ++k) {
    for (int i = 0; i < nx; ++i) {
      const int h = at(i, k);
      const double x = i, z = k, y = h;
      AddQuad(&mesh, {x, y, z}, {x + 1, y, z}, {x + 1, y, z + 1}, {x, y, z + 1}, {0, 1, 0});
      const int di[4] = {1, -1, 0, 0}, dk[4] = {0, 0, 1, -1};
      for (int side = 0; side < 4; ++side) {
        const int lower = at(i + di[side], k + dk[side]);
        const Vec3 out{static_cast<double>(di[side]), 0, static_cast<double>(dk[side])};
        // The side's edge on the column's boundary, from p to q.
        const double px = di[side] > 0 ? x + 1 : x, pz = dk[side] > 0 ? z + 1 : z;
        const double qx = di[side] != 0 ? px : x + 1, qz = dk[side] != 0 ? pz : z + 1;
        for (int level = lower; level < h; ++level) {
          AddQuad(&mesh, {px, level + 0.0, pz}, {qx, level + 0.0, qz}, {qx, level + 1.0, qz},
                  {px, level + 1.0, pz}, out);
        }
      }
    }
  }
  return mesh;
}

TriangleMesh MakeRampsMesh(const std::vector<double>& slopes_deg, double length, double width) {
  TriangleMesh mesh;
  std::vector<std::pair<double, double>> profile{{0, 0}, {length, 0}};  // (z, y)
  for (double slope : slopes_deg) {
    const auto [z, y] = profile.back();
    profile.push_back({z + length, y + length * std::tan(slope * kPi / 180)});
  }
  profile.push_back({profile.back().first + length, profile.back().second});
  for (const auto& [z, y] : profile) {
    AddVertex(&mesh, {0, y, z}), AddVertex(&mesh, {width, y, z});
  }
  for (uint32_t s = 0; s + 1 < profile.size(); ++s) {
    const uint32_t a = 2 * s, b = 2 * s + 1, c = 2 * s + 2, d = 2 * s + 3;
    // (a, c, d) and (a, d, b): wound to face up, towards -z on the rising part.
    mesh.triangles.push_back({a, c, d}), mesh.triangles.push_back({a, d, b});
  }
  return mesh;
}

TriangleMesh MakeRocksMesh(int n, double cell, double amplitude, uint64_t seed) {
  TriangleMesh mesh;
  for (int k = 0; k <= n; ++k) {
    for (int i = 0; i <= n; ++i) {
      const double x = i * cell, z = k * cell;
      double h = 0, weight = 1, total = 0, frequency = 1 / 3.0;
      for (int octave = 0; octave < 4; ++octave) {
        const double ridge =
            1 - std::abs(2 * ValueNoise(x * frequency, z * frequency, seed + octave) - 1);
        h += weight * ridge * ridge, total += weight;
        weight *= 0.5, frequency *= 2.1;
      }
      AddVertex(&mesh, {x, amplitude * h / total, z});
    }
  }
  const uint32_t row = static_cast<uint32_t>(n + 1);
  for (uint32_t k = 0; k < static_cast<uint32_t>(n); ++k) {
    for (uint32_t i = 0; i < static_cast<uint32_t>(n); ++i) {
      const uint32_t nw = k * row + i, ne = nw + 1, sw = nw + row, se = sw + 1;
      mesh.triangles.push_back({nw, sw, ne}), mesh.triangles.push_back({ne, sw, se});
    }
  }
  return mesh;
}

TriangleMesh MakeSphereMesh(const Vec3& centre, double radius, int subdivisions) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> unit = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                            {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                            {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& v : unit) v = Normalize(v);
  std::vector<std::array<uint32_t, 3>> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    auto middle = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto found = midpoints.find(key);
      if (found != midpoints.end()) return found->second;
      unit.push_back(Normalize(unit[a] + unit[b]));
      const uint32_t id = static_cast<uint32_t>(unit.size() - 1);
      midpoints.emplace(key, id);
      return id;
    };
    std::vector<std::array<uint32_t, 3>> finer;
    finer.reserve(faces.size() * 4);
    for (const auto& f : faces) {
      const uint32_t ab = middle(f[0], f[1]), bc = middle(f[1], f[2]), ca = middle(f[2], f[0]);
      finer.push_back({f[0], ab, ca}), finer.push_back({f[1], bc, ab});
      finer.push_back({f[2], ca, bc}), finer.push_back({ab, bc, ca});
    }
    faces.swap(finer);
  }
  TriangleMesh mesh;
  for (const Vec3& v : unit) mesh.vertices.push_back(centre + v * radius);
  mesh.triangles = faces;
  return mesh;
}

}  // namespace footfall
