"""Type stubs for voxpress (the C++ extension voxpress._voxpress)."""
from typing import Any, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class Error(RuntimeError): ...
class InputError(Error):
    """Bad input data: "<source>: <problem>" (exit code 1 in the CLI)."""
class LimitError(InputError):
    """A resource limit would be exceeded (checked before allocating)."""
class UsageError(Error):
    """Invalid or contradictory arguments (exit code 2 in the CLI)."""

Method = Literal["pressing", "cesn", "diamond", "cell-edge", "cell-size", "taubin", "laplacian"]

class Lattice:
    """physical = origin + direction @ diag(spacing) @ (i, j, k)."""
    @property
    def dims(self) -> Tuple[int, int, int]: ...
    @property
    def spacing(self) -> Tuple[float, float, float]: ...
    @property
    def origin(self) -> Tuple[float, float, float]: ...
    @property
    def direction(self) -> npt.NDArray[np.float64]:
        """3 x 3; column a is the physical direction of index axis a."""
    @property
    def space(self) -> str:
        """"LPS", "RAS" or "unknown"."""

class Mesh:
    """A triangle mesh in physical units, triangles counter-clockwise seen from outside."""
    @property
    def vertices(self) -> npt.NDArray[np.float64]:
        """N x 3 view of the positions (no copy; valid while the Mesh lives)."""
    @property
    def faces(self) -> npt.NDArray[np.int32]:
        """M x 3 vertex indices."""
    @property
    def regions(self) -> Optional[npt.NDArray[np.int32]]:
        """Per face: flat id, -1 for curved faces; None when flats were not searched."""
    @property
    def label_pairs(self) -> Optional[npt.NDArray[np.int64]]:
        """Per face of a shared surface (press_labels(interfaces=True)): its (inside, outside) labels; else None."""
    @property
    def sharp_edges(self) -> npt.NDArray[np.int32]:
        """K x 2 vertex pairs: the sharp feature curves."""
    @property
    def stats(self) -> dict[str, Any]:
        """method, sticks, vertices, triangles, iterations, flats, sharp_edges, keeps_classification, seconds_*."""
    def simplify(self, *, faces: int = 0, max_error: float = 0.0) -> "Mesh":
        """A copy with at most `faces` triangles and/or every vertex of this mesh within `max_error` (physical
        units) of it; labelled sharp edges, flat borders and regions are kept. A mesh from press() keeps every
        sample of its volume on its side (and stays closed, manifold, without self-intersection); a mesh read
        from a file keeps all but the samples, which it does not know. stats["simplify"]: faces, error, seconds."""
    def save(self, path: str, ascii: bool = False) -> None:
        """Writes .ply .obj .stl .off .glb .gltf .vtk .vtp atomically (no partial file on failure)."""

def press(
    mask: npt.ArrayLike,
    *,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    direction: Optional[npt.ArrayLike] = None,
    method: Method = "pressing",
    axes: Literal["xyz", "zyx"] = "xyz",
    label: Optional[Union[int, str]] = None,
    threshold: Optional[float] = None,
    iterations: int = ...,
    tolerance: float = ...,
    flats: bool = True,
    sharpen: bool = True,
    min_flat_area: float = 100,
    junction_angle: float = 30,
    sharp_angle: float = 30,
    disable_passes: Optional[Sequence[str]] = None,
    color_regions: bool = False,
    lambda_: float = ...,
    mu: float = ...,
    chunk: Optional[int] = None,
    halo: int = 0,
    faces: int = 0,
    max_error: float = 0.0,
) -> Mesh:
    """The smooth surface of a 3-D mask, as `voxpress press` computes it.

    faces / max_error: simplify the result (as `press --faces / --max-error`),
    every sample still on its side.

    mask: bool, integer-label or float array; C or Fortran order. axes="xyz"
    indexes it mask[i, j, k] (nibabel); "zyx" mask[k, j, i]
    (SimpleITK.GetArrayFromImage). Inside samples: a mask with one non-zero
    value needs nothing; label maps need label=N (or "all-nonzero"), grey
    images threshold=T (value >= T). spacing, origin and direction always
    refer to the x, y, z (i, j, k) axes, whatever `axes` says — pass
    SimpleITK's GetSpacing(), GetOrigin() and GetDirection() (reshaped 3 x 3)
    unchanged with axes="zyx". direction: 3 x 3, column a = physical
    direction of index axis a. The GIL is released while it works.
    """

def chunk_plan(shape: Sequence[int], *, chunk: int = 256, halo: int = 0) -> list[dict[str, Any]]:
    """The blocks of a volume, x fastest: [{"block": b, "core": (lo, hi), "read": (lo, hi)}] (voxpress.dask)."""
    ...

def press_labels(
    array: npt.ArrayLike,
    labels: Optional[Sequence[float]] = None,
    *,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    origin: Sequence[float] = (0.0, 0.0, 0.0),
    direction: Optional[npt.ArrayLike] = None,
    method: Method = "pressing",
    axes: Literal["xyz", "zyx"] = "xyz",
    separate: bool = False,
    interfaces: bool = False,
    **options: Any,
) -> Union[dict[float, Mesh], Tuple[dict[float, Mesh], Mesh]]:
    """Every label of an integer label map (0 = background) at once: {label: Mesh}.

    labels=None takes every non-zero value; an absent value raises
    InputError. Each mesh keeps its label's samples inside and all others
    outside. By default the meshes are cut from one pressed surface shared
    by all labels: where two labels touch, their meshes hold the same
    triangles (opposite orientations) at bit-identical positions.
    interfaces=True also returns that surface, each interface once, with
    Mesh.label_pairs. The shared surface gets each label's flats
    (flats=False: none; min_flat_area, junction_angle apply) but no
    sharpening. separate=True (or a baseline method) meshes each label
    alone, with press()'s flats and sharpening; touching labels' surfaces
    may then overlap. Options: press()'s (iterations, tolerance, flats;
    sharpen, sharp_angle, fit_rings, color_regions with separate=True only).
    """

def read_volume(path: str) -> Tuple[npt.NDArray[Any], Lattice]:
    """A volume file (NRRD, NIfTI, MetaImage, TIFF) as an array indexed [i, j, k] (no copy) and its lattice."""

def read_mesh(path: str) -> Mesh:
    """A .ply .obj .stl .off .glb .gltf .vtk .vtp mesh (STL welded)."""

def check(mesh: Mesh, volume: Union[str, npt.ArrayLike, None] = None, **lattice: Any) -> dict[str, Any]:
    """check_mesh (closed, manifold, oriented, self-intersections); with a volume (path, or a mask with
    spacing/origin/direction/axes/label/threshold keywords) also the samples on the wrong side."""

def evaluate(mesh: Mesh, *, truth: str = "", volume: Union[str, npt.ArrayLike, None] = None,
             samples: int = 200000) -> dict[str, Any]:
    """Distances to the true surface, as `voxpress eval` (truth: a mesh file or a volume that remembers its model)."""
