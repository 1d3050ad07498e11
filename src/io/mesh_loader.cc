#include "rigid_body_sim/io/mesh_loader.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include "io/text_mesh_reader.h"

namespace rigid_body_sim::io {
namespace {

using physics::Result;
using physics::TriangleMesh;
using physics::Vec3;

constexpr char kFileScheme[] = "file://";

std::string Lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

// Vertices of all sub-meshes in file order and triangles indexing them.
struct MeshBuilder {
  TriangleMesh mesh;
  bool has_non_finite_vertex = false;
};

// Joins vertices with identical coordinates: sorts the vertex indices by
// coordinates, keeps the first index of each run of equal vertices, and
// renumbers the kept vertices in file order. Needs finite coordinates.
void JoinIdenticalVertices(TriangleMesh* mesh) {
  const std::vector<Vec3>& vertices = mesh->vertices;
  std::vector<int> order(vertices.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  const auto key = [&vertices](int i) {
    return std::make_tuple(vertices[i].x(), vertices[i].y(), vertices[i].z(), i);
  };
  std::sort(order.begin(), order.end(), [&key](int a, int b) { return key(a) < key(b); });
  std::vector<int> representative(vertices.size());
  for (size_t k = 0; k < order.size(); ++k) {
    const bool same_as_previous = k > 0 && vertices[order[k]] == vertices[order[k - 1]];
    representative[order[k]] = same_as_previous ? representative[order[k - 1]] : order[k];
  }
  std::vector<int> new_index(vertices.size(), -1);
  std::vector<Vec3> joined;
  for (size_t i = 0; i < vertices.size(); ++i) {
    if (representative[i] == static_cast<int>(i)) {
      new_index[i] = static_cast<int>(joined.size());
      joined.push_back(vertices[i]);
    }
  }
  for (Eigen::Vector3i& triangle : mesh->triangles) {
    for (int k = 0; k < 3; ++k) triangle[k] = new_index[representative[triangle[k]]];
  }
  mesh->vertices = std::move(joined);
}

// Appends the triangles of `node` and its children, each mesh placed by the
// product of the node transforms from the root (assimp's node hierarchy).
void CollectNode(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent_from_root,
                 const Vec3& scale, MeshBuilder* builder) {
  const aiMatrix4x4 root_from_node = parent_from_root * node.mTransformation;
  for (unsigned int m = 0; m < node.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[node.mMeshes[m]];
    const int first_vertex = static_cast<int>(builder->mesh.vertices.size());
    for (unsigned int v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D placed = root_from_node * mesh.mVertices[v];
      const Vec3 vertex = Vec3(placed.x, placed.y, placed.z).cwiseProduct(scale);
      if (!vertex.allFinite()) builder->has_non_finite_vertex = true;
      builder->mesh.vertices.push_back(vertex);
    }
    // A mirroring transform (negative determinant) turns counter-clockwise
    // triangles clockwise; swapping two corners keeps them facing outwards.
    const bool mirrored = root_from_node.Determinant() * scale.prod() < 0.0;
    for (unsigned int f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;
      const int a = first_vertex + static_cast<int>(face.mIndices[0]);
      const int b = first_vertex + static_cast<int>(face.mIndices[1]);
      const int c = first_vertex + static_cast<int>(face.mIndices[2]);
      if (mirrored) {
        builder->mesh.triangles.emplace_back(a, c, b);
      } else {
        builder->mesh.triangles.emplace_back(a, b, c);
      }
    }
  }
  for (unsigned int c = 0; c < node.mNumChildren; ++c) {
    CollectNode(scene, *node.mChildren[c], root_from_node, scale, builder);
  }
}

// An OBJ or ASCII STL file read in double precision (ReadObjText,
// ReadAsciiStlText), or nullopt for assimp to read. A binary STL is known by
// its size, 84 bytes and 50 per facet, whatever its header says.
std::optional<TriangleMesh> ReadTextMesh(const std::string& path, const std::string& extension,
                                         std::uintmax_t size) {
  if (extension != ".obj" && extension != ".stl") return std::nullopt;
  std::ifstream file(path, std::ios::binary);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!file.read(text.data(), static_cast<std::streamsize>(text.size()))) return std::nullopt;
  if (extension == ".obj") return ReadObjText(text);
  if (size >= 84) {
    std::uint32_t facets = 0;
    std::memcpy(&facets, text.data() + 80, sizeof(facets));
    if (size == 84 + 50 * static_cast<std::uintmax_t>(facets)) return std::nullopt;
  }
  return ReadAsciiStlText(text);
}

// The scale, the orientation under a mirroring scale and the joined
// vertices, as for a mesh that assimp read.
Result<TriangleMesh> FinishTextMesh(const std::string& path, const Vec3& scale, TriangleMesh mesh) {
  for (Vec3& vertex : mesh.vertices) {
    vertex = vertex.cwiseProduct(scale);
    if (!vertex.allFinite()) {
      return Result<TriangleMesh>::Error("mesh file '" + path +
                                         "' has a vertex that is not finite");
    }
  }
  if (scale.prod() < 0.0) {
    for (Eigen::Vector3i& triangle : mesh.triangles) std::swap(triangle[1], triangle[2]);
  }
  JoinIdenticalVertices(&mesh);
  return mesh;
}

}  // namespace

Result<std::string> ResolveFileUri(const std::string& uri) {
  if (uri.empty()) return Result<std::string>::Error("empty mesh URI");
  if (uri.rfind(kFileScheme, 0) == 0) {
    const std::string path = uri.substr(std::strlen(kFileScheme));
    if (path.empty()) return Result<std::string>::Error("URI '" + uri + "' has no path");
    return path;
  }
  if (uri.find("://") != std::string::npos) {
    return Result<std::string>::Error("cannot resolve URI '" + uri +
                                      "': only file:// URIs and plain paths are supported "
                                      "without a resolver");
  }
  return uri;
}

Result<TriangleMesh> LoadMesh(const std::string& uri, const Vec3& scale,
                              const UriResolver& resolver, std::uintmax_t max_file_bytes) {
  if (!scale.allFinite() || (scale.array() == 0.0).any()) {
    return Result<TriangleMesh>::Error("mesh '" + uri +
                                       "': scale must be finite and non-zero on every axis");
  }
  const Result<std::string> resolved = resolver ? resolver(uri) : ResolveFileUri(uri);
  if (!resolved.ok())
    return Result<TriangleMesh>::Error("mesh '" + uri + "': " + resolved.message());
  const std::string& path = *resolved;

  const std::string extension = Lowercase(std::filesystem::path(path).extension().string());
  if (extension != ".stl" && extension != ".obj" && extension != ".dae" && extension != ".ply") {
    return Result<TriangleMesh>::Error("mesh file '" + path + "': unsupported format '" +
                                       extension + "' (supported: .stl, .obj, .dae, .ply)");
  }
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    return Result<TriangleMesh>::Error("mesh file '" + path +
                                       "' does not exist or is not a regular file");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error || size > max_file_bytes) {
    return Result<TriangleMesh>::Error("mesh file '" + path + "' size " + std::to_string(size) +
                                       " bytes is above the limit " +
                                       std::to_string(max_file_bytes));
  }

