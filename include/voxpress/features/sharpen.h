// voxpress/features/sharpen.h — sharp edge recovery (Pressing, Chica et al.,
// Section 5) and the flat / curved / sharp segmentation as output.
//
// The pressed stick surface cuts every feature with a chamfer one cell wide:
// its vertices sample the lattice edges, never the crease itself. Sharpening
// inserts the crease (Section 5, Fig. 8-10):
//
//  0. Beyond the paper: curved bands and corner patches the flats' rims
//     stopped short of, recognised because the flats' own solid (their
//     half-spaces intersected at a convex crease, united at a concave one)
//     crosses their sticks, slide along their sticks onto the flats
//     (`snap_rings`, `snap_tolerance`, `snap_share`; a patch at least half
//     explained retries the rest with twice the rings, for a corner's third
//     flat); a curved face's sticks lie outside that solid and stay.
//     Beyond the paper, the curved vertices next to the final junctions are
//     placed again by the crease fit (`final_crease_rings`).
//  1. Chamfer edges join vertices of two different regions (two flats, or a
//     flat and a curved junction vertex; beyond the paper, also the two
//     sides of a crease between curved faces, `curved_creases`); smooth
//     flat/curved borders (no junction) and flats meeting at less than
//     `min_angle` are left alone.
//     Each chamfer edge gets a new vertex; a triangle with one chamfer edge
//     becomes 2 triangles, with two 3, with three 6 around a new corner vertex.
//  2. Each side of a chamfer edge has a plane: a flat's own plane, or for a
//     curved junction vertex the least-squares plane of the fresh,
//     non-junction vertices in its 2-ring. A new edge vertex moves to the
//     closest point of the two planes' intersection line, a corner vertex to
//     the three planes' intersection; both solved as a truncated
//     least-squares problem (directions the planes do not pin stay where the
//     vertex is), and left in place when the planes meet at less than
//     `min_angle` or the solution lies more than `max_move` cells away.
//     Beyond the paper, on a flat/curved edge the two planes' solid must
//     agree with the samples of the edge's sticks; where it does not, the
//     curved side's plane moves onto the misplaced sample, or the vertex
//     stays (sample_wedges).
//  3. The new vertices form chains along the new edges (corners and ends
//     fixed); the chains are smoothed with a bilaplacian, each vertex moving
//     across its chain only and, next to a flat, within the flat's plane.
//     Beyond the paper, each chain is first judged whole (round-chains,
//     src/features/sharpen_chains.cpp): where its samples allow and demand
//     a fillet the lattice resolves, its vertices stay on the chamfer and
//     are not labelled, so a filleted edge stays round.
//  4. Beyond the paper — the guarantee survives: every move is checked
//     exactly before it is made. A vertex moving from p to q sweeps each
//     incident triangle (p, a, b) through the tetrahedron (p, q, a, b); a
//     move is cut back (bisection) until no lattice sample lies in any swept
//     tetrahedron, no incident triangle turns over and none meets another
//     triangle nearby. So no sample ever changes side, and the mesh stays
//     closed, 2-manifold and free of self-intersections. The move also keeps
//     a clearance of 4x the worst float32 rounding (to every sample, between
//     triangles, on every altitude), so the guarantee survives STL and glTF
//     output (src/core/clearance.h).
//
// Output: the refined mesh (physical units) with a face attribute "region"
// (flat id, or -1: curved, including the faces straddling a smooth border),
// vertex attributes "region", "junction" and "feature" (1 on a sharp curve),
// and mesh.edges = the edges of the sharp feature curves (the creases whose
// two sides meet at `sharp_angle` or more).
#pragma once

#include <cstdint>
#include <vector>

#include "voxpress/core/mesh.h"
#include "voxpress/core/progress.h"
#include "voxpress/extract/sticks.h"
#include "voxpress/features/flats.h"

namespace voxpress {

struct SharpenOptions {
  double sharp_angle = 30;    ///< degrees between the two sides' normals above which a crease is labelled sharp
  double margin = 0.01;       ///< snapped vertices keep t in [margin, 1 - margin] on their sticks
  bool colors = false;        ///< vertex colours per region (flats, curved grey, junctions orange, features red)
  PassSet passes;             ///< the layer's passes (voxpress/features/passes.h)
  Progress* progress = nullptr;
};

struct SharpenStats {
  size_t chamfer_edges = 0, chamfer_triangles = 0;
  size_t inserted = 0, corners = 0;   ///< new edge vertices, new corner vertices
  size_t fallbacks = 0;               ///< new vertices left where inserted (parallel planes, far solution, no plane)
  size_t snapped = 0;                 ///< original vertices slid along their sticks onto a flat (snap_to_flats)
  size_t tangent_planes = 0;          ///< curved sides whose plane is their quadric's tangent plane
  size_t wall_vertices = 0;           ///< vertices given a thin wall's plane (fit_walls)
  size_t final_crease_vertices = 0;   ///< curved vertices placed again by the crease fit (final_crease_fit)
  size_t curved_crease_vertices = 0;  ///< vertices placed on creases between two curved faces (curved_creases)
  size_t past_crease = 0;             ///< curved junction vertices past their crease that joined the flat
  size_t left_flat = 0;               ///< flat members past their crease that left the flat (past_creases)
  size_t inherited_junctions = 0;     ///< curved vertices made junctions by a joined neighbour (inherit_junctions)
  size_t wedge_checks = 0;            ///< chamfer edges whose two planes' solid misplaced a sample (sample_wedge)
  size_t wedge_shifts = 0;            ///< ... of which the curved side's plane was moved onto the sample
  size_t round_chains = 0;            ///< chains left round: their samples allow a fillet the lattice resolves
  size_t cut_back = 0;                ///< moves shortened to keep the guarantee or the mesh valid
  size_t sharp_edges = 0;             ///< labelled sharp edges (mesh.edges)
  PassTimes passes;                   ///< Stage::sharpen's passes (setup and output as Pass::sharpen), and the trace
  double seconds = 0;
};

struct SharpenResult {
  Mesh mesh;
  SharpenStats stats;
};

/// Sharpens the pressed `surface` segmented by `flats` (from press_with_flats).
/// Without flats the result is to_mesh(surface) with the attributes.
SharpenResult sharpen(const StickSurface& surface, const FlatSegmentation& flats, const SharpenOptions& options = {});

}  // namespace voxpress
