#!/usr/bin/env python3
"""export_zarr DIR OUT.zarr [--split train|valid|all]: a ManiSoft dataset (robomimic-layout HDF5)
as Diffusion Policy's zarr replay buffer (Debian python3-zarr): data/action (N x 61),
data/state, data/eef_pose, data/gripper, data/rod_centerline (N x 63), data/rod_directors (N x 180), data/ee_target (N x 7: the
end-effector track's action), data/ee_waypoint (N x 1) and data/img (N x H x W x 3
uint8, when the episodes carry an image at every step) concatenated over the episodes of the
split, and meta/episode_ends (int64, cumulative step counts), Diffusion Policy's ReplayBuffer
layout. Episodes with different object counts cannot share object_poses/state widths: state
and object_poses are padded with NaN-free zeros to the widest (meta/state_width gives each
episode's own width)."""
import argparse
import os
import shutil

import h5py
import numpy as np
import zarr


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("dir")
    p.add_argument("out")
    p.add_argument("--split", default="train", choices=("train", "valid", "all"))
    args = p.parse_args()
    with h5py.File(os.path.join(args.dir, "dataset.hdf5"), "r") as f:
        if args.split == "all":
            names = sorted(f["data"].keys(), key=lambda n: int(n.split("_")[1]))
        else:
            names = [m.decode() for m in f["mask"][args.split][()]]
        demos = [f["data"][n] for n in names]
        fixed = {"action": "actions", "eef_pose": "obs/eef_pose", "gripper": "obs/gripper", "rod_centerline": "obs/rod_centerline",
                 "rod_directors": "obs/rod_directors", "ee_target": "obs/ee_target", "ee_waypoint": "obs/ee_waypoint"}
        padded = {"state": "states", "object_poses": "obs/object_poses"}
        arrays = {k: np.concatenate([d[v][()] for d in demos]) for k, v in fixed.items()}
        for k, v in padded.items():
            width = max(d[v].shape[1] for d in demos)
            arrays[k] = np.concatenate([np.pad(d[v][()], ((0, 0), (0, width - d[v].shape[1]))) for d in demos])
        ends = np.cumsum([d["actions"].shape[0] for d in demos]).astype(np.int64)
        state_width = np.array([d["states"].shape[1] for d in demos], dtype=np.int64)
        if all("agentview_image" in d["obs"] for d in demos):
            arrays["img"] = np.concatenate([d["obs/agentview_image"][()] for d in demos])
    tmp = args.out + ".partial"
    shutil.rmtree(tmp, ignore_errors=True)
    root = zarr.open_group(tmp, mode="w")
    data, meta = root.create_group("data"), root.create_group("meta")
    for k, a in arrays.items():
        chunks = (min(len(a), 1 if k == "img" else 1024),) + a.shape[1:]
        data.array(k, a, chunks=chunks)
    meta.array("episode_ends", ends)
    meta.array("state_width", state_width)
    shutil.rmtree(args.out, ignore_errors=True)
    os.replace(tmp, args.out)
    print(f"{len(demos)} episodes, {ends[-1] if len(ends) else 0} steps -> {args.out} ({', '.join(arrays)})")


if __name__ == "__main__":
    main()
