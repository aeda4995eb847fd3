#include "footfall/import/mesh_reader.h"

#include <cmath>
#include <fstream>
#include <mutex>
#include <sstream>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include "footfall/terrain/file_extension.h"
#include "footfall/terrain/samples.h"
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
  static std::ostringstream& Buffer() {
    static std::ostringstream* const buffer = [] {
      auto* b = new std::ostringstream;  // never freed: OpenMesh's streams write to it to the end
      ::omerr().disconnect(std::cerr), ::omlog().disconnect(std::clog);
      ::omout().disconnect(std::cout);
      ::omerr().connect(*b), ::omlog().connect(*b), ::omout().connect(*b);
      return b;
    }();
    return *buffer;
  }
  std::lock_guard<std::mutex> lock_;
};

size_t CountOccurrences(const std::string& text, const std::string& what) {
  size_t count = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++count;
  return count;
}

// The first line of OpenMesh's messages, for error reports.
std::string FirstLine(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  return line.empty() ? "no details" : line;
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
    std::ifstream probe(path, std::ios::binary);
    if (!probe) {
      if (error) *error = path + ": cannot open";
      return Status::kIoError;
    }
    if (probe.peek() == std::ifstream::traits_type::eof()) {
      if (error) *error = path + ": the file is empty, expected a " + ext + " mesh";
      return Status::kParseError;
    }
  }
  Status status = Status::kOk;
  long long declared_faces = -1;
  std::vector<Vec3> exact;  // OBJ, OFF: the coordinates in double, in file order
  if (ext == "obj") status = detail::CheckObjFile(path, &declared_faces, &exact, error);
  if (ext == "off") status = detail::CheckOffFile(path, &declared_faces, &exact, error);
  if (ext == "ply") status = detail::CheckPlyFile(path, &declared_faces, error);
  if (ext == "stl") status = detail::CheckStlFile(path, error);
  if (status != Status::kOk) return status;

  PolyMesh mesh;
  mesh.request_vertex_status();
  mesh.request_edge_status();
  mesh.request_face_status();
  std::string messages;
  bool read = false;
  {
    CapturedOpenMeshMessages capture;
    OpenMesh::IO::Options options;
    read = OpenMesh::IO::read_mesh(mesh, path, options);
    messages = capture.Text();
  }
  if (!read) {
    if (error) *error = path + ": OpenMesh cannot read it as " + ext + ": " + FirstLine(messages);
    return Status::kParseError;
  }
  if (CountOccurrences(messages, "invalid vertex index")) {
    if (error) *error = path + ": a face uses a vertex that does not exist (truncated file?)";
    return Status::kParseError;
  }
  // Faces OpenMesh dropped (repeated vertices): declared minus read where the file declares.
  size_t skipped = CountOccurrences(messages, "equal vertices");
  if (declared_faces > static_cast<long long>(mesh.n_faces())) {
    skipped = static_cast<size_t>(declared_faces) - mesh.n_faces();
  }

  // Vertices, all finite. OpenMesh parses text coordinates as float; where the file's own
  // double-precision coordinates match its vertices one to one, they are used instead.
  const bool use_exact = exact.size() == mesh.n_vertices();
  out->vertices.resize(mesh.n_vertices());
  for (const auto vh : mesh.vertices()) {
    const auto& p = mesh.point(vh);
    const Vec3 v = use_exact ? exact[vh.idx()] : Vec3{p[0], p[1], p[2]};
    if (!IsFinite(v)) {
      if (error)
        *error = path + ": vertex " + std::to_string(vh.idx() + 1) + " has a non-finite coordinate";
      return Status::kParseError;
    }
    const double limit = terrain::kMaxCoordinate;
    if (std::fabs(v.x) > limit || std::fabs(v.y) > limit || std::fabs(v.z) > limit) {
      if (error) {
        std::ostringstream m;
        m << path << ": vertex " << vh.idx() + 1 << " (" << v.x << ", " << v.y << ", " << v.z
          << ") is out of range (expected |coordinate| <= " << limit << ")";
        *error = m.str();
      }
      return Status::kParseError;
    }
    out->vertices[vh.idx()] = v;
  }
  if (mesh.n_vertices() == 0) {
    if (error) *error = path + ": no vertices: the mesh is empty";
    return Status::kParseError;
  }
  if (mesh.n_faces() == 0) {
    if (error)
      *error = path + ": " + std::to_string(mesh.n_vertices()) +
               " vertices but no faces: expected a polygon mesh";
    return Status::kParseError;
  }

  // Faces OpenMesh could only add by duplicating their vertices break the manifold property.
  size_t non_manifold = 0;
  int first_bad = -1;
  for (const auto fh : mesh.faces()) {
    if (mesh.status(fh).fixed_nonmanifold()) {
      if (first_bad < 0) first_bad = fh.idx();
      ++non_manifold;
    }
  }
  if (non_manifold) {
    if (error) {
      *error = path + ": the mesh is not manifold: " + std::to_string(non_manifold) +
               " faces (the first is face " + std::to_string(first_bad + 1) +
               ") share an edge with two other faces or meet another sheet at a single vertex";
    }
    return Status::kParseError;
  }

  // Fan triangulation in stored order.
  std::vector<uint32_t> corners;
  for (const auto fh : mesh.faces()) {
    corners.clear();
    for (const auto vh : mesh.fv_range(fh)) corners.push_back(static_cast<uint32_t>(vh.idx()));
    for (size_t i = 2; i < corners.size(); ++i) {
      out->triangles.push_back({corners[0], corners[i - 1], corners[i]});
    }
  }
  skipped += RemoveDegenerateTriangles(out);
  if (report) {
    report->vertices = mesh.n_vertices();
    report->faces = mesh.n_faces();
    report->skipped_faces = skipped;
  }
  if (out->triangles.empty()) {
    if (error) *error = path + ": every face is degenerate (zero area)";
    return Status::kParseError;
  }
  return Status::kOk;
}

}  // namespace footfall
