#pragma once
// What --max-memory charges per unit of work, in one place (issue 73). Each
// figure is the measured peak (`/usr/bin/time -f %M`, less the 14 MiB the
// process holds before any work: `/usr/bin/time -f %M voxpress --version`)
// over the units, rounded up; docs/RELIABILITY.md has the table.
#include <cstdint>
#include <string>

namespace voxpress {

/// Once per run that does work: the thread pool's stacks and the writer's
/// buffers (`extract BallBinary30x30x30.nrrd` peaks 1.1 MiB above `--version`;
/// `press totalseg_heart.nii.gz` 25.4 MiB above it for 23.9 charged without
/// this; voxart deer.vox 2.4 MiB for 1.3).
inline constexpr uint64_t kRunBytesFixed = 2 << 20;
/// Voxel art, per cell of a part's grid: colours 4, the solid fill's masks and
/// stack, the cuberille's padded masks and face slots (read_voxel_art;
/// `voxpress voxart monu1.vox -o m.glb`: 80 x 80 x 115 cells).
inline constexpr uint64_t kVoxartBytesPerCell = 16;
/// Voxel art, per cuberille quad: the quad mesh, its triangles, fairing,
/// the atlas's half-edges, neighbours and charts, the glTF buffers; 826 on
/// menger.vox (`voxpress voxart menger.vox -o m.glb --stats-json s.json`).
inline constexpr uint64_t kVoxartBytesPerQuad = 1024;
/// Voxel art, per atlas texel: the RGBA texture and its PNG encoding
/// (`voxpress voxart dragon.vox -o d.glb`: a 2226 x 2575 atlas).
inline constexpr uint64_t kVoxartBytesPerTexel = 8;
/// A voxelized or generated (`voxpress generate`) volume, per sample: the mask, its scalar copy for
/// the writer and the compressed payload (`voxpress voxelize bunny.off --res 200`:
/// 13.7 MiB for 6.25 M samples, 2.3 bytes).
inline constexpr uint64_t kVolumeOutBytesPerSample = 3;
/// render, per supersampled pixel: depth 4, colour 3 (`voxpress render
/// armadillo.obj -o a.png`: 2400 x 1800 supersamples).
inline constexpr uint64_t kRenderBytesPerSupersample = 7;
/// render, per byte of a mesh file: what reading it charged (OBJ: 4) stays
/// in the heap (`voxpress render armadillo.obj --size 200x150`: 16.3 MiB).
inline constexpr uint64_t kRenderBytesPerMeshFileByte = 4;
/// eval, per triangle of the result: its copy, BVH, area samples, distance and
/// self-intersection work (`voxpress eval heart.ply --truth bunny.off`: 47 MiB
/// for 76 914 faces, 610 a face; bunny.ply from `voxelize --res 200`: 470).
inline constexpr uint64_t kEvalBytesPerResultFace = 640;
/// press --labels, per sample of a label map held in memory: the samples, the
/// label view and masks (`voxpress press pyradiomics_brain1_label.nrrd --labels
/// all -o L`: 13.9 MiB for 1.64 M samples and 10 188 interface triangles;
/// pyradiomics_lung2_label.nrrd: 94 MiB for 16 M samples).
inline constexpr uint64_t kLabelBytesPerSample = 8;
/// press --labels, per label: its mesh, flats box mask and output
/// (totalseg_example_seg_fast_force_split.nii.gz, 61 labels: 4.8 MiB above
/// its samples and 256 bytes per interface triangle).
inline constexpr uint64_t kLabelBytesPerLabel = 128 << 10;
/// A mesh in memory, per vertex (position 24, its projection or normal 24)
/// and per triangle (12 and its per-face work 12), as render holds them
/// (`voxpress render armadillo.obj -o a.png`: 43 243 vertices, 86 482 faces).
inline constexpr uint64_t kMeshBytesPerVertex = 48, kMeshBytesPerTriangle = 24;

/// The voxel faces of a preview (render, report), per face: two triangles,
/// about one shared corner and its hash entry (`voxpress report
/// totalseg_heart.nii.gz --methods voxels`).
inline constexpr uint64_t kVoxelFaceBytes = 160;

/// Throws LimitError naming `path` when `bytes` exceed `cap` (0: no cap):
/// "<what> needs N, above the memory limit of M" in MiB, KiB or bytes.
void charge_memory(const std::string& path, uint64_t bytes, uint64_t cap, const std::string& what);

}  // namespace voxpress
