"""Chunked Pressing from Python: press(..., chunk=) is `press --chunk`, and
voxpress.dask.press on a LocalCluster of 2 worker processes gives the same
bytes as the in-process chunked run.
"""
import os
import subprocess

import numpy as np
import pytest

import voxpress

CLI = os.environ.get("VOXPRESS_CLI", "voxpress")


def cli(*args):
    subprocess.run([CLI, "-q", *map(str, args)], check=True, capture_output=True)


def test_chunked_press_is_the_clis(tmp_path):
    vol = tmp_path / "part.nrrd"
    cli("generate", "cad-part", "--res", 40, "--rotate", "random:4", "--spacing", "1,0.9,1.3", "-o", vol)
    cli("press", vol, "--chunk", 16, "--halo", 14, "-o", tmp_path / "cli.ply")
    data, lattice = voxpress.read_volume(str(vol))
    mesh = voxpress.press(data, spacing=lattice.spacing, origin=lattice.origin, direction=lattice.direction,
                          chunk=16, halo=14)
    ref = voxpress.read_mesh(str(tmp_path / "cli.ply"))
    np.testing.assert_array_equal(mesh.faces, ref.faces)
    np.testing.assert_array_equal(mesh.vertices, ref.vertices)
    assert mesh.stats["blocks"] == len(voxpress.chunk_plan(data.shape, chunk=16, halo=14))
    # Pressed block by block in rounds: the whole run without flats, up to rounding.
    plain = voxpress.press(data, spacing=lattice.spacing, origin=lattice.origin, direction=lattice.direction,
                           flats=False)
    np.testing.assert_array_equal(mesh.faces, plain.faces)
    np.testing.assert_allclose(mesh.vertices, plain.vertices, rtol=0, atol=1e-9)
    with pytest.raises(voxpress.UsageError, match="--halo 5"):
        voxpress.press(data, chunk=16, halo=5)
    assert voxpress.check(mesh, data, spacing=lattice.spacing, origin=lattice.origin,
                          direction=lattice.direction)["ok"]
    # Without a halo (exact): the whole run's bytes, flats and sharp edges included.
    whole = voxpress.press(data, spacing=lattice.spacing, origin=lattice.origin, direction=lattice.direction)
    exact = voxpress.press(data, spacing=lattice.spacing, origin=lattice.origin, direction=lattice.direction, chunk=16)
    np.testing.assert_array_equal(exact.vertices, whole.vertices)
    np.testing.assert_array_equal(exact.faces, whole.faces)
    np.testing.assert_array_equal(exact.sharp_edges, whole.sharp_edges)
    assert exact.stats["flats"] == whole.stats["flats"] > 0
    with pytest.raises(voxpress.UsageError):
        voxpress.press(data, halo=5)
    with pytest.raises(voxpress.UsageError):
        voxpress.press(data, chunk=4)


def test_plan_covers_the_volume_once():
    plan = voxpress.chunk_plan((50, 33, 17), chunk=16, halo=3)
    seen = np.zeros((50, 33, 17), dtype=int)
    for b in plan:
        (x0, y0, z0), (x1, y1, z1) = b["core"]
        seen[x0:x1, y0:y1, z0:z1] += 1
        (rx0, ry0, rz0), (rx1, ry1, rz1) = b["read"]
        assert rx0 == max(0, x0 - 3) and rx1 == min(50, x1 + 3) and rz1 == min(17, z1 + 3)
    assert (seen == 1).all()
    assert [b["block"] for b in plan] == list(range(len(plan)))


def sphere(n, seed=1):
    rng = np.random.default_rng(seed)
    c = n / 2 + rng.uniform(-0.5, 0.5, 3)
    i, j, k = np.indices((n, n, n), dtype=np.float32)
    return (i - c[0]) ** 2 + ((j - c[1]) / 0.9) ** 2 + ((k - c[2]) / 1.1) ** 2 < (0.38 * n) ** 2


