#!/usr/bin/env python3
"""One STL per label of a NIfTI label map, in the file's RAS millimetres.

    examples/nifti_labels_to_stl.py seg.nii.gz out/        # out/label_<N>.stl for every label
    examples/nifti_labels_to_stl.py seg.nii.gz out/ --method diamond

Needs nibabel (apt install python3-nibabel) and the voxpress module
(PYTHONPATH=build/python, or `cmake --install build --component python`).
"""
import argparse
import os

import nibabel as nib
import numpy as np

import voxpress


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("labels", help="NIfTI label map (.nii or .nii.gz)")
    ap.add_argument("out", help="output folder")
    ap.add_argument("--method", default="pressing", help="pressing (default), diamond, cesn, taubin, ...")
    args = ap.parse_args()

    img = nib.load(args.labels)
    data = np.asanyarray(img.dataobj)      # indexed [i, j, k]: axes="xyz"
    zooms = np.array(img.header.get_zooms()[:3], float)
    lattice = dict(spacing=zooms, origin=img.affine[:3, 3], direction=img.affine[:3, :3] / zooms)
    os.makedirs(args.out, exist_ok=True)
    # Every label in one call (labels in parallel, each on its bounding box).
    for label, mesh in voxpress.press_labels(data, method=args.method, **lattice).items():
        path = os.path.join(args.out, f"label_{label}.stl")
        mesh.save(path)
        print(f"{path}: {mesh.stats['triangles']} triangles, {mesh.stats['flats']} flats")


if __name__ == "__main__":
    main()
