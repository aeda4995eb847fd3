#include "footfall/import/terrain_generators.h"

#include <algorithm>
#include <cmath>

#include "footfall/import/mesh_generators.h"
#include "footfall/import/mesh_sampler.h"
#include "footfall/terrain/samples.h"
#include "footfall/terrain/text_stream.h"

namespace footfall {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Deterministic smooth noise: a sum of a few sinusoids with seeded phases and frequencies.
struct Waves {
  explicit Waves(uint64_t seed) {
    uint64_t s = seed * 6364136223846793005ull + 1442695040888963407ull;
    auto next = [&s] {
      s ^= s >> 33, s *= 0xff51afd7ed558ccdull, s ^= s >> 33;
      return static_cast<double>(s >> 11) / 9007199254740992.0;
    };
    for (int i = 0; i < 4; ++i) {
      fx[i] = (0.05 + 0.25 * next()) * (i + 1);
      fz[i] = (0.05 + 0.25 * next()) * (i + 1);
      phase[i] = 2 * kPi * next();
    }
  }
  double Height(double x, double z) const {
    double h = 0;
    for (int i = 0; i < 4; ++i) h += std::sin(fx[i] * x + fz[i] * z + phase[i]) / (i + 1);
    return h;
  }
  double fx[4], fz[4], phase[4];
};

}  // namespace

namespace {

// y = amplitude * noise(x / unit, z / unit) on an nx x nz lattice of `spacing`.
RawSamples NoiseField(int nx, int nz, double spacing, double unit, double amplitude,
                      uint64_t seed) {
  RawSamples s;
  const Waves w(seed);
  const double e = 1e-4;
  const double scale = spacing / unit;  // noise units per sample
  for (int k = 0; k < nz; ++k) {
    for (int i = 0; i < nx; ++i) {
      const double u = i * scale, v = k * scale;
      const double h = amplitude * w.Height(u, v);
      const double dhdx = amplitude * (w.Height(u + e, v) - w.Height(u - e, v)) / (2 * e) / unit;
      const double dhdz = amplitude * (w.Height(u, v + e) - w.Height(u, v - e)) / (2 * e) / unit;
      s.push_back({i * spacing, h, k * spacing}, Normalize(Vec3{-dhdx, 1, -dhdz}));
    }
  }
  return s;
}

}  // namespace

RawSamples MakeHeightField(int nx, int nz, double spacing, double amplitude, uint64_t seed) {
  return NoiseField(nx, nz, spacing, spacing, amplitude, seed);
}

RawSamples MakeHills(int n, double spacing, double amplitude, uint64_t seed) {
  return NoiseField(n, n, spacing, kHillsUnit, amplitude, seed);
}

RawSamples MakeSphere(int count, const Vec3& centre, double radius) {
  RawSamples s;
  const double golden = kPi * (3 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double y = 1 - 2 * (i + 0.5) / count;
    const double r = std::sqrt(std::max(0.0, 1 - y * y));
    const double t = golden * i;
    const Vec3 n{r * std::cos(t), y, r * std::sin(t)};
    s.push_back(centre + n * radius, n);
  }
  return s;
}

RawSamples MakeStairs(int steps, double rise, double run, double width, double spacing) {
  RawSamples s;
  const int across = std::max(1, static_cast<int>(std::round(width / spacing)));
  const int along = std::max(1, static_cast<int>(std::round(run / spacing)));
  const int up = std::max(1, static_cast<int>(std::round(std::fabs(rise) / spacing)));
  // Risers face the way down: -z on stairs rising along +z, +z on stairs falling along it.
  const Vec3 riser_normal{0, 0, rise > 0 ? -1.0 : 1.0};
  for (int step = 0; step < steps; ++step) {
    const double y = step * rise + 0.0, z0 = step * run;  // (+ 0.0: no -0 for a negative rise)
    for (int a = 0; a <= across; ++a) {
      const double x = a * width / across;
      for (int b = 0; b < along; ++b) s.push_back({x, y, z0 + b * run / along}, {0, 1, 0});
      if (step + 1 < steps) {
        for (int c = 1; c < up; ++c) s.push_back({x, y + c * rise / up, z0 + run}, riser_normal);
      }
    }
  }
  return s;
}

