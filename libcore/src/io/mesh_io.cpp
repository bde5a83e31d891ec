#include "impinge/io/mesh_io.hpp"

#include <assimp/cimport.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <dlfcn.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <type_traits>

#include "impinge/core/atomic_file.hpp"
#include "impinge/core/error.hpp"
#include "io/mesh_readers.hpp"

namespace impinge {

namespace {
/// assimp's C interface (assimp/cimport.h), loaded when a file first needs it: PLY, OFF and OBJ, the formats of
/// every shipped and generated mesh, have their own readers, so most runs never load assimp and its libraries
/// (Draco, minizip), which cost 1.3 ms of every start when linked (issue 52). IMPINGE_ASSIMP_LIBRARY is the shared
/// library's name as CMake found it (libcore/CMakeLists.txt). Throws impinge::Error naming the file when it
/// cannot be loaded.
struct AssimpC {
  decltype(&aiImportFileExWithProperties) import_file = nullptr;
  decltype(&aiReleaseImport) release_import = nullptr;
  decltype(&aiGetErrorString) error_string = nullptr;
  decltype(&aiCreatePropertyStore) create_properties = nullptr;
  decltype(&aiReleasePropertyStore) release_properties = nullptr;
  decltype(&aiSetImportPropertyInteger) set_integer = nullptr;
  std::string error;  ///< why it could not be loaded, empty when it was
};

const AssimpC& assimp_c() {
  static const AssimpC a = [] {
    AssimpC c;
    void* lib = dlopen(IMPINGE_ASSIMP_LIBRARY, RTLD_NOW | RTLD_LOCAL);  // kept loaded for the process
    if (lib == nullptr) {
      const char* why = dlerror();
      c.error = std::string(IMPINGE_ASSIMP_LIBRARY) + ": " + (why != nullptr ? why : "cannot be loaded");
      return c;
    }
    const auto get = [&](auto& fn, const char* name) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(lib, name));
      if (fn == nullptr && c.error.empty()) c.error = std::string(IMPINGE_ASSIMP_LIBRARY) + " has no " + name;
    };
    get(c.import_file, "aiImportFileExWithProperties");
    get(c.release_import, "aiReleaseImport");
    get(c.error_string, "aiGetErrorString");
    get(c.create_properties, "aiCreatePropertyStore");
    get(c.release_properties, "aiReleasePropertyStore");
    get(c.set_integer, "aiSetImportPropertyInteger");
    return c;
  }();
  return a;
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// load_mesh's checks on a mesh read by any reader: valid, degenerate faces removed, some left.
TriangleMesh checked(TriangleMesh mesh, const std::string& path) {
  mesh.source = path;
  require(mesh.V.rows() > 0, path + ": mesh has no vertices");
  require(mesh.F.rows() > 0, path + ": mesh has no triangles");
  validate_mesh(mesh);
  remove_degenerate_faces(mesh);
  require(mesh.F.rows() > 0, path + ": every triangle is degenerate (zero area)");
  return mesh;
}

// A PLY, OFF or OBJ file (ext: its lower-case extension) through our readers, in the file's vertex order: read
// whole from `in` (open, binary) in one read into a string of its size (no stream buffer copied twice), then
// checked. Throws impinge::Error naming path when its size cannot be read or it changed while read.
TriangleMesh read_with_own_reader(const std::string& path, const std::string& ext, std::ifstream& in) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  require(!ec && size < std::uintmax_t(std::numeric_limits<std::streamsize>::max()),
          [&] { return path + ": cannot read the file's size (" + ec.message() + ")"; });
  std::string b(static_cast<std::size_t>(size), '\0');
  in.read(b.data(), static_cast<std::streamsize>(size));
  require(in.gcount() == static_cast<std::streamsize>(size) && in.peek() == std::char_traits<char>::eof(),
          [&] { return path + ": the file changed while it was read (" + std::to_string(size) + " bytes expected)"; });
  return checked(ext == ".ply" ? detail::read_ply(path, b) : ext == ".off" ? detail::read_off(path, b)
                                                                           : detail::read_obj(path, b),
                 path);
}

