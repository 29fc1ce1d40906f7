#!/usr/bin/env python3
"""Summarises a ManiSoft dataset with h5py and numpy only (no ManiSoft code), the way robomimic
reads it: the index file DIR/dataset.hdf5 links every episode under data/demo_<k>.

usage: /usr/bin/python3 read_dataset.py DIR
"""
import argparse
import json

import h5py
import numpy as np


def main(folder):
    with h5py.File(f"{folder}/dataset.hdf5", "r") as f:
        data = f["data"]
        env_args = json.loads(data.attrs["env_args"])
        demos = sorted(data.keys(), key=lambda name: int(name.split("_")[1]))
        steps = 0
        action_sum = 0.0
        tasks = {}
        for name in demos:
            demo = data[name]
            actions = demo["actions"][()]
            assert actions.shape[0] == demo.attrs["num_samples"], name
            steps += actions.shape[0]
            action_sum += float(np.sum(actions))
            key = f'{demo.attrs.get("task", "?")}/{demo.attrs.get("setting", "?")}'
            tasks[key] = tasks.get(key, 0) + 1
            for obs_name, obs in demo["obs"].items():
                assert obs.shape[0] == actions.shape[0], f"{name}/obs/{obs_name}"
        train = [m.decode() for m in f["mask/train"][()]]
        valid = [m.decode() for m in f["mask/valid"][()]]
        assert data.attrs["total"] == steps
        print(f"env_args {json.dumps(env_args, sort_keys=True)}")
        print(f"demos {len(demos)} steps {steps} train {len(train)} valid {len(valid)}")
        print(f"action sum {action_sum:.6f}")
        for key, count in sorted(tasks.items()):
            print(f"  {key}: {count}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="the dataset folder (holding dataset.hdf5)")
    main(parser.parse_args().folder)
