#include "footfall/import/mesh_reader.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <mutex>
#include <utility>
#include <vector>

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include "footfall/terrain/file_extension.h"
#include "footfall/terrain/input_file.h"
#include "footfall/terrain/samples.h"
#include "footfall/terrain/text_stream.h"
#include "mesh_file_checks.h"

namespace footfall {
namespace {

struct DoubleTraits : public OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
};
using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<DoubleTraits>;

// OpenMesh reports problems on its global streams omerr/omlog/omout. They go, for good, to a
// buffer of ours instead of the process's stderr: connected once, as OpenMesh's disconnect never
// frees what its connect allocated (connecting for each read leaked 96 bytes a mesh). A read
// holds the buffer, empty when it starts, behind a mutex so concurrent loads do not mix their
// messages.
class CapturedOpenMeshMessages {
 public:
  CapturedOpenMeshMessages() : lock_(Mutex()) {
    Buffer().str("");
    Buffer().clear();
  }
  // Everything OpenMesh said since this capture started.
  std::string Text() {
    ::omerr().flush(), ::omlog().flush(), ::omout().flush();
    return Buffer().str();
  }

 private:
  static std::mutex& Mutex() {
    static std::mutex mutex;
    return mutex;
  }
  static TextStream& Buffer() {
    static TextStream* const buffer = [] {
      auto* b = new TextStream;  // never freed: OpenMesh's streams write to it to the end
      ::omerr().disconnect(std::cerr), ::omlog().disconnect(std::clog);
      ::omout().disconnect(std::cout);
      ::omerr().connect(*b), ::omlog().connect(*b), ::omout().connect(*b);
      return b;
    }();
    return *buffer;
  }
  std::lock_guard<std::mutex> lock_;
};

// "face 3, line 8" (text files) or "face 3", for messages.
std::string FaceName(const detail::ParsedMesh& mesh, size_t f) {
  std::string name = "face " + std::to_string(f + 1);
  if (f < mesh.face_line.size()) name += ", line " + std::to_string(mesh.face_line[f]);
  return name;
}

}  // namespace

bool IsMeshExtension(const std::string& ext) {
  return ext == "obj" || ext == "ply" || ext == "off" || ext == "stl";
}