// The meshes of an assimp scene read from `path` as one mesh: V (n x 3, the file's units: mm) and F (the
// triangles, their indices past the meshes before), unchecked. Throws impinge::Error naming path when the scene
// holds no mesh, no vertex or no face, or a face is not a triangle or indexes outside its mesh.
TriangleMesh mesh_of_scene(const aiScene& scene, const std::string& path) {
  require(scene.mNumMeshes > 0, path + ": file holds no mesh");

  std::size_t nv = 0, nf = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    nv += scene.mMeshes[m]->mNumVertices;
    nf += scene.mMeshes[m]->mNumFaces;
  }
  require(nv > 0, path + ": mesh has no vertices");
  require(nf > 0, path + ": mesh has no triangles");

  TriangleMesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(nv), 3);
  mesh.F.resize(static_cast<Eigen::Index>(nf), 3);
  Eigen::Index vo = 0, fo = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* am = scene.mMeshes[m];
    for (unsigned i = 0; i < am->mNumVertices; ++i) {
      mesh.V(vo + i, 0) = am->mVertices[i].x;
      mesh.V(vo + i, 1) = am->mVertices[i].y;
      mesh.V(vo + i, 2) = am->mVertices[i].z;
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) {
        std::ostringstream os;
        os << path << ": face " << (fo + f) << " has " << face.mNumIndices << " vertices; only triangles are supported";
        throw Error(os.str());
      }
      for (int k = 0; k < 3; ++k) {
        const unsigned idx = face.mIndices[k];
        if (idx >= am->mNumVertices) {
          std::ostringstream os;
          os << path << ": face " << (fo + f) << " has vertex index " << idx << " outside [0, " << am->mNumVertices
             << ")";
          throw Error(os.str());
        }
        mesh.F(fo + f, k) = static_cast<int>(vo + idx);
      }
    }
    vo += am->mNumVertices;
    fo += am->mNumFaces;
  }
  return mesh;
}
}  // namespace

TriangleMesh load_mesh(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  require(fs::exists(path, ec), path + ": file does not exist");
  require(fs::is_regular_file(path, ec), path + ": not a regular file");
  std::ifstream in(path, std::ios::binary);
  require(in.good(), path + ": cannot open file for reading");
  const std::string ext = lower_extension(path);
  if (ext == ".ply" || ext == ".off" || ext == ".obj") return read_with_own_reader(path, ext, in);
  in.close();  // assimp opens the file itself
  const AssimpC& ai = assimp_c();
  require(ai.error.empty(),
          [&] { return path + ": reading " + ext + " files needs assimp, which cannot be loaded (" + ai.error + ")"; });
  unsigned flags = 0;
  const std::unique_ptr<aiPropertyStore, decltype(ai.release_properties)> props(ai.create_properties(),
                                                                               ai.release_properties);
  if (ext == ".stl") {
    // Weld corners by position only: drop the per-face normals and texture coordinates that
    // would otherwise keep identical positions apart.
    ai.set_integer(props.get(), AI_CONFIG_PP_RVC_FLAGS,
                   aiComponent_NORMALS | aiComponent_TEXCOORDS | aiComponent_COLORS |
                       aiComponent_TANGENTS_AND_BITANGENTS);
    flags |= aiProcess_RemoveComponent | aiProcess_JoinIdenticalVertices;
  }
  // One import at a time: the C interface keeps the last error in one string for the process (the two bones
  // are read on two threads).
  static std::mutex one_import;
  std::unique_lock<std::mutex> lock(one_import);
  const std::unique_ptr<const aiScene, decltype(ai.release_import)> owned(
      ai.import_file(path.c_str(), flags, nullptr, props.get()), ai.release_import);
  const aiScene* scene = owned.get();
  if (scene == nullptr) throw Error(path + ": cannot parse mesh: " + ai.error_string());
  lock.unlock();
  return checked(mesh_of_scene(*scene, path), path);
}

namespace {
// A binary PLY's body: the string grown once by the body's size, then each value copied to its place (an append
// per value cost more than the copies: some 2 ms of a one-pose run's output, issue 52). Values in the machine's
// byte order (little-endian, as the headers say). Throws impinge::Error past the size given (a miscounted body).
class BodyWriter {
 public:
  BodyWriter(std::string& out, std::size_t bytes) : out_(out), at_(out.size()) { out_.resize(at_ + bytes); }
  template <typename T>
  void put(T value) {
    if (at_ + sizeof(T) > out_.size()) throw Error("PLY writer: the body is longer than counted");
    std::memcpy(out_.data() + at_, &value, sizeof(T));
    at_ += sizeof(T);
  }
  void finish() const { require(at_ == out_.size(), "PLY writer: the body is shorter than counted"); }

