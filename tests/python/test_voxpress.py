"""The Python module against the CLI, nibabel and its own promises.

Run by ctest (tests/CMakeLists.txt) with PYTHONPATH=build/python and
VOXPRESS_CLI set to the command-line tool.
"""
import os
import subprocess

import numpy as np
import pytest

import voxpress

CLI = os.environ.get("VOXPRESS_CLI", "voxpress")


def cli(*args):
    subprocess.run([CLI, "-q", *map(str, args)], check=True, capture_output=True)


def ball(n=24, r=8.5):
    i, j, k = np.indices((n, n, n))
    return (i - n / 2 + 0.3) ** 2 + (j - n / 2) ** 2 + (k - n / 2 - 0.2) ** 2 < r * r


@pytest.mark.parametrize("method", ["pressing", "cesn", "diamond", "taubin"])
def test_same_mesh_as_the_cli(tmp_path, method):
    vol = tmp_path / "part.nrrd"
    cli("generate", "cad-part", "--res", 40, "--rotate", "random:3", "--spacing", "1,0.9,1.3", "-o", vol)
    cli("press", vol, "-o", tmp_path / "cli.ply", "--method", method)
    data, lattice = voxpress.read_volume(str(vol))
    assert data.shape == lattice.dims
    mesh = voxpress.press(data, spacing=lattice.spacing, origin=lattice.origin, direction=lattice.direction,
                          method=method)
    ref = voxpress.read_mesh(str(tmp_path / "cli.ply"))
    np.testing.assert_array_equal(mesh.faces, ref.faces)
    np.testing.assert_array_equal(mesh.vertices, ref.vertices)  # PLY keeps doubles exactly
    assert mesh.stats["method"] == method
    assert ("residual" in mesh.stats) == (method == "pressing")  # the press's residual reached (issue 74)


def test_axes_order_and_spacing_match_a_nifti_read_with_nibabel(tmp_path):
    nib = pytest.importorskip("nibabel")
    vol = tmp_path / "t.nii.gz"
    cli("generate", "torus", "--res", 36, "--rotate", "random:2", "--spacing", "0.8,1.1,1.7", "-o", vol)
    cli("press", vol, "-o", tmp_path / "cli.ply")
    img = nib.load(str(vol))
    data = np.asanyarray(img.dataobj)
    zooms = np.array(img.header.get_zooms()[:3], float)
    affine = img.affine
    kw = dict(spacing=zooms, origin=affine[:3, 3], direction=affine[:3, :3] / zooms)
    ref = voxpress.read_mesh(str(tmp_path / "cli.ply"))
    for mask, axes in [(data, "xyz"),                                         # nibabel: [i, j, k], Fortran order
                       (np.ascontiguousarray(data.transpose(2, 1, 0)), "zyx"),  # SimpleITK's order
                       (np.ascontiguousarray(data), "xyz")]:                   # C order
        mesh = voxpress.press(mask, axes=axes, **kw)
        np.testing.assert_array_equal(mesh.faces, ref.faces)
        np.testing.assert_allclose(mesh.vertices, ref.vertices, rtol=0, atol=1e-9)
    lo, hi = ref.vertices.min(0), ref.vertices.max(0)
    assert np.all(hi - lo > 10)  # in millimetres, not voxels


def test_labels_dtypes_and_the_guarantee():
    m = ball()
    labels = m.astype(np.int16) * 3
    labels[:4] = 7  # a second label
    with pytest.raises(voxpress.InputError, match="--label"):
        voxpress.press(labels)
    by_label = voxpress.press(labels, label=3)
    assert by_label.stats["vertices"] == voxpress.press(m.astype(np.uint8)).stats["vertices"]
    grey = m.astype(np.float32) * 100
    assert voxpress.press(grey, threshold=50).stats["sticks"] == by_label.stats["sticks"]
    for method in ["pressing", "diamond", "cell-edge"]:
        mesh = voxpress.press(m, method=method, spacing=(0.5, 0.5, 2.0))
        report = voxpress.check(mesh, m, spacing=(0.5, 0.5, 2.0))
        assert report["closed"] and report["manifold"] and report["oriented"]
        assert report["classification_violations"] == 0, method