RawSamples MakeRoom(const Vec3& size, double spacing) {
  RawSamples s;
  auto count = [spacing](double len) {
    return std::max(1, static_cast<int>(std::round(len / spacing)));
  };
  const int nx = count(size.x), ny = count(size.y), nz = count(size.z);
  for (int i = 0; i <= nx; ++i) {
    for (int k = 0; k <= nz; ++k) {
      const double x = size.x * i / nx, z = size.z * k / nz;
      s.push_back({x, 0, z}, {0, 1, 0});
      s.push_back({x, size.y, z}, {0, -1, 0});
    }
  }
  for (int j = 1; j < ny; ++j) {
    const double y = size.y * j / ny;
    for (int i = 0; i <= nx; ++i) {
      const double x = size.x * i / nx;
      s.push_back({x, y, 0}, {0, 0, 1});
      s.push_back({x, y, size.z}, {0, 0, -1});
    }
    for (int k = 1; k < nz; ++k) {
      const double z = size.z * k / nz;
      s.push_back({0, y, z}, {1, 0, 0});
      s.push_back({size.x, y, z}, {-1, 0, 0});
    }
  }
  return s;
}

RawSamples MakeFlat(int n, double spacing, double y) {
  RawSamples s;
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < n; ++i) s.push_back({i * spacing, y, k * spacing}, {0, 1, 0});
  return s;
}

RawSamples MakeRamp(int nx, int nz, double spacing, double slope_deg) {
  RawSamples s;
  const double a = slope_deg * kPi / 180;
  const Vec3 along{0, std::sin(a), std::cos(a)};
  const Vec3 normal{0, std::cos(a), -std::sin(a)};
  for (int k = 0; k < nz; ++k)
    for (int i = 0; i < nx; ++i)
      s.push_back(Vec3{i * spacing, 0, 0} + along * (k * spacing), normal);
  return s;
}

namespace {

RawSamples Sample(const TriangleMesh& mesh, double spacing, bool smooth, uint64_t seed,
                  size_t max_samples, std::string* error) {
  MeshSampleOptions options;
  options.separation = spacing;
  options.max_samples = max_samples;
  options.smooth_normals = smooth;
  options.seed = seed;
  RawSamples s;
  SampleMesh(mesh, options, &s, error);  // empty on a bad spacing
  return s;
}

}  // namespace

RawSamples MakeBlocks(int nx, int nz, int max_height, double spacing, uint64_t seed,
                      std::string* error, size_t max_samples) {
  return Sample(MakeBlocksMesh(nx, nz, max_height, seed), spacing, false, seed, max_samples, error);
}

RawSamples MakeRamps(const std::vector<double>& slopes_deg, double length, double width,
                     double spacing, std::string* error, size_t max_samples) {
  return Sample(MakeRampsMesh(slopes_deg, length, width), spacing, false, 1, max_samples, error);
}

RawSamples MakeRocks(double size, double amplitude, double spacing, uint64_t seed,
                     std::string* error, size_t max_samples) {
  const int n = std::max(1, static_cast<int>(std::ceil(size / std::min(spacing, 0.25))));
  const TriangleMesh mesh = MakeRocksMesh(n, size / n, amplitude, seed);
  // Rocks reaching beyond the grid's range are refused before they are sampled: sampling
  // slivers 1e40 high took minutes, only for the samples to be refused.
  double reach = 0;
  for (const Vec3& v : mesh.vertices)
    reach = std::max({reach, std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
  if (!(reach <= terrain::kMaxCoordinate)) {
    TextStream m;
    m << "the parameters give coordinates beyond " << terrain::kMaxCoordinate << " (" << reach
      << "), out of the grid's range";
    if (error) *error = m.str();
    return {};
  }
  return Sample(mesh, spacing, true, seed, max_samples, error);
}

}  // namespace footfall