Status ReadMesh(const std::string& path, TriangleMesh* out, std::string* error,
                MeshReadReport* report) {
  out->vertices.clear(), out->triangles.clear();
  if (report) *report = MeshReadReport{};
  const std::string ext = FileExtension(path);
  if (!IsMeshExtension(ext)) {
    if (error) *error = path + ": not a mesh extension '" + ext + "' (obj, ply, off, stl)";
    return Status::kInvalidArgument;
  }
  {
    // A directory read as an empty file; a FIFO waited for a writer.
    const Status input = CheckInputFile(path, "mesh", error);
    if (input != Status::kOk) return input;
    errno = 0;
    std::ifstream probe(path, std::ios::binary);
    if (!probe) {
      if (error) *error = path + ": cannot open: " + std::strerror(errno ? errno : EIO);
      return Status::kIoError;
    }
    if (probe.peek() == std::ifstream::traits_type::eof()) {
      if (error) *error = path + ": the file is empty, expected a mesh (." + ext + ")";
      return Status::kParseError;
    }
  }
  detail::ParsedMesh parsed;
  const Status status = ext == "obj"   ? detail::ParseObjFile(path, &parsed, error)
                        : ext == "off" ? detail::ParseOffFile(path, &parsed, error)
                        : ext == "ply" ? detail::ParsePlyFile(path, &parsed, error)
                                       : detail::ParseStlFile(path, &parsed, error);
  if (status != Status::kOk) return status;
  if (parsed.vertices.empty()) {
    if (error) *error = path + ": no vertices: the mesh is empty";
    return Status::kParseError;
  }
  const size_t faces = parsed.Faces();
  if (faces == 0) {
    if (error)
      *error = path + ": " + std::to_string(parsed.vertices.size()) +
               " vertices but no faces: expected a polygon mesh";
    return Status::kParseError;
  }
  auto corners_of = [&](size_t f) {
    return std::make_pair(parsed.corners.data() + parsed.face_start[f],
                          parsed.face_start[f + 1] - parsed.face_start[f]);
  };

  // 1. Faces using a vertex twice are left out, and so is a face with the corners of an earlier
  // one (the same face listed again, either way round: it doubled the area and, turned, faced
  // the other way); corners at the same position count as the same.
  const std::vector<uint32_t> id = CoincidentVertexIds(parsed.vertices);
  std::vector<char> used(faces, 1);
  size_t repeated = 0, listed_again = 0;  // faces left out, for the message when none is left
  std::vector<uint32_t> sorted;
  std::vector<std::pair<uint64_t, uint32_t>> keyed;  // (hash of the sorted corners, face)
  auto sorted_corners = [&](size_t f, std::vector<uint32_t>* out_corners) {
    const auto [c, n] = corners_of(f);
    out_corners->clear();
    for (size_t k = 0; k < n; ++k) out_corners->push_back(id[c[k]]);
    std::sort(out_corners->begin(), out_corners->end());
  };
  for (size_t f = 0; f < faces; ++f) {
    const auto [c, n] = corners_of(f);
    sorted.assign(c, c + n);
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
      used[f] = 0;
      ++repeated;
      continue;
    }
    sorted_corners(f, &sorted);
    uint64_t hash = 1469598103934665603ull;  // FNV-1a over the corner ids
    for (uint32_t v : sorted) hash = (hash ^ v) * 1099511628211ull;
    keyed.push_back({hash, static_cast<uint32_t>(f)});
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<uint32_t> other;
  for (size_t i = 0; i < keyed.size();) {
    size_t j = i + 1;
    while (j < keyed.size() && keyed[j].first == keyed[i].first) ++j;
    for (size_t a = i + 1; a < j; ++a) {  // faces of one hash, in file order: later ones go
      sorted_corners(keyed[a].second, &sorted);
      for (size_t b = i; b < a; ++b) {
        if (!used[keyed[b].second]) continue;
        sorted_corners(keyed[b].second, &other);
        if (other == sorted) {
          used[keyed[a].second] = 0;
          ++listed_again;
          break;
        }
      }
    }
    i = j;
  }

  // 2. Faces wound against their neighbours are turned to match them: across an edge of two
  // faces, one goes a -> b and the other b -> a. In each connected sheet the winding of most of
  // its faces is kept (a sheet that cannot be wound consistently is left as it is). Faces meet
  // where their corners are at the same position, as in a soup's or a split mesh's faces.
  size_t turned = 0;
  bool one_sided = false;  // a sheet that cannot be wound consistently (a Moebius strip)
  {
    struct Side {
      uint64_t edge;  // the lower vertex << 32 | the higher
      uint32_t face;
      bool forward;  // goes lower -> higher
      bool operator<(const Side& o) const { return edge < o.edge; }
    };
    std::vector<Side> sides;
    for (size_t f = 0; f < faces; ++f) {
      if (!used[f]) continue;
      const auto [c, n] = corners_of(f);
      for (size_t k = 0; k < n; ++k) {
        const uint64_t a = id[c[k]], b = id[c[(k + 1) % n]];
        if (a == b) continue;
        sides.push_back({std::min(a, b) << 32 | std::max(a, b), static_cast<uint32_t>(f), a < b});
      }
    }
    std::sort(sides.begin(), sides.end());
    // Neighbours across edges of exactly two faces: (face, other, whether they disagree).
    std::vector<size_t> first(faces + 1, 0);
    std::vector<std::pair<uint32_t, bool>> across;
    std::vector<std::array<uint32_t, 3>> pairs;  // face, other, disagree
    for (size_t i = 0; i < sides.size();) {
      size_t j = i;
      while (j < sides.size() && sides[j].edge == sides[i].edge) ++j;
      if (j - i == 2 && sides[i].face != sides[i + 1].face) {
        const uint32_t disagree = sides[i].forward == sides[i + 1].forward;
        pairs.push_back({sides[i].face, sides[i + 1].face, disagree});
        pairs.push_back({sides[i + 1].face, sides[i].face, disagree});
      }
      i = j;
    }
    for (const auto& p : pairs) ++first[p[0] + 1];
    for (size_t f = 0; f < faces; ++f) first[f + 1] += first[f];
    across.resize(pairs.size());
    std::vector<size_t> next(first.begin(), first.end() - 1);
    for (const auto& p : pairs) across[next[p[0]]++] = {p[1], p[2] != 0};
    constexpr uint8_t kUnseen = 2;
    std::vector<uint8_t> flip(faces, kUnseen);
    std::vector<uint32_t> sheet, queue;
    for (size_t start = 0; start < faces; ++start) {
      if (!used[start] || flip[start] != kUnseen) continue;
      sheet.clear();
      flip[start] = 0;
      sheet.push_back(static_cast<uint32_t>(start));
      bool consistent = true;
      for (size_t q = 0; q < sheet.size(); ++q) {
        const uint32_t f = sheet[q];
        for (size_t i = first[f]; i < first[f + 1]; ++i) {
          const auto [g, disagree] = across[i];
          const uint8_t want = flip[f] ^ static_cast<uint8_t>(disagree);
          if (flip[g] == kUnseen) {
            flip[g] = want;
            sheet.push_back(g);
          } else if (flip[g] != want) {
            consistent = false;
          }
        }
      }
      size_t flipped = 0;
      for (uint32_t f : sheet) flipped += flip[f];
      one_sided |= !consistent;
      if (!consistent || flipped == 0) continue;
      const uint8_t turn = 2 * flipped > sheet.size() ? 0 : 1;  // the minority is turned
      for (uint32_t f : sheet) {
        if (flip[f] != turn) continue;
        std::reverse(
            parsed.corners.begin() + static_cast<std::ptrdiff_t>(parsed.face_start[f]),
            parsed.corners.begin() + static_cast<std::ptrdiff_t>(parsed.face_start[f + 1]));
        ++turned;
      }
    }
  }

  // 3. Manifold: every face must join OpenMesh's half-edge mesh, as two faces at most share an
  // edge and the faces around a vertex form fans.
  {
    PolyMesh mesh;
    for (const Vec3& v : parsed.vertices) mesh.add_vertex(PolyMesh::Point(v.x, v.y, v.z));
    std::vector<PolyMesh::VertexHandle> handles;
    size_t non_manifold = 0, first_bad = 0;
    CapturedOpenMeshMessages capture;  // add_face says why it refused a face
    for (size_t f = 0; f < faces; ++f) {
      if (!used[f]) continue;
      const auto [c, n] = corners_of(f);
      handles.clear();
      for (size_t k = 0; k < n; ++k)
        handles.push_back(PolyMesh::VertexHandle(static_cast<int>(c[k])));
      if (mesh.add_face(handles).is_valid()) continue;
      if (non_manifold++ == 0) first_bad = f;
    }
    if (non_manifold) {
      if (error) {
        *error = path + ": the mesh is not manifold: " + std::to_string(non_manifold) +
                 " faces (the first is " + FaceName(parsed, first_bad) +
                 ") share an edge with two other faces or meet another sheet at a single vertex" +
                 (one_sided ? ", or close a one-sided surface (a sheet whose faces cannot all be "
                              "wound one way, as on a Moebius strip)"
                            : "");
      }
      return Status::kParseError;
    }
  }

  // 4. Polygons triangulated by ear clipping in their plane (the fan of the first corner for a
  // convex polygon; a fan for a self-intersecting one); triangles of no area left out, and a
  // face left with none is skipped.
  out->vertices = std::move(parsed.vertices);
  size_t skipped = 0;
  std::vector<uint32_t> polygon;
  std::vector<std::array<uint32_t, 3>> pieces;
  for (size_t f = 0; f < faces; ++f) {
    const size_t before = out->triangles.size();
    if (used[f]) {
      const auto [c, n] = corners_of(f);
      polygon.assign(c, c + n);
      pieces.clear();
      TriangulatePolygon(out->vertices, polygon, &pieces);
      const auto& v = out->vertices;
      for (const auto& t : pieces)
        if (!IsDegenerateTriangle(v[t[0]], v[t[1]], v[t[2]])) out->triangles.push_back(t);
    }
    if (out->triangles.size() == before) ++skipped;
  }
  if (report) {
    report->vertices = out->vertices.size();
    report->faces = faces;
    report->skipped_faces = skipped;
    report->turned_faces = turned;
  }
  if (out->triangles.empty()) {
    // Why each face went (a polygon with a hole joined by a bridge that reuses its corners was
    // said to be "degenerate (zero area)").
    if (error) {
      std::string why = path + ": no face is left:";
      const size_t no_area = faces - repeated - listed_again;
      const char* sep = "";
      if (repeated) {
        why += " " + std::to_string(repeated) +
               " with a vertex used twice (a polygon with a hole bridged through its own "
               "corners: give the bridge's corners vertices of their own, or triangulate it)";
        sep = ",";
      }
      if (listed_again)
        why += sep + (" " + std::to_string(listed_again)) + " listed again", sep = ",";
      if (no_area) why += sep + (" " + std::to_string(no_area)) + " of no area (degenerate)";
      *error = why;
    }
    return Status::kParseError;
  }
  return Status::kOk;
}

}  // namespace footfall
