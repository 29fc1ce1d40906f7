"""The SAC executor trainer (examples/python/sac_executor.py) on a tiny run: a run stopped and
resumed ends with the weights of an uninterrupted one, the exported weight file gives the C++ MLP
executor the Python network's actions, and the reach reward's R_s switch (stability_beta) changes
the reward by the paper's -sgn(dd/dt) beta term only."""
import os
import tempfile
import unittest

import numpy as np
import torch

import manisoft
import sac_executor

TINY = ["--envs", "3", "--threads", "2", "--horizon", "60", "--repeat", "10", "--warmup", "12", "--batch", "16",
        "--hidden", "16", "16", "--updates", "1", "--eval-every", "2", "--eval-targets", "2", "--seed", "5"]


def train(out, *extra):
    sac_executor.main(["train", "--out", out, *TINY, *extra])
    return torch.load(os.path.join(out, "checkpoint.pt"))


def without_time(log):
    return [{k: v for k, v in e.items() if k != "seconds"} for e in log]


class SacExecutorTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        cls.whole = train(os.path.join(cls.dir.name, "whole"), "--rounds", "4")

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def test_a_resumed_run_ends_with_the_uninterrupted_weights(self):
        out = os.path.join(self.dir.name, "resumed")
        stopped = train(out, "--rounds", "4", "--stop-after", "2")
        self.assertEqual(stopped["round"], 2)
        resumed = train(out, "--rounds", "4", "--resume")
        self.assertEqual(resumed["round"], 4)
        self.assertGreater(resumed["updates"], 0)
        for part in ("actor", "critics", "targets"):
            for key, value in self.whole["sac"][part].items():
                self.assertTrue(torch.equal(value, resumed["sac"][part][key]), f"{part}.{key}")
        self.assertEqual(without_time(self.whole["log"]), without_time(resumed["log"]))
        self.assertIn("eval_success", self.whole["log"][1])  # every second round evaluates

    def test_the_exported_file_gives_the_cpp_executor_the_networks_actions(self):
        path = os.path.join(self.dir.name, "executor.mlp")
        checkpoint = os.path.join(self.dir.name, "whole", "checkpoint.pt")
        sac_executor.main(["export", checkpoint, path])
        args = self.whole["args"]
        import argparse
        sac = sac_executor.Sac(torch, torch.nn, 90, 12, argparse.Namespace(**args))
        sac.load(self.whole["sac"])
        executor = manisoft.MlpExecutor(path)
        env = manisoft.make_env("reach", horizon=40)
        high = np.asarray(env.action_space.high)
        obs, _ = env.reset(seed=11)
        for _ in range(30):
            batch = {k: np.asarray(v)[None] for k, v in obs.items() if k != "time"}
            with torch.no_grad():
                _, _, u = sac.policy(torch.from_numpy(sac_executor.features(batch).astype(np.float32)))
            expected = sac_executor.torques(u.numpy().astype(np.float64), sac_executor.basis(high))[0]
            action = executor.act(obs)
            self.assertEqual(action.shape, (20, 3))
            np.testing.assert_array_equal(action[0], 0)  # element 0 takes no torque
            np.testing.assert_allclose(action, expected, atol=1e-4 * 150)  # float32 network, double executor
            obs, *_ = env.step(action)

    def test_distilled_executor_fits_the_model_executor_and_starts_sac(self):
        out = os.path.join(self.dir.name, "distilled")
        sac_executor.main(["distill", "--out", out, "--iterations", "2", "--targets", "2", "--horizon", "300", "--epochs", "150",
                           "--hidden", "32", "32", "--eval-targets", "2", "--seed", "3"])
        log = torch.load(os.path.join(out, "checkpoint.pt"))["log"]
        self.assertEqual([e["samples"] for e in log], [200, 400])  # 2 targets x 300 steps / stride 3, twice
        # the network's torques are much closer to the model executor's than zero torques on its own
        # noisy episodes, and closer on the blended DAgger episodes' states too
        self.assertLess(log[0]["loss"], 0.1 * log[0]["zero_torque_loss"])
        self.assertLess(log[1]["loss"], 0.5 * log[1]["zero_torque_loss"])
        best = torch.load(os.path.join(out, "best.pt"))  # the iteration that reached most held-out targets, the first of equals
        scores = [(e["eval_reached"], e["eval_success"]) for e in log]
        self.assertEqual(best["iteration"], 1 + scores.index(max(scores)))
        sac_executor.main(["curves", os.path.join(out, "curves.png"), out])
        with open(os.path.join(out, "curves.png"), "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        sac_executor.main(["export", os.path.join(out, "checkpoint.pt"), os.path.join(out, "executor.mlp")])
        self.assertEqual(manisoft.MlpExecutor(os.path.join(out, "executor.mlp")).act(manisoft.make_env("reach").reset(seed=1)[0]).shape, (20, 3))
        post = ("--rounds", "3", "--init", os.path.join(out, "checkpoint.pt"), "--hidden", "32", "32", "--init-log-std", "-3", "--actor-delay", "3")
        tuned = train(os.path.join(self.dir.name, "tuned"), *post)
        self.assertGreater(tuned["updates"], 0)
        # --anchor holds the post-trained actor near the clone: its deterministic actions move less
        # than plain SAC's from the same start, seeds and updates
        held = train(os.path.join(self.dir.name, "held"), *post, "--anchor", "1000")
        self.assertIsNotNone(held["sac"]["anchor"])
        import argparse
        states = torch.from_numpy(sac_executor.features({k: np.stack([np.asarray(manisoft.make_env("reach").reset(seed=i)[0][k]) for i in range(8)])
                                                         for k in ("target", "end_effector", "node_positions", "node_velocities")}).astype(np.float32))

        def actions(checkpoint):
            sac = sac_executor.Sac(torch, torch.nn, states.shape[1], 12, argparse.Namespace(**tuned["args"]))
            sac.load(checkpoint["sac"], weights_only=True)
            with torch.no_grad():
                return sac.policy(states)[2]

        start = actions(torch.load(os.path.join(out, "checkpoint.pt")))
        moved_free, moved_held = (float((actions(c) - start).abs().max()) for c in (tuned, held))
        self.assertGreater(moved_free, 0)
        self.assertLess(moved_held, 0.5 * moved_free)
        with self.assertRaises(SystemExit):
            sac_executor.main(["train", "--out", os.path.join(self.dir.name, "bad"), *TINY, "--anchor", "1"])

    def test_stability_beta_switches_the_paper_stability_term(self):
        # The model executor's actions, replayed in batches with beta = 1 and beta = 0: the rewards
        # differ by R_s = -sgn(d_t - d_{t-1}) while d = |d_p| + 0.2 |d_r| <= D = 0.3, else 0.
        env = manisoft.make_env("reach", horizon=700)
        env.reset(seed=3)
        actions, rewards = [], []
        for _ in range(700):
            actions.append(np.array(env.expert_action()))
            _, r, *_ = env.step(actions[-1])
            rewards.append(r)
        runs = {}
        for beta in (1.0, 0.0):
            vec = manisoft.make_vec_env("reach", 1, num_threads=1, horizon=700, stability_beta=beta)
            vec.reset(seed=3)
            got = []
            for a in actions:
                _, r, _, _, info = vec.step(a[None])
                got.append((float(r[0]), float(info["position_error"][0] + 0.2 * info["rotation_error"][0])))
            runs[beta] = np.array(got)
            vec.close()
        np.testing.assert_array_equal(runs[1.0][:, 0], rewards)  # the batch's beta = 1 is the environment's default
        d = runs[0.0][:, 1]
        expected = np.where(d[1:] <= 0.3, -np.sign(d[1:] - d[:-1]), 0.0)
        self.assertGreater(np.count_nonzero(expected), 100)  # the arm spends time near the target
        np.testing.assert_allclose(runs[1.0][1:, 0] - runs[0.0][1:, 0], expected, atol=1e-12)
        self.assertEqual(runs[1.0][0, 0], runs[0.0][0, 0])  # no rate at the first step


if __name__ == "__main__":
    unittest.main()
