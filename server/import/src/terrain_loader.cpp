#include "footfall/import/terrain_loader.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "footfall/import/height_map.h"
#include "footfall/import/mesh_reader.h"
#include "footfall/import/mesh_sampler.h"
#include "footfall/terrain/file_extension.h"
#include "footfall/terrain/input_file.h"
#include "footfall/terrain/large_memory.h"
#include "footfall/terrain/point_file.h"
#include "footfall/terrain/text_stream.h"

namespace footfall {

bool IsPointFileExtension(const std::string& lower_extension) {
  return lower_extension == "pts" || lower_extension == "xyz" || lower_extension == "txt";
}

namespace {

Status CheckOptions(const TerrainLoadOptions& o, std::string* error) {
  std::string what;
  if (!(std::isfinite(o.separation) && o.separation >= 0))
    what = "separation must be a finite number >= 0";
  if (!(std::isfinite(o.finest_default) && o.finest_default >= 0))
    what = "finest default separation must be a finite number >= 0";
  if (!(std::isfinite(o.cell_size) && o.cell_size >= 0))
    what = "cell size must be a finite number >= 0";
  if (!std::isfinite(o.height_scale)) what = "height scale must be finite";
  if (o.up_axis != 'x' && o.up_axis != 'y' && o.up_axis != 'z') what = "up axis must be x, y or z";
  if (!(o.crease_angle_deg >= 0 && o.crease_angle_deg <= 180))
    what = "crease angle must be from 0 to 180 degrees";
  if (what.empty()) return Status::kOk;
  if (error) *error = what;
  return Status::kInvalidArgument;
}

void Bounds(const RawSamples& samples, Vec3* lo, Vec3* hi) {
  *lo = *hi = samples.size() ? samples.points[0] : Vec3{};
  for (const Vec3& p : samples.points) {
    lo->x = std::min(lo->x, p.x), lo->y = std::min(lo->y, p.y), lo->z = std::min(lo->z, p.z);
    hi->x = std::max(hi->x, p.x), hi->y = std::max(hi->y, p.y), hi->z = std::max(hi->z, p.z);
  }
}

Status LoadAny(const std::string& path, const std::string& ext, const TerrainLoadOptions& options,
               RawSamples* out, std::string* error, TerrainLoadReport* report) {
  if (IsPointFileExtension(ext)) {
    report->format = "points";
    Status status = CheckHeightMapOnly(path, ext, options, error);
    if (status != Status::kOk) return status;
    status = ReadPointFile(path, out, error);
    if (status == Status::kOk && out->size() == 0) {
      if (error) *error = path + ": no samples (expected at least one line x y z nx ny nz)";
      return Status::kParseError;
    }
    return status;
  }
  TriangleMesh mesh;
  const Status status = ReadTerrainMesh(path, options, &mesh, error, report);
  if (status != Status::kOk) return status;
  return ResampleTerrainMesh(path, mesh, options, out, error, report);
}

}  // namespace

Status CheckHeightMapOnly(const std::string& path, const std::string& ext,
                          const TerrainLoadOptions& o, std::string* error) {
  if (ext == "asc" || ext == "pgm" || (o.cell_size == 0 && o.height_scale == 1)) return Status::kOk;
  if (error)
    *error = path +
             ": a cell size or height scale (--cell-size, --height-scale) applies to "
             "height maps (.asc .pgm) only, not to " +
             (IsPointFileExtension(ext) ? "a point file" : "a mesh");
  return Status::kInvalidArgument;
}

Status ReadTerrainMesh(const std::string& path, const TerrainLoadOptions& options,
                       TriangleMesh* mesh, std::string* error, TerrainLoadReport* report) {
  *mesh = TriangleMesh{};
  Status status = CheckOptions(options, error);
  if (status != Status::kOk) return status;
  const std::string ext = FileExtension(path);
  if (!IsPointFileExtension(ext)) {
    status = CheckInputFile(path, "terrain file", error);
    if (status != Status::kOk) return status;
  }
  if (IsPointFileExtension(ext)) {
    if (error) *error = path + ": a point file, not a mesh or height map";
    return Status::kInvalidArgument;
  }
  if (IsMeshExtension(ext)) {
    report->format = "mesh";
    status = CheckHeightMapOnly(path, ext, options, error);
    if (status != Status::kOk) return status;
    MeshReadReport read;
    status = ReadMesh(path, mesh, error, &read);
    if (status != Status::kOk) return status;
    report->vertices = read.vertices;
    report->faces = read.faces;
    report->skipped_faces = read.skipped_faces;
    report->rewound_faces = read.turned_faces;
    report->file_separation = DefaultSeparation(*mesh);
    const Vec3 up{options.up_axis == 'x' ? 1.0 : 0.0, options.up_axis == 'y' ? 1.0 : 0.0,
                  options.up_axis == 'z' ? 1.0 : 0.0};
    report->turnover = TurnOutward(mesh, up);
    return Status::kOk;
  }
  if (ext == "asc" || ext == "pgm") {
    report->format = "heightmap";
    HeightMap map;
    status = ext == "asc" ? ReadAscGrid(path, &map, error, options.cell_size > 0)
                          : ReadPgm(path, &map, error);
    if (status != Status::kOk) return status;
    HeightMapFrame frame;
    frame.cell_size = options.cell_size > 0 ? options.cell_size : map.cell_size;
    frame.height_scale = options.height_scale;
    frame.up_axis = options.up_axis;
    std::string why;
    status = HeightMapToMesh(map, frame, mesh, &why);
    if (status != Status::kOk) {
      if (error) *error = path + ": " + why;
      return status;
    }
    report->vertices = mesh->vertices.size();
    report->nodata_cells = map.heights.size() - map.ValidCount();
    report->skipped_faces = RemoveDegenerateTriangles(mesh);
    report->faces = mesh->triangles.size();
    report->file_separation = frame.cell_size;
    // Each triangle of the grid covers half a cell.
    const double covered =
        0.5 * static_cast<double>(report->faces) * frame.cell_size * frame.cell_size;
    if (covered > 0) report->surface_ratio = SurfaceArea(*mesh) / covered;
    if (mesh->triangles.empty() && report->skipped_faces > 0) {
      if (error)
        *error = path + ": all " + std::to_string(report->skipped_faces) +
                 " triangles of the grid are degenerate, too thin for their length (heights far "
                 "larger than the cell size: check --height-scale and --cell-size)";
      return Status::kParseError;
    }
    if (mesh->triangles.empty()) {
      if (error) *error = path + ": no square of the grid has three cells with data";
      return Status::kParseError;
    }
    return Status::kOk;
  }
  if (error && ext == "om") {
    // OpenMesh's reader of its own binary format asserts on malformed files: the process
    // would abort (footfalld with it).
    *error = path +
             ": OpenMesh's .om format is not read (its reader aborts on a damaged file); export "
             "the mesh as .obj, .ply, .off or .stl";
  } else if (error) {
    *error = path + ": unknown terrain file extension '" + ext +
             "' (expected points .pts .xyz .txt, meshes .obj .ply .off .stl, height maps "
             ".asc .pgm)";
  }
  return Status::kInvalidArgument;
}

Status ResampleTerrainMesh(const std::string& path, const TriangleMesh& mesh,
                           const TerrainLoadOptions& options, RawSamples* out, std::string* error,
                           TerrainLoadReport* report) {
  out->clear();
  const double file_separation = report->file_separation;
  MeshSampleOptions sample;
  // At most what this process's memory holds while sampling (the CLI ran for seconds, then
  // died with a bare "out of memory").
  const double memory = UsableMemoryBytes();
  const size_t fits_memory =
      memory > 0 ? static_cast<size_t>(
                       std::max(1000.0, memory / static_cast<double>(kSamplingBytesPerSample)))
                 : SIZE_MAX;
  sample.max_samples = std::min(options.max_samples, fits_memory);
  sample.separation = options.separation > 0 ? options.separation : file_separation;
  if (!(options.separation > 0) && options.finest_default > 0) {
    // The finer of the file's default and finest_default, unless the sample budget needs
    // coarser (1.001: a margin for the estimate's rounding).
    const double fits =
        1.001 * std::sqrt(1.6 * SurfaceArea(mesh) / std::max<double>(1, sample.max_samples));
    sample.separation = std::max(std::min(file_separation, options.finest_default), fits);
  }
  sample.smooth_normals = options.smooth_normals;
  sample.crease_angle_deg = options.crease_angle_deg;
  sample.seed = options.seed;
  sample.threads = options.threads;
  std::string why;
  const Status status = SampleMesh(mesh, sample, out, &why);
  if (status == Status::kLimitExceeded && fits_memory < options.max_samples)
    why += " (the limit is what this process's memory holds while sampling: " +
           std::to_string(static_cast<long long>(memory / (1 << 20))) + " MB)";
  if (status != Status::kOk) {
    if (status == Status::kLimitExceeded && report->format == "heightmap") {
      // A grid far narrower than its heights are tall: most likely cells in degrees (a
      // geographic grid) under heights in metres, whose separation advice makes a spike.
      const int up = options.up_axis == 'x' ? 0 : options.up_axis == 'z' ? 2 : 1;
      double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
      for (const Vec3& v : mesh.vertices) {
        const double p[3] = {v.x, v.y, v.z};
        for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
      }
      double across = 0;
      for (int a = 0; a < 3; ++a)
        if (a != up) across = std::max(across, hi[a] - lo[a]);
      const double tall = hi[up] - lo[up];
      auto shown = [](double x) {  // 3 significant digits, in any locale
        char text[32];
        const auto end = std::to_chars(text, text + sizeof text, x, std::chars_format::general, 3);
        return std::string(text, end.ptr);
      };
      const bool thin = why.find("long and thin") != std::string::npos;
      if (thin)
        why +=
            " (a height map's cells are thin when its heights are far larger than its cell "
            "size: check --height-scale and --cell-size";
      if (tall > 10 * across)
        why += std::string(thin ? "; the" : " (but the") + " grid is " + shown(across) +
               " across under heights spanning " + shown(tall) +
               ": if its cells are in degrees, as a geographic grid's, give --cell-size in the "
               "heights' units, for example metres";
      if (thin || tall > 10 * across) why += ")";
    }
    if (error) *error = path + ": " + why;
    return status;
  }
  report->area = SurfaceArea(mesh);
  report->separation = sample.separation;
  report->samples = out->size();
  Bounds(*out, &report->bounds_min, &report->bounds_max);
  return Status::kOk;
}

std::string DescribeTurnover(const TerrainLoadReport& report) {
  const MeshTurnover& t = report.turnover;
  auto faces = [](size_t n) { return std::to_string(n) + (n == 1 ? " face" : " faces"); };
  // MeshTurnover counts the triangles the polygons were cut into.
  auto triangles = [](size_t n) {
    return std::to_string(n) + (n == 1 ? " triangle" : " triangles");
  };
  std::vector<std::string> parts;
  if (report.rewound_faces > 0)
    parts.push_back(faces(report.rewound_faces) +
                    (report.rewound_faces == 1 ? " wound against its neighbours"
                                               : " wound against their neighbours") +
                    " turned to match them");
  if (t.inside_out_shells > 0)
    parts.push_back(std::to_string(t.inside_out_shells) + " of " + std::to_string(t.closed_shells) +
                    " closed shells inside out");
  if (t.open_faced_down)
    parts.push_back("the " + triangles(t.open_faces) + " of its open parts faced down");
  std::string text;
  for (const std::string& part : parts) text += (text.empty() ? "" : "; ") + part;
  if (t.turned_faces > 0) text += ": " + triangles(t.turned_faces) + " turned over";
  return text;
}

std::string DescribeSkippedFaces(const TerrainLoadReport& report) {
  const size_t n = report.skipped_faces;
  if (n == 0) return "";
  if (report.format == "heightmap") {
    return std::to_string(n) + (n == 1 ? " triangle" : " triangles") +
           " of the grid left out, too thin for " + (n == 1 ? "its" : "their") +
           " length (check --height-scale and --cell-size)";
  }
  return std::to_string(n) + " of " + std::to_string(report.faces) +
         " faces left out (a vertex used twice, a face listed again, or no area)";
}

std::string DescribeSteepHeightMap(const TerrainLoadReport& report) {
  if (report.format != "heightmap" || !(report.surface_ratio > kSteepHeightMapRatio)) return "";
  TextStream m(3);
  m << "its surface is " << report.surface_ratio << " times the area it covers (slopes of about "
    << std::acos(1 / report.surface_ratio) * 180 / 3.14159265358979323846
    << " degrees on average, steeper than ground): its cells, " << report.file_separation
    << " apart, are likely not in its heights' unit (a .pgm's cells are 1 apart, an SRTM grid's "
       "3 arc-seconds about 90 m): give --cell-size in the heights' unit, or --height-scale";
  return m.str();
}

Status LoadTerrain(const std::string& path, const TerrainLoadOptions& options, RawSamples* out,
                   std::string* error, TerrainLoadReport* report) {
  out->clear();
  TerrainLoadReport local;
  if (!report) report = &local;
  *report = TerrainLoadReport{};
  Status status = CheckOptions(options, error);
  if (status == Status::kOk) {
    status = LoadAny(path, FileExtension(path), options, out, error, report);
  }
  if (status != Status::kOk) {
    out->clear();
    return status;
  }
  report->samples = out->size();
  Bounds(*out, &report->bounds_min, &report->bounds_max);
  return Status::kOk;
}

}  // namespace footfall