  if (std::optional<TriangleMesh> text = ReadTextMesh(path, extension, size)) {
    return FinishTextMesh(path, scale, std::move(*text));
  }

  Assimp::Importer importer;
  // Points and lines carry no volume; drop them so only triangles remain.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_SortByPType);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    return Result<TriangleMesh>::Error("mesh file '" + path +
                                       "' could not be read: " + importer.GetErrorString());
  }

  // Assimp's COLLADA importer folds <unit meter> into the root transform and
  // turns the file's <up_axis> into +y up. ROS geometry is +z up, so rotate
  // +y up to +z up: (x, y, z) -> (x, -z, y).
  aiMatrix4x4 z_up_from_root;
  if (extension == ".dae") {
    z_up_from_root = aiMatrix4x4(1, 0, 0, 0,   //
                                 0, 0, -1, 0,  //
                                 0, 1, 0, 0,   //
                                 0, 0, 0, 1);
  }
  MeshBuilder builder;
  CollectNode(*scene, *scene->mRootNode, z_up_from_root, scale, &builder);
  if (builder.mesh.triangles.empty()) {
    return Result<TriangleMesh>::Error("mesh file '" + path + "' contains no triangles");
  }
  if (builder.has_non_finite_vertex) {
    return Result<TriangleMesh>::Error("mesh file '" + path + "' has a vertex that is not finite");
  }
  JoinIdenticalVertices(&builder.mesh);
  return std::move(builder.mesh);
}

}  // namespace rigid_body_sim::io