def test_strided_views_read_like_their_copies():
    big = np.zeros((30, 60, 28), np.uint16)
    big[:24, :48:2, :24] = ball(24)[:, :24, :] * 9
    for view in [big[:24, :48:2, :24], big[::-1, ::2, :], np.asfortranarray(big)[:, ::2, ::-1]]:
        a = voxpress.press(view, method="diamond", label=9)
        b = voxpress.press(np.ascontiguousarray(view), method="diamond", label=9)
        np.testing.assert_array_equal(a.vertices, b.vertices)
        np.testing.assert_array_equal(a.faces, b.faces)


def test_bad_arguments_raise_clear_exceptions():
    m = ball()
    with pytest.raises(voxpress.UsageError, match="unknown method 'blur'"):
        voxpress.press(m, method="blur")
    with pytest.raises(voxpress.UsageError, match="3-D"):
        voxpress.press(np.zeros((4, 4), bool))
    with pytest.raises(voxpress.UsageError, match="axes"):
        voxpress.press(m, axes="xzy")
    with pytest.raises(voxpress.UsageError):
        voxpress.press(m, spacing=(1, -1, 1))
    with pytest.raises(voxpress.InputError, match="empty"):
        voxpress.press(np.zeros((5, 5, 5), bool))
    with pytest.raises(TypeError, match="smoothness"):
        voxpress.press(m, smoothness=3)
    with pytest.raises(voxpress.UsageError, match="lambda"):
        voxpress.press(m, method="diamond", lambda_=0.3)
    with pytest.raises(TypeError, match="unknown option 'spacng'"):
        voxpress.check(voxpress.press(m), m, spacng=(1, 1, 1))
    with pytest.raises(voxpress.InputError, match="no such file"):
        voxpress.read_volume("/nonexistent/x.nrrd")
    assert issubclass(voxpress.LimitError, voxpress.InputError)
    assert issubclass(voxpress.InputError, voxpress.Error)


@pytest.mark.parametrize("kwargs, message", [
    (dict(iterations=-1), "iterations"),
    (dict(tolerance=float("nan")), "tolerance"),
    (dict(junction_angle=-5), "junction_angle"),
    (dict(sharp_angle=400), "sharp_angle"),
    (dict(spacing="1,1,1"), "sequence of 3 numbers"),
    (dict(spacing=(1e150, 1, 1)), "spacing"),
    (dict(origin=(float("inf"), 0, 0)), "origin"),
    (dict(iterations=float("nan")), "iterations"),  # issue 73: bare cast RuntimeErrors before
    (dict(iterations=10**30), "iterations"),
    (dict(sharp_angle="wide"), "sharp_angle"),
])
def test_out_of_range_options_are_the_libraries_usage_errors(kwargs, message):
    with pytest.raises(voxpress.UsageError, match=message):
        voxpress.press(ball(12, 4.5), **kwargs)


def test_a_nested_list_is_an_array_like_mask():
    m = ball(12, 4.5)
    assert voxpress.press(m.astype(np.uint8).tolist()).vertices.shape == voxpress.press(m).vertices.shape


