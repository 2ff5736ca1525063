#include "voxpress/io/mesh_io.h"

#include <filesystem>

#include "formats.h"
#include "io_util.h"
#include "voxpress/io/volume_io.h"

namespace voxpress {

MeshFormat mesh_format_from_path(const std::string& path) {
  const std::string ext = detail::extension_of(path);
  if (ext == ".ply") return MeshFormat::ply;
  if (ext == ".obj") return MeshFormat::obj;
  if (ext == ".stl") return MeshFormat::stl;
  if (ext == ".off") return MeshFormat::off;
  if (ext == ".gltf") return MeshFormat::gltf;
  if (ext == ".glb") return MeshFormat::glb;
  if (ext == ".vtk") return MeshFormat::vtk;
  if (ext == ".vtp") return MeshFormat::vtp;
  throw InputError(path, "unknown mesh format '" + ext + "' (use .ply .obj .stl .off .glb .gltf .vtk or .vtp)");
}

void write_mesh(const std::string& path, const Mesh& mesh, const MeshWriteOptions& options) {
  switch (mesh_format_from_path(path)) {
    case MeshFormat::ply: return detail::write_ply(path, mesh, !options.ascii, options.space);
    case MeshFormat::obj: return detail::write_obj(path, mesh);
    case MeshFormat::stl: return detail::write_stl(path, mesh, options.space);
    case MeshFormat::off: return detail::write_off(path, mesh);
    case MeshFormat::gltf: return detail::write_gltf(path, mesh, false);
    case MeshFormat::glb: return detail::write_gltf(path, mesh, true);
    case MeshFormat::vtk: return detail::write_vtk(path, mesh, !options.ascii, options.space);
    case MeshFormat::vtp: return detail::write_vtp(path, mesh, options.space);
  }
}

void write_scene(const std::string& path, const std::vector<SceneMesh>& meshes) {
  const MeshFormat f = mesh_format_from_path(path);
  if (f != MeshFormat::glb && f != MeshFormat::gltf) throw UsageError(path + ": a scene of several meshes is .glb or .gltf");
  detail::write_gltf_scene(path, meshes, f == MeshFormat::glb);
}

Mesh read_mesh(const std::string& path, const MeshReadOptions& options) {
  const uint64_t cap = options.max_bytes ? options.max_bytes : default_memory_limit();
  const MeshFormat f = mesh_format_from_path(path);
  detail::file_size(path);  // uniform "no such file" message
  switch (f) {
    case MeshFormat::ply: return detail::read_ply(path, cap);
    case MeshFormat::obj: return detail::read_obj(path, cap);
    case MeshFormat::stl: return detail::read_stl(path, cap);
    case MeshFormat::off: return detail::read_off(path, cap);
    case MeshFormat::gltf: return detail::read_gltf(path, cap, false);
    case MeshFormat::glb: return detail::read_gltf(path, cap, true);
    case MeshFormat::vtk: return detail::read_vtk(path, cap);
    case MeshFormat::vtp: return detail::read_vtp(path, cap);
  }
  return {};
}

}  // namespace voxpress
