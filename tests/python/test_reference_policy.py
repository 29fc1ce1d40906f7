"""The privileged-state reference policy (examples/python/reference_policy.py) on a tiny dataset
written by generate_dataset: training lowers the loss, the saved model acts as the trained network
did, a run stopped after some epochs and resumed ends with the uninterrupted run's weights, and its
act() drives the end-effector track through evaluate.py."""
import json
import os
import shutil
import subprocess
import tempfile
import unittest

import torch

import evaluate
import reference_policy as rp


def train_args(data, out, *extra):
    return ["train", "--data", data, "--out", out, "--tasks", "ALN", "--epochs", "20", "--batch", "64", "--width", "64",
            "--stride", "8", "--threads", "1", *extra]


class ReferencePolicyTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="manisoft_reference_")
        cls.data = os.path.join(cls.dir, "data")
        subprocess.run([os.environ["MANISOFT_GENERATE_DATASET"], "--tasks", "ALN", "--clean", "4", "--randomized", "1",
                        "--seed", "0", "--out", cls.data], check=True, stdout=subprocess.DEVNULL)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_training_lowers_the_loss_and_the_saved_model_acts_the_same(self):
        out = os.path.join(self.dir, "models")
        self.assertEqual(rp.main(train_args(self.data, out)), 0)
        model = rp.Policy(os.path.join(out, "ALN.pt"), torch)
        saved = torch.load(os.path.join(out, "ALN.pt"))
        losses = [train for _, train, _ in saved["history"]]
        self.assertEqual(len(losses), 20)
        self.assertLess(losses[-1], 0.5 * losses[0], losses)
        # the network as trained (the checkpoint's weights) and the model file read back by act()'s loader
        data, assets, _ = rp.build_dataset([self.data], "ALN", 8, 36)
        self.assertEqual(assets, saved["assets"])
        x = data["train"][0][:50]
        trained = rp.build_model(torch, x.shape[1], 64, 3)
        trained.load_state_dict(torch.load(os.path.join(out, "ALN.pt.checkpoint"))["model"])
        xn = torch.from_numpy((x - model.norm.x_mean) / model.norm.x_std)
        with torch.no_grad():
            self.assertTrue(torch.equal(trained(xn), model.model(xn)))

    def test_a_stopped_run_resumes_to_the_uninterrupted_weights(self):
        whole, parts = os.path.join(self.dir, "whole"), os.path.join(self.dir, "parts")
        rp.main(train_args(self.data, whole))
        rp.main(train_args(self.data, parts, "--stop-after", "2"))
        self.assertFalse(os.path.exists(os.path.join(parts, "ALN.pt")))
        self.assertEqual(torch.load(os.path.join(parts, "ALN.pt.checkpoint"))["epoch"], 2)
        rp.main(train_args(self.data, parts, "--resume"))
        a, b = torch.load(os.path.join(whole, "ALN.pt")), torch.load(os.path.join(parts, "ALN.pt"))
        self.assertEqual(a["history"], b["history"])
        for k in a["model"]:
            self.assertTrue(torch.equal(a["model"][k], b["model"][k]), k)

    def test_evaluate_runs_it_on_the_end_effector_track(self):
        models = os.path.join(self.dir, "eval_models")
        rp.main(train_args(self.data, models))
        os.environ["MANISOFT_REFERENCE_MODELS"] = models
        out = os.path.join(self.dir, "eval")
        code = evaluate.main(["--task", "ALN", "--setting", "clean", "--policy", "python:reference_policy:act", "--observation",
                              "privileged", "--action-mode", "ee_pose", "--indices", "0", "--out", out])
        self.assertEqual(code, 0)
        with open(os.path.join(out, "episodes.jsonl")) as f:
            episodes = [json.loads(line) for line in f if line.strip()]
        self.assertEqual(len(episodes), 1)
        # a model this small may fail the episode; it must fail it by the task, never by the policy
        self.assertNotIn(episodes[0]["failure"], ("policy_error", "bad_action", "policy_timeout"), episodes[0])
        self.assertGreater(episodes[0]["steps"], 36)


if __name__ == "__main__":
    unittest.main()
