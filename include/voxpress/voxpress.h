// voxpress/voxpress.h — everything, for convenience.
#pragma once

#include "voxpress/core/error.h"
#include "voxpress/core/lattice.h"
#include "voxpress/core/mesh.h"
#include "voxpress/core/progress.h"
#include "voxpress/core/types.h"
#include "voxpress/core/volume.h"
#include "voxpress/eval/checks.h"
#include "voxpress/eval/shapes.h"
#include "voxpress/extract/cube_cases.h"
#include "voxpress/extract/sticks.h"
#include "voxpress/io/atomic_file.h"
#include "voxpress/io/image_io.h"
#include "voxpress/io/mesh_io.h"
#include "voxpress/io/volume_file.h"
#include "voxpress/io/volume_io.h"
#include "voxpress/render/render.h"
#include "voxpress/features/flats.h"
#include "voxpress/smooth/pressing.h"
#include "voxpress/smooth/mesh_smoothing.h"
#include "voxpress/smooth/pipeline.h"
#include "voxpress/labels/labels.h"
#include "voxpress/labels/shared_flats.h"
#include "voxpress/labels/shared_surface.h"
#include "voxpress/labels/shared_fit.h"
#include "voxpress/labels/shared_press.h"
#include "voxpress/labels/shared_sharpen.h"
#include "voxpress/chunk/chunked.h"
#include "voxpress/chunk/chunked_labels.h"
#include "voxpress/features/sharpen.h"
#include "voxpress/smooth/surface_nets.h"
#include "voxpress/voxart/polygonize.h"
#include "voxpress/voxart/voxel_art.h"

namespace voxpress {
inline constexpr const char* kVersion = "0.1.0";
}
