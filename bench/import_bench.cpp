// Mesh resampling speed on a generated 1M-triangle rocky height field (MakeRocksMesh, 708 x 708
// cells, 1,002,528 triangles, 100 x 100 wu). Counters report samples per second:
//   BM_SampleMesh        Poisson-disk resampling at the separation (mesh_sampler.h)
//   BM_UniformRandom     baseline: as many uniform random surface points, no spacing guarantee
//   BM_VertexExtraction  baseline: copying the vertices with their vertex normals
// Compare the rates within one run (same machine, same load).
#include <benchmark/benchmark.h>

#include "footfall/import/mesh_generators.h"
#include "footfall/import/mesh_sampler.h"

namespace {

const footfall::TriangleMesh& Mesh() {
  static const footfall::TriangleMesh mesh = footfall::MakeRocksMesh(708, 100.0 / 708, 2.0, 7);
  return mesh;
}

// Separation in wu: 0.1 gives about 1.7M samples, 0.2 about 0.4M.
void BM_SampleMesh(benchmark::State& state) {
  const footfall::TriangleMesh& mesh = Mesh();
  footfall::MeshSampleOptions options;
  options.separation = state.range(0) / 1000.0;
  footfall::RawSamples samples;
  footfall::MeshSampleStats stats;
  for (auto _ : state) {
    footfall::SampleMesh(mesh, options, &samples, nullptr, &stats);
    benchmark::DoNotOptimize(samples.points.data());
  }
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
  state.counters["samples"] = static_cast<double>(stats.samples);
  state.counters["candidates"] = static_cast<double>(stats.candidates);
  state.counters["samples_per_s"] = benchmark::Counter(
      static_cast<double>(stats.samples) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SampleMesh)->Arg(100)->Arg(200)->Unit(benchmark::kMillisecond);

void BM_UniformRandom(benchmark::State& state) {
  const footfall::TriangleMesh& mesh = Mesh();
  const size_t count = static_cast<size_t>(state.range(0));
  footfall::RawSamples samples;
  for (auto _ : state) {
    footfall::SampleMeshUniform(mesh, count, true, footfall::kDefaultCreaseAngleDeg, 1, &samples);
    benchmark::DoNotOptimize(samples.points.data());
  }
  state.counters["samples_per_s"] = benchmark::Counter(
      static_cast<double>(count) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_UniformRandom)->Arg(1000000)->Unit(benchmark::kMillisecond);

void BM_VertexExtraction(benchmark::State& state) {
  const footfall::TriangleMesh& mesh = Mesh();
  footfall::RawSamples samples;
  for (auto _ : state) {
    const std::vector<footfall::Vec3> normals = footfall::VertexNormals(mesh);
    samples.clear();
    for (size_t v = 0; v < mesh.vertices.size(); ++v)
      samples.push_back(mesh.vertices[v], normals[v]);
    benchmark::DoNotOptimize(samples.points.data());
  }
  state.counters["samples_per_s"] = benchmark::Counter(
      static_cast<double>(mesh.vertices.size()) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_VertexExtraction)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