def test_dask_on_a_local_cluster_gives_the_in_process_bytes():
    pytest.importorskip("dask")
    distributed = pytest.importorskip("distributed")
    import dask.array as da

    import voxpress.dask

    mask = sphere(256)
    spacing, origin = (0.8, 0.8, 1.2), (-3.0, 4.0, 10.0)
    ref = voxpress.press(mask, spacing=spacing, origin=origin)  # the whole run: exact mode gives its bytes
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        array = da.from_array(mask.astype(np.uint8), chunks=96)  # Dask's chunks need not be the blocks
        # split_every=3: the 8 pieces merge on the workers (3 + 3 + 2), then the caller stitches 3.
        mesh = voxpress.dask.press(array, chunk=128, spacing=spacing, origin=origin, client=client, split_every=3)
        # Blocks pressed on the workers (a halo): each block held on a worker
        # between its rounds, the pieces moving between the processes.
        part = mask[100:164, 100:164, 20:84]
        held = voxpress.dask.press(da.from_array(part, chunks=32), chunk=32, halo=12, client=client)
    apart = voxpress.press(part, chunk=32, halo=12)
    np.testing.assert_array_equal(held.vertices, apart.vertices)
    np.testing.assert_array_equal(held.faces, apart.faces)
    np.testing.assert_array_equal(mesh.faces, ref.faces)
    np.testing.assert_array_equal(mesh.vertices, ref.vertices)
    assert mesh.stats["blocks"] == 8
    assert voxpress.check(mesh)["ok"]
    # Blocks pressed on the workers (a halo), the threaded scheduler, a label:
    # the in-process run with the same halo.
    labels = np.where(mask, 3, 0).astype(np.int16)[100:164, 100:164, 20:84]
    again = voxpress.dask.press(da.from_array(labels, chunks=32), chunk=32, halo=12, label=3, split_every=2)
    small = voxpress.press(labels == 3, chunk=32, halo=12)
    np.testing.assert_array_equal(again.vertices, small.vertices)
    np.testing.assert_array_equal(again.faces, small.faces)
    assert again.stats["iterations"] == small.stats["iterations"]
    assert again.stats["residual"] == small.stats["residual"]
    with pytest.raises(voxpress.InputError):
        voxpress.dask.press(da.zeros((32, 32, 32), chunks=16), chunk=16)
    with pytest.raises(voxpress.UsageError):
        voxpress.dask.press(labels, chunk=32, split_every=1)


def label_phantom():
    """A rotated box (1) with a sphere (2) pressed into it, a sphere (3) nested
    in that one: three-label junctions, a flat box; anisotropic spacing."""
    i, j, k = np.indices((56, 52, 40), dtype=np.float64)
    x0, y0, z = i - 27.5, (j - 25.5) * 1.1, (k - 19.5) * 1.3
    c, s = np.cos(0.35), np.sin(0.35)
    x, y = c * x0 - s * y0, s * x0 + c * y0
    out = np.zeros(i.shape, np.uint16)
    out[(np.abs(x + 6) < 15) & (np.abs(y) < 13) & (np.abs(z) < 14)] = 1
    r2 = (x - 9) ** 2 + y ** 2 + z ** 2
    out[r2 < 13 ** 2] = 2
    out[r2 < 5 ** 2] = 300
    return out


