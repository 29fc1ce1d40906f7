"""The `manisoft` Python module's reach environment, used as a Gymnasium user would: the loop,
the spaces, the expert reaching its target, determinism, and bad input refused with a clear
exception that leaves the episode as it was. Run: PYTHONPATH=<build>/python python3 -m unittest."""
import math
import unittest

import numpy as np

import manisoft


class ReachEnvTest(unittest.TestCase):
    def test_spaces_and_reset(self):
        env = manisoft.make_env("reach", target_set="table", seed=1)
        space = env.action_space
        self.assertIsInstance(space, manisoft.Box)
        self.assertEqual((space.shape, space.dtype), ((20, 3), np.float64))
        high = space.high
        # Element 0 takes no torque; bend limits 150 N m, twist 75 N m (paper's actuation limits).
        np.testing.assert_array_equal(high[0], [0, 0, 0])
        np.testing.assert_array_equal(high[1:], np.tile([150.0, 150.0, 75.0], (19, 1)))
        np.testing.assert_array_equal(space.low, -high)
        obs, info = env.reset(seed=3)
        self.assertEqual(list(env.observation_space.keys()), ["end_effector", "target", "node_positions", "node_velocities", "time"])
        for key, space in env.observation_space.items():
            value = np.asarray(obs[key])
            self.assertEqual(value.shape, space.shape, key)
            self.assertEqual(value.dtype, space.dtype, key)
            self.assertTrue((space.low == -np.inf).all() and (space.high == np.inf).all(), key)  # unbounded
        self.assertEqual(env.observation_space["node_positions"].shape, (11, 3))  # every 2nd node of 20 elements and the tip
        self.assertTrue(env.observation_space.contains(obs))
        self.assertIs(env.action_space, env.action_space)  # one object: its seed holds
        # The arm starts straight along +x from its base at (-0.05, 0, 1.5): the tip node 1 m on.
        np.testing.assert_allclose(obs["node_positions"][0], [-0.05, 0, 1.5], atol=1e-12)
        np.testing.assert_allclose(obs["node_positions"][-1], [0.95, 0, 1.5], atol=1e-9)
        self.assertEqual(info["steps"], 0)
        self.assertFalse(info["success"])

    def test_expert_reaches_the_target_within_the_horizon(self):
        env = manisoft.make_env("reach", seed=0)
        obs, info = env.reset(seed=5)
        for _ in range(env.horizon):
            obs, reward, terminated, truncated, info = env.step(env.expert_action())
            if info["success"] or terminated or truncated:
                break
        self.assertTrue(info["success"], info)
        self.assertFalse(terminated)
        self.assertLess(info["position_error"], 0.03)
        self.assertLess(info["rotation_error"], 0.3)
        # The pose error is measured between the observed poses: check d_p's size by hand (the
        # translation of T_target^-1 T_ee bounds |d_p| within the small rotation left).
        relative = np.linalg.inv(obs["target"]) @ obs["end_effector"]
        self.assertLess(np.linalg.norm(relative[:3, 3]), 0.03 * 1.05)

    def test_same_seed_same_trajectory_bit_for_bit(self):
        runs = []
        for _ in range(2):
            env = manisoft.make_env("reach", seed=0)
            obs, _ = env.reset(seed=11)
            trace = []
            for _ in range(40):
                obs, reward, *_ = env.step(env.expert_action())
                trace.append((obs["end_effector"].copy(), reward))
            runs.append(trace)
        for (a, ra), (b, rb) in zip(*runs):
            self.assertTrue(np.array_equal(a, b))
            self.assertEqual(ra, rb)

    def test_truncated_at_the_horizon_and_clipping_counted(self):
        env = manisoft.make_env("reach", seed=0, horizon=5)
        env.reset(seed=2)
        # 1000 N m everywhere: every entry of the 19 actuated elements is clamped (element 0 is
        # zeroed, not counted), so 57 entries a step.
        flags = [env.step(np.full((20, 3), 1000.0))[2:4] for _ in range(5)]
        self.assertEqual(flags[:4], [(False, False)] * 4)
        self.assertEqual(flags[4], (False, True))
        env.reset(seed=2)
        self.assertEqual(env.step(np.full((20, 3), 1000.0))[4]["clipped"], 57)
        self.assertEqual(env.step(np.zeros((20, 3), dtype=np.float32))[4]["clipped"], 0)

    def test_bad_input_is_refused_and_changes_nothing(self):
        env = manisoft.make_env("reach", seed=0)
        with self.assertRaisesRegex(RuntimeError, "reset"):
            env.step(np.zeros((20, 3)))
        env.reset(seed=4)
        reference = manisoft.make_env("reach", seed=0)
        reference.reset(seed=4)
        with self.assertRaisesRegex(ValueError, r"shape \(20, 3\), got \(19, 3\)"):
            env.step(np.zeros((19, 3)))
        with self.assertRaisesRegex(ValueError, "dtype"):
            env.step(np.array([["a"] * 3] * 20))
        bad = np.zeros((20, 3))
        bad[7, 2] = math.nan
        with self.assertRaisesRegex(ValueError, r"entry \(7, 2\) = nan is not finite"):
            env.step(bad)
        # Nothing changed: the next valid step matches an environment that never saw the bad ones.
        a = env.step(np.ones((20, 3)))[0]["end_effector"]
        b = reference.step(np.ones((20, 3)))[0]["end_effector"]
        self.assertTrue(np.array_equal(a, b))
        with self.assertRaisesRegex(ValueError, "unknown option"):
            env.reset(options={"index": 3})
        with self.assertRaisesRegex(ValueError, r"reset: seed must be an integer in \[0, 2\^64\), got 'x' \(str\)"):
            env.reset(seed="x")
        # a list is an action (numpy.asarray), the same as the array
        a = env.step([[1.0] * 3] * 20)[0]["end_effector"]
        b = reference.step(np.ones((20, 3)))[0]["end_effector"]
        self.assertTrue(np.array_equal(a, b))
        env.close()
        with self.assertRaisesRegex(RuntimeError, "closed"):
            env.step(np.zeros((20, 3)))
        with self.assertRaisesRegex(ValueError, "unknown environment 'PICK'"):
            manisoft.make_env("PICK")
        with self.assertRaisesRegex(ValueError, "unknown target set"):
            manisoft.make_env("reach", target_set="moon")


if __name__ == "__main__":
    unittest.main()