 private:
  std::string& out_;
  std::size_t at_;
};

constexpr std::size_t kFaceBytes = 1 + 3 * sizeof(std::int32_t);  // a face: its count (uchar 3), three int indices

void write_faces(BodyWriter& out, const Faces& F) {
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    out.put<std::uint8_t>(3);
    for (int k = 0; k < 3; ++k) out.put<std::int32_t>(F(f, k));
  }
}
}  // namespace

void write_gap_ply(const std::string& path, PointsRef V, const Faces& F, const Eigen::VectorXf& gap_mm,
                   const Eigen::Matrix<unsigned char, Eigen::Dynamic, 1>& level,
                   const Eigen::Matrix<unsigned char, Eigen::Dynamic, 3, Eigen::RowMajor>& rgb,
                   const Eigen::VectorXf* distance_mm, const std::vector<std::uint8_t>* sign_undecided) {
  if (distance_mm == nullptr) sign_undecided = nullptr;
  require(gap_mm.size() == V.rows() && level.size() == V.rows() && rgb.rows() == V.rows() &&
              (distance_mm == nullptr || distance_mm->size() == V.rows()) &&
              (sign_undecided == nullptr || sign_undecided->size() == static_cast<std::size_t>(V.rows())),
          path + ": per-vertex arrays do not match the vertex count");
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\ncomment impinge per-vertex gap (mm)\n"
         << "element vertex " << V.rows() << "\n"
         << "property float x\nproperty float y\nproperty float z\n"
         << "property float gap_mm\nproperty float quality\n"
         << (distance_mm != nullptr ? "property float distance_mm\n" : "")
         << (sign_undecided != nullptr ? "property uchar sign_undecided\n" : "") << "property uchar level\n"
         << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
         << "element face " << F.rows() << "\nproperty list uchar int vertex_indices\nend_header\n";
  std::string out = header.str();
  BodyWriter body(out, static_cast<std::size_t>(V.rows()) * (24 + (distance_mm != nullptr ? 4 : 0) +
                                                            (sign_undecided != nullptr ? 1 : 0)) +
                           static_cast<std::size_t>(F.rows()) * kFaceBytes);
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    for (int k = 0; k < 3; ++k) body.put<float>(static_cast<float>(V(i, k)));
    body.put<float>(gap_mm[i]);
    body.put<float>(gap_mm[i]);
    if (distance_mm != nullptr) body.put<float>((*distance_mm)[i]);
    if (sign_undecided != nullptr) body.put<std::uint8_t>((*sign_undecided)[static_cast<std::size_t>(i)]);
    body.put<std::uint8_t>(level[i]);
    for (int k = 0; k < 3; ++k) body.put<std::uint8_t>(rgb(i, k));
  }
  write_faces(body, F);
  body.finish();
  write_file_atomically(path, out);
}

void write_ply(const std::string& path, const TriangleMesh& mesh) { write_ply(path, mesh, {}); }

void write_ply(const std::string& path, const TriangleMesh& mesh, const std::vector<PointArray>& arrays) {
  validate_mesh(mesh);
  for (const PointArray& a : arrays)
    require(a.f32.size() == static_cast<std::size_t>(mesh.V.rows()) && !a.name.empty(),
            path + ": per-vertex property '" + a.name + "' has " + std::to_string(a.f32.size()) +
                " values for " + std::to_string(mesh.V.rows()) + " vertices");
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\nelement vertex " << mesh.V.rows() << "\n"
         << "property float x\nproperty float y\nproperty float z\n";
  for (const PointArray& a : arrays) header << "property float " << a.name << "\n";
  header << "element face " << mesh.F.rows() << "\nproperty list uchar int vertex_indices\nend_header\n";
  std::string out = header.str();
  BodyWriter body(out, static_cast<std::size_t>(mesh.V.rows()) * sizeof(float) * (3 + arrays.size()) +
                           static_cast<std::size_t>(mesh.F.rows()) * kFaceBytes);
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    for (int k = 0; k < 3; ++k) body.put<float>(static_cast<float>(mesh.V(i, k)));
    for (const PointArray& a : arrays) body.put<float>(a.f32[static_cast<std::size_t>(i)]);
  }
  write_faces(body, mesh.F);
  body.finish();
  write_file_atomically(path, out);
}

}  // namespace impinge