def test_dask_label_maps_give_press_labels_bytes():
    pytest.importorskip("dask")
    distributed = pytest.importorskip("distributed")
    import dask.array as da

    import voxpress.dask

    vol = label_phantom()
    spacing, origin = (1.0, 1.1, 1.3), (5.0, -2.0, 7.5)
    ref, ref_all = voxpress.press_labels(vol, spacing=spacing, origin=origin, interfaces=True)
    assert sorted(ref) == [1, 2, 300] and ref[1].stats["flats"] > 0  # the box's faces: masks read back from Dask
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        got, got_all = voxpress.dask.press_labels(da.from_array(vol, chunks=24), chunk=16, spacing=spacing,
                                                  origin=origin, client=client, interfaces=True)
    assert sorted(got) == sorted(ref)
    for label, mesh in ref.items():
        np.testing.assert_array_equal(got[label].vertices, mesh.vertices)
        np.testing.assert_array_equal(got[label].faces, mesh.faces)
        assert got[label].stats["flats"] == mesh.stats["flats"]
    np.testing.assert_array_equal(got_all.vertices, ref_all.vertices)
    np.testing.assert_array_equal(got_all.faces, ref_all.faces)
    # The threaded scheduler, a selection, no flats: press_labels's bytes again.
    some = voxpress.dask.press_labels(vol, labels=[300], chunk=20, flats=False)
    alone = voxpress.press_labels(vol, labels=[300], flats=False)
    assert list(some) == [300]
    np.testing.assert_array_equal(some[300].vertices, alone[300].vertices)
    with pytest.raises(voxpress.InputError):
        voxpress.dask.press_labels(np.zeros((20, 20, 20), np.uint8), chunk=8)
    with pytest.raises(voxpress.InputError):
        voxpress.dask.press_labels(vol, labels=[7], chunk=32)


def test_dask_press_labels_takes_all_as_press_labels_does():
    # issue 73: labels="all" was split into the characters 'a', 'l', 'l'.
    pytest.importorskip("dask")
    import voxpress.dask

    vol = np.zeros((12, 12, 12), np.uint16)
    vol[2:10, 2:10, 2:6] = 7
    vol[2:10, 2:10, 6:10] = 300
    every = voxpress.dask.press_labels(vol, labels="all", chunk=8, flats=False)
    assert sorted(every) == [7, 300]
    ref = voxpress.press_labels(vol, flats=False)
    for label, mesh in ref.items():
        np.testing.assert_array_equal(every[label].faces, mesh.faces)
    with pytest.raises(voxpress.UsageError, match="labels="):
        voxpress.dask.press_labels(vol, labels="7,300", chunk=8)


def test_a_held_block_is_the_same_after_any_round_and_through_pickle():
    """voxpress.dask keeps a block extracted between its rounds (_BlockRounds):
    a round changes nothing it holds, and a worker that receives it pickled
    extracts it again to the same rounds."""
    import pickle

    mask = sphere(48)
    shape, chunk, halo = mask.shape, 24, 12
    inside = np.argwhere(mask)
    bounds = (inside.min(axis=0).tolist(), (inside.max(axis=0) + 1).tolist())
    rounds = voxpress._voxpress._press_rounds(shape, halo=halo, bounds=bounds)
    assert len(rounds) > 2 and rounds[-1][2] and not rounds[0][2]  # only the last stage's rounds are measured
    plan = voxpress.chunk_plan(shape, chunk=chunk, halo=halo)
    (x0, y0, z0), (x1, y1, z1) = plan[0]["read"]
    args = dict(shape=shape, block=0, chunk=chunk, halo=halo, bounds=bounds, threads=1)
    held = voxpress._voxpress._BlockRounds(mask[x0:x1, y0:y1, z0:z1], args)
    first = held.round([], rounds[0][0], rounds[0][1])
    later = held.round([first], rounds[1][0], rounds[1][1])
    again = pickle.loads(pickle.dumps(held))
    assert held.nbytes > 0
    for a, b in [(first, held.round([], rounds[0][0], rounds[0][1])), (first, again.round([], rounds[0][0], rounds[0][1])),
                 (later, again.round([first], rounds[1][0], rounds[1][1]))]:
        for key in ("sticks", "t", "velocity"):
            np.testing.assert_array_equal(a[key], b[key])
    assert not np.array_equal(first["t"], later["t"])
    with pytest.raises(voxpress.UsageError, match="repeated"):
        held.round([first, first], rounds[1][0], rounds[1][1])
