#include "recon/mesh.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <spdlog/spdlog.h>

#include <assimp/Importer.hpp>
#include <cmath>
#include <map>

namespace igi::recon {

Eigen::Vector3f TriangleMesh::FaceNormal(size_t t) const {
  const Eigen::Vector3i& tri = triangles[t];
  const Eigen::Vector3f e1 = positions[tri[1]] - positions[tri[0]];
  const Eigen::Vector3f e2 = positions[tri[2]] - positions[tri[0]];
  return e1.cross(e2).normalized();
}

double TriangleArea(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
  return 0.5 * (b - a).cast<double>().cross((c - a).cast<double>()).norm();
}

double TriangleMesh::TriangleArea(size_t t) const {
  const Eigen::Vector3i& tri = triangles[t];
  return igi::recon::TriangleArea(positions[tri[0]], positions[tri[1]], positions[tri[2]]);
}

void TriangleMesh::Append(const TriangleMesh& other) {
  const int offset = static_cast<int>(positions.size());
  if (has_uvs() != other.has_uvs()) {
    if (!has_uvs()) uvs.assign(positions.size(), Eigen::Vector2f::Zero());
  }
  positions.insert(positions.end(), other.positions.begin(), other.positions.end());
  normals.insert(normals.end(), other.normals.begin(), other.normals.end());
  if (other.has_uvs()) {
    uvs.insert(uvs.end(), other.uvs.begin(), other.uvs.end());
  } else if (has_uvs()) {
    uvs.resize(positions.size(), Eigen::Vector2f::Zero());
  }
  std::vector<int> region_map(other.region_names.size());
  for (size_t r = 0; r < other.region_names.size(); ++r) {
    auto it = std::find(region_names.begin(), region_names.end(), other.region_names[r]);
    if (it == region_names.end()) {
      region_names.push_back(other.region_names[r]);
      it = region_names.end() - 1;
    }
    region_map[r] = static_cast<int>(it - region_names.begin());
  }
  for (size_t t = 0; t < other.triangles.size(); ++t) {
    triangles.push_back(other.triangles[t] + Eigen::Vector3i::Constant(offset));
    triangle_region.push_back(region_map[other.triangle_region[t]]);
  }
}

namespace {

// Adds one Assimp mesh (already in world coordinates) to `out`.
// Replaces shared vertices by one vertex per triangle corner carrying the face normal.
void MakeFlat(TriangleMesh* mesh) {
  TriangleMesh flat;
  flat.region_names = mesh->region_names;
  flat.triangle_region = mesh->triangle_region;
  for (size_t t = 0; t < mesh->triangles.size(); ++t) {
    const Eigen::Vector3f n = mesh->FaceNormal(t);
    const int base = static_cast<int>(flat.positions.size());
    for (int k = 0; k < 3; ++k) {
      const int v = mesh->triangles[t][k];
      flat.positions.push_back(mesh->positions[v]);
      flat.normals.push_back(n);
      if (mesh->has_uvs()) flat.uvs.push_back(mesh->uvs[v]);
    }
    flat.triangles.emplace_back(base, base + 1, base + 2);
  }
  *mesh = std::move(flat);
}

void AddAssimpMesh(const aiScene& scene, const aiMesh& mesh, TriangleMesh* out,
                   std::map<std::string, int>* region_index, MeshLoadSummary* summary) {
  const std::string region = scene.mMaterials[mesh.mMaterialIndex]->GetName().C_Str();
  auto [it, inserted] = region_index->try_emplace(region, int(out->region_names.size()));
  if (inserted) out->region_names.push_back(region);
  const int offset = static_cast<int>(out->positions.size());
  for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
    const aiVector3D& p = mesh.mVertices[v];
    out->positions.emplace_back(p.x, p.y, p.z);
    if (mesh.HasNormals()) {
      const aiVector3D& n = mesh.mNormals[v];
      out->normals.emplace_back(n.x, n.y, n.z);
    }
    if (mesh.HasTextureCoords(0)) {
      const aiVector3D& uv = mesh.mTextureCoords[0][v];
      out->uvs.emplace_back(uv.x, uv.y);
    }
  }
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines are not surfaces
    Eigen::Vector3i tri(int(face.mIndices[0]) + offset, int(face.mIndices[1]) + offset,
                        int(face.mIndices[2]) + offset);
    if (TriangleArea(out->positions[tri[0]], out->positions[tri[1]], out->positions[tri[2]]) <=
        0.0) {
      ++summary->num_degenerate_dropped;
      continue;
    }
    out->triangles.push_back(tri);
    out->triangle_region.push_back(it->second);
  }
}

void CheckVertices(const std::filesystem::path& path, TriangleMesh* mesh, ProblemList* problems) {
  for (size_t v = 0; v < mesh->positions.size(); ++v) {
    if (!mesh->positions[v].allFinite()) {
      problems->Add(path.string(), "vertex " + std::to_string(v), "",
                    "position must be finite (NaN or infinity found)");
      return;
    }
  }
  for (Eigen::Vector3f& n : mesh->normals) {
    const float len = n.norm();
    if (std::isfinite(len) && len > 1e-12f) {
      n /= len;
    } else {
      spdlog::warn("{}: a vertex normal is zero or not finite: shading the mesh flat",
                   path.string());
      mesh->normals.clear();
      return;
    }
  }
}

}  // namespace

TriangleMesh LoadMesh(const std::filesystem::path& path, ProblemList* problems,
                      MeshLoadSummary* summary) {
  MeshLoadSummary local_summary;
  if (summary == nullptr) summary = &local_summary;
  TriangleMesh out;
  if (!std::filesystem::is_regular_file(path)) {
    problems->Add(path.string(), "", "", "mesh file not found");
    return out;
  }
  Assimp::Importer importer;
  // Points and lines are removed; no normals are invented (no normals = flat shading).
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      path.string(), aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_JoinIdenticalVertices |
                         aiProcess_SortByPType | aiProcess_ValidateDataStructure);
  if (scene == nullptr || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0) {
    problems->Add(path.string(), "", "", std::string("cannot read mesh: ") + importer.GetErrorString());
    return out;
  }
  std::map<std::string, int> region_index;
  bool all_normals = scene->mNumMeshes > 0, all_uvs = scene->mNumMeshes > 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    all_normals = all_normals && scene->mMeshes[m]->HasNormals();
    all_uvs = all_uvs && scene->mMeshes[m]->HasTextureCoords(0);
  }
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    AddAssimpMesh(*scene, *scene->mMeshes[m], &out, &region_index, summary);
  }
  if (!all_uvs) out.uvs.clear();
  if (out.triangles.empty()) {
    problems->Add(path.string(), "", "", "mesh has no triangles");
    return out;
  }
  if (!all_normals) out.normals.clear();
  CheckVertices(path, &out, problems);
  const bool file_normals = out.has_normals();
  if (!file_normals) MakeFlat(&out);
  summary->num_vertices = out.positions.size();
  summary->num_triangles = out.triangles.size();
  summary->has_normals = file_normals;
  summary->has_uvs = out.has_uvs();
  return out;
}

}  // namespace igi::recon