def test_truncated_tiff_is_an_error_naming_the_file(tmp_path):
    path = tmp_path / "stack.tif"
    cli("generate", "sphere", "--res", 24, "-o", path)
    data = path.read_bytes()
    for cut in (500, len(data) // 2, len(data) - 10):
        cut_path = tmp_path / f"cut{cut}.tif"
        cut_path.write_bytes(data[:cut])
        with pytest.raises(voxpress.InputError, match=f"cut{cut}.tif"):
            voxpress.read_volume(str(cut_path))


def test_disable_passes_reaches_the_sharpening():
    # A tilted plate 3 cells thick: its rim lies between two opposite flats.
    i, j, k = np.indices((56, 56, 56)).astype(float) - 27.6
    n = np.array([0.25, 0.15, 1.0]) / np.linalg.norm([0.25, 0.15, 1.0])
    u = np.cross(n, [1.0, 0, 0])
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    h = n[0] * i + n[1] * j + n[2] * k
    a = u[0] * i + u[1] * j + u[2] * k
    b = w[0] * i + w[1] * j + w[2] * k
    plate = (np.abs(h) < 1.5) & (np.abs(a) < 20) & (np.abs(b) < 14)
    walls, flat = voxpress.press(plate), voxpress.press(plate, disable_passes=["walls"])
    assert walls.stats["flats"] >= 2
    assert not np.array_equal(walls.vertices[: len(flat.vertices)], flat.vertices)
    for mesh in (walls, flat):
        assert voxpress.check(mesh, plate)["classification_violations"] == 0
    with pytest.raises(voxpress.UsageError, match="unknown pass 'wall'"):
        voxpress.press(plate, disable_passes=["wall"])


def test_mesh_outputs_and_evaluation(tmp_path):
    vol = tmp_path / "box.nrrd"
    cli("generate", "box", "--res", 48, "--rotate", "random:2", "-o", vol)
    data, lat = voxpress.read_volume(str(vol))
    mesh = voxpress.press(data, spacing=lat.spacing, origin=lat.origin, direction=lat.direction)
    assert mesh.regions is not None and mesh.regions.shape == (len(mesh.faces),)
    assert mesh.regions.max() >= 5  # six flats
    assert mesh.sharp_edges.shape[1] == 2 and len(mesh.sharp_edges) > 0
    mesh.save(str(tmp_path / "m.obj"))
    assert voxpress.read_mesh(str(tmp_path / "m.obj")).faces.shape == mesh.faces.shape
    for ext in ("vtp", "vtk"):  # VTK formats keep the doubles and the regions (cell data)
        mesh.save(str(tmp_path / f"m.{ext}"))
        back = voxpress.read_mesh(str(tmp_path / f"m.{ext}"))
        np.testing.assert_array_equal(back.vertices, mesh.vertices)
        np.testing.assert_array_equal(back.faces, mesh.faces)
        np.testing.assert_array_equal(back.regions, mesh.regions)
    e = voxpress.evaluate(mesh, volume=str(vol), samples=20000)
    m0_mesh = voxpress.press(data, spacing=lat.spacing, origin=lat.origin, direction=lat.direction,
                             method="taubin", iterations=0)
    m0 = voxpress.evaluate(m0_mesh, volume=str(vol), samples=20000)
    assert e["classification_violations"] == 0
    assert e["result_to_truth_vox"]["rms"] < 0.5 * m0["result_to_truth_vox"]["rms"]
    assert "result_to_truth_rule_rms" not in e
    q = voxpress.evaluate(m0_mesh, volume=str(vol), samples=20000, quadrature=True)
    sampled = q["result_to_truth_vox"]["rms"]
    assert abs(q["result_to_truth_rule_rms_vox"] - sampled) < 0.03 * sampled


def test_simplify_keeps_every_sample_on_its_side(tmp_path):
    vol = tmp_path / "part.nrrd"
    cli("generate", "cad-part", "--res", 32, "--rotate", "random:4", "-o", vol)
    data, lat = voxpress.read_volume(str(vol))
    where = dict(spacing=lat.spacing, origin=lat.origin, direction=lat.direction)
    full = voxpress.press(data, **where)
    small = voxpress.press(data, faces=700, **where)
    assert len(small.faces) <= 700 < len(full.faces) / 4
    assert small.stats["simplify"]["faces_before"] == len(full.faces)
    assert len(small.sharp_edges) > 0
    again = full.simplify(faces=700)  # the same collapses on the same mesh
    np.testing.assert_array_equal(again.vertices, small.vertices)
    np.testing.assert_array_equal(again.faces, small.faces)
    bounded = full.simplify(max_error=0.2)
    assert bounded.stats["simplify"]["error"] <= 0.2 and len(bounded.faces) < len(full.faces)
    for m in (small, bounded):
        assert voxpress.check(m, str(vol))["classification_violations"] == 0
    with pytest.raises(voxpress.UsageError, match="max_error"):
        full.simplify(max_error=-1)


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_no_memory_growth_over_1000_calls():
    m = ball(16, 5.5)
    for _ in range(100):  # warm up allocator pools
        voxpress.press(m, method="diamond").vertices.sum()
    before = rss_bytes()
    for _ in range(1000):
        mesh = voxpress.press(m, method="diamond")
        mesh.vertices.sum()
        mesh.faces.sum()
    growth = rss_bytes() - before
    assert growth < 4 << 20, f"RSS grew by {growth} bytes over 1000 calls"


def test_press_shows_its_real_signature_and_docstring():
    import inspect
    params = inspect.signature(voxpress.press).parameters
    for name in ("spacing", "method", "iterations", "junction_angle", "sharp_angle", "disable_passes", "lambda_"):
        assert name in params
    assert not any(p.kind == p.VAR_KEYWORD for p in params.values())
    assert "sharp_angle" in voxpress.press.__doc__
    with pytest.raises(TypeError, match="smoothness"):
        voxpress.press(ball(12, 4.5), smoothness=3)


def test_press_labels_every_label_at_once(tmp_path):
    n = 22
    i, j, k = np.indices((n, n, n))
    labels = np.zeros((n, n, n), np.uint16)
    labels[(i > 2) & (i < 11) & (j > 2) & (j < 19) & (k > 2) & (k < 19)] = 4
    labels[(i - 13) ** 2 + (j - 11) ** 2 + (k - 11) ** 2 < 36] = 9   # touches label 4
    labels[(i - 14) ** 2 + (j - 11) ** 2 + (k - 11) ** 2 < 4] = 700  # nested in label 9
    meshes = voxpress.press_labels(labels, spacing=(1, 1, 1.5))
    assert sorted(meshes) == [4, 9, 700]
    for value, mesh in meshes.items():
        report = voxpress.check(mesh, labels == value, spacing=(1, 1, 1.5))
        assert report["closed"] and report["manifold"] and report["oriented"], value
        assert report["classification_violations"] == 0, value
    some = voxpress.press_labels(labels, labels=[9], spacing=(1, 1, 1.5))
    assert list(some) == [9]
    np.testing.assert_array_equal(some[9].vertices, meshes[9].vertices)
    # Shared interfaces: each triangle of the combined surface is in its two
    # labels' meshes (the background has none), at the same positions.
    meshes2, shared = voxpress.press_labels(labels, spacing=(1, 1, 1.5), interfaces=True)
    pairs = shared.label_pairs
    assert pairs.shape == (len(shared.faces), 2) and set(np.unique(pairs)) == {0, 4, 9, 700}
    def triangles(mesh, rows, flip=False):
        tri = mesh.vertices[mesh.faces[rows]]
        if flip:
            tri = tri[:, ::-1]
        return sorted(tuple(np.roll(t, -int(np.lexsort(t.T[::-1])[0]), axis=0).ravel()) for t in tri)
    for value, mesh in meshes2.items():
        assert mesh.stats["shared"]
        want = triangles(shared, pairs[:, 0] == value) + triangles(shared, pairs[:, 1] == value, flip=True)
        assert triangles(mesh, np.arange(len(mesh.faces))) == sorted(want), value
    alone = voxpress.press_labels(labels, spacing=(1, 1, 1.5), separate=True)
    assert not alone[9].stats["shared"] and alone[9].stats["flats"] >= 0
    with pytest.raises(voxpress.UsageError, match="separate"):
        voxpress.press_labels(labels, color_regions=True)
    # The shared surface is fitted and sharpened as one label alone would be; sharpen=False keeps the chamfers.
    _, chamfered = voxpress.press_labels(labels, spacing=(1, 1, 1.5), sharpen=False, interfaces=True)
    assert chamfered.stats["crease_vertices"] == 0 and chamfered.stats["fitted_vertices"] >= 0
    assert 0 < chamfered.stats["residual"] < 1  # the shared press's, not converged in its 100 sweeps (issue 74)
    # Flats of the shared surface can be turned off: the plain shared press.
    plain, plain_shared = voxpress.press_labels(labels, spacing=(1, 1, 1.5), flats=False, interfaces=True)
    assert plain_shared.stats["flats"] == 0 and plain_shared.stats["flat_vertices"] == 0
    assert all(m.stats["flats"] == 0 for m in plain.values())
    with pytest.raises(voxpress.InputError, match="label 5"):
        voxpress.press_labels(labels, labels=[4, 5])
    with pytest.raises(voxpress.InputError):
        voxpress.press_labels(np.zeros((4, 4, 4), np.uint8))


def test_press_labels_takes_all_as_the_command_line_does():
    # issue 73: labels="all" raised a bare cast RuntimeError.
    vol = np.zeros((12, 12, 12), np.uint16)
    vol[2:10, 2:10, 2:6] = 7
    vol[2:10, 2:10, 6:10] = 300
    every = voxpress.press_labels(vol, labels="all")
    assert len(every) == len(voxpress.press_labels(vol))
    with pytest.raises(voxpress.UsageError, match="labels="):
        voxpress.press_labels(vol, labels="7,300")
    with pytest.raises(voxpress.UsageError, match="labels"):
        voxpress.press_labels(vol, labels=[7, "x"])
