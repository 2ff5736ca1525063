"""voxpress: smooth, accurate solids from binary voxel volumes.

    import numpy as np, voxpress
    mesh = voxpress.press(mask, spacing=(0.8, 0.8, 2.5))   # Pressing: every sample kept on its side
    mesh.save("organ.stl")

Methods: "pressing" (default), "cesn", "diamond", "cell-edge", "cell-size",
"taubin", "laplacian". Errors raise voxpress.InputError / UsageError /
LimitError (all voxpress.Error) with the command line's messages.
See voxpress/__init__.pyi for the signatures.
"""
from ._voxpress import (  # noqa: F401
    Error,
    InputError,
    Lattice,
    LimitError,
    Mesh,
    UsageError,
    __version__,
    check,
    evaluate,
    press,
    read_mesh,
    read_volume,
)

__all__ = ["Error", "InputError", "LimitError", "UsageError", "Lattice", "Mesh", "press", "read_volume",
           "read_mesh", "check", "evaluate", "__version__"]
