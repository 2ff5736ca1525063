"""voxpress: smooth, accurate solids from binary voxel volumes.

    import numpy as np, voxpress
    mesh = voxpress.press(mask, spacing=(0.8, 0.8, 2.5))   # Pressing: every sample kept on its side
    mesh.save("organ.stl")

Methods: "pressing" (default), "cesn", "diamond", "cell-edge", "cell-size",
"taubin", "laplacian". Errors raise voxpress.InputError / UsageError /
LimitError (all voxpress.Error) with the command line's messages.
See voxpress/__init__.pyi for the signatures.
"""
from . import _voxpress
from ._voxpress import (  # noqa: F401
    Error,
    chunk_plan,
    InputError,
    Lattice,
    LimitError,
    Mesh,
    UsageError,
    __version__,
    check,
    evaluate,
    read_mesh,
    read_volume,
)


def press(mask, *, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0), direction=None, method="pressing",
          axes="xyz", label=None, threshold=None, iterations=None, tolerance=None, flats=None, sharpen=None,
          min_flat_area=None, junction_angle=None, sharp_angle=None, disable_passes=None, color_regions=None,
          fit_rings=None, lambda_=None, mu=None, chunk=None, halo=None, faces=None, max_error=None):
    """The smooth surface of a 3-D mask, as `voxpress press` computes it; returns a Mesh.

    mask: bool, integer-label or float array (anything numpy.asarray takes);
    C or Fortran order. axes="xyz" indexes it mask[i, j, k] (nibabel); "zyx"
    mask[k, j, i] (SimpleITK.GetArrayFromImage). spacing, origin and
    direction (3 x 3, column a = physical direction of index axis a) always
    refer to the i, j, k axes. Inside samples: a mask with one non-zero value
    needs nothing; label maps need label=N (or "all-nonzero"), grey images
    threshold=T (value >= T).

    method: "pressing" (default; every sample kept on its side), "cesn",
    "diamond", "cell-edge", "cell-size", "taubin", "laplacian".
    Options left at None keep the method's default:
      iterations, tolerance  the smoothing's cap (pressing: 100) and stop (1e-4)
      flats (True), sharpen (True)  plane voting and sharp-edge recovery (pressing)
      min_flat_area (100 cells), junction_angle (30 deg), sharp_angle (30 deg),
      color_regions (False), fit_rings (5)
      disable_passes  names of feature-layer passes to switch off, e.g.
                     ["curved-creases"] (the list: voxpress press --help)
      lambda_, mu  Taubin / Laplacian steps
      chunk, halo  block by block, as `press --chunk N [--halo H]`: without a
                   halo the same mesh; with one, blocks pressed apart in
                   exchange rounds (no flats; the same surface as flats=False
                   up to rounding); voxpress.dask runs the blocks on Dask
      faces, max_error  simplify the result (as `press --faces / --max-error`):
                   at most `faces` triangles, every input vertex within
                   max_error (physical units), every sample still on its side;
                   Mesh.simplify does the same to a mesh afterwards
    Out-of-range values raise UsageError with the command line's message; the
    GIL is released while it works.
    """
    options = dict(iterations=iterations, tolerance=tolerance, flats=flats, sharpen=sharpen,
                   min_flat_area=min_flat_area, junction_angle=junction_angle, sharp_angle=sharp_angle,
                   disable_passes=None if disable_passes is None else list(disable_passes),
                   color_regions=color_regions, fit_rings=fit_rings,
                   lambda_=lambda_, mu=mu, chunk=chunk, halo=halo, faces=faces, max_error=max_error)
    return _voxpress.press(mask, spacing=spacing, origin=origin, direction=direction, method=method, axes=axes,
                           label=label, threshold=threshold,
                           **{k: v for k, v in options.items() if v is not None})


def press_labels(array, labels=None, *, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0), direction=None,
                 method="pressing", axes="xyz", **options):
    """Every label of a label map at once, as `voxpress press --labels`: {label: Mesh}.

    array: integer label map (0 = background); labels: None or "all" for
    every non-zero value, or an iterable of values (an absent one raises
    InputError). By default every label is cut from one pressed shared
    surface: touching labels share their interface vertex for vertex, each
    mesh keeps its own label's samples inside and every other sample
    outside; each label's flats are found (flats=False: none) and their
    creases sharpened once for both sides (sharpen=False: chamfers).
    interfaces=True returns ({label: Mesh}, the shared surface
    with face attributes label_in / label_out). separate=True (or a baseline
    method) meshes each label alone on its box, with the whole feature
    layer. spacing, origin, direction, axes, method and the options are
    press()'s. voxpress.dask.press_labels does this block by block.
    """
    if "disable_passes" in options and options["disable_passes"] is not None:
        options["disable_passes"] = list(options["disable_passes"])
    return _voxpress.press_labels(array, labels=labels if labels is None or isinstance(labels, str) else list(labels), spacing=spacing,
                                  origin=origin, direction=direction, method=method, axes=axes,
                                  **{k: v for k, v in options.items() if v is not None})


__all__ = ["Error", "InputError", "LimitError", "UsageError", "Lattice", "Mesh", "press", "press_labels", "read_volume",
           "read_mesh", "check", "evaluate", "chunk_plan", "__version__"]
