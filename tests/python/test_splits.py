"""Which scenes the programs draw: evaluate.py (examples/python) runs held-out scenes of the eval split
and generate_dataset (examples/benchmark) training scenes of the train split. Each runs a tiny case
and the split is read from what it produced: the environment evaluate.py stepped (its reset info and
the instruction its policy was given, against the sampler's eval and train scenes), and the episode
file generate_dataset wrote (its split attribute and the scene it stores, against the sampler's)."""
import json
import os
import shutil
import subprocess
import tempfile
import unittest
from unittest import mock

import h5py

import evaluate
import manisoft


class RecordingEnv:
    """A task environment that records the info of every reset and the instruction observed."""

    def __init__(self, env, log):
        self.env, self.log = env, log

    def reset(self, *args, **kwargs):
        obs, info = self.env.reset(*args, **kwargs)
        self.log.append((dict(info), obs["instruction"]))
        return obs, info

    def __getattr__(self, name):
        return getattr(self.env, name)


def instructions(scene_json):
    scene = json.loads(scene_json)
    return {scene["instruction"], *scene["instructions_seen"], *scene["instructions_unseen"]}


class SplitTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="manisoft_splits_")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def test_evaluate_runs_eval_scenes(self):
        log, make_env = [], manisoft.make_env
        with mock.patch.object(manisoft, "make_env", lambda *a, **k: RecordingEnv(make_env(*a, **k), log)):
            code = evaluate.main(["--task", "ARR", "--setting", "randomized", "--policy", "python:eval_policies:raising",
                                  "--indices", "3", "4", "--image-size", "32", "24", "--out", os.path.join(self.dir, "eval")])
        self.assertEqual(code, 0)
        self.assertEqual(len(log), 2)
        sampler = manisoft.SceneSampler()
        for (info, instruction), index in zip(log, (3, 4)):
            self.assertEqual((info["task"], info["setting"], info["index"], info["split"]), ("ARR", "randomized", index, "eval"))
            eval_scene = sampler.sample("ARR", "randomized", index, 0, "eval")
            train_scene = sampler.sample("ARR", "randomized", index, 0, "train")
            self.assertIn(instruction, instructions(eval_scene))
            self.assertNotIn(instruction, instructions(train_scene))

    def test_generate_dataset_writes_train_scenes(self):
        out = os.path.join(self.dir, "data")
        subprocess.run([os.environ["MANISOFT_GENERATE_DATASET"], "--tasks", "ALN", "--clean", "1", "--randomized", "0", "--seed", "6",
                        "--jobs", "1", "--out", out], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        with h5py.File(os.path.join(out, "episodes", "demo_0.hdf5"), "r") as f:
            attrs = f["data/demo_0"].attrs
            split, stored, index = attrs["split"], json.loads(attrs["scene"]), int(attrs["scene_index"])
        self.assertEqual(split, "train")
        sampler = manisoft.SceneSampler()
        train = json.loads(sampler.sample("ALN", "clean", index, 6, "train"))
        held_out = json.loads(sampler.sample("ALN", "clean", index, 6, "eval"))
        self.assertEqual(stored["split"], "train")
        self.assertEqual(stored["objects"], train["objects"])
        self.assertNotEqual(stored["objects"], held_out["objects"])


if __name__ == "__main__":
    unittest.main()
