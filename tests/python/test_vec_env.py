"""The vector environments (manisoft.make_vec_env) against single environments: each reach arm
bit-identical to make_env("reach") with the same seeds and actions at 1 and 2 threads, reset
masks, Gymnasium's NEXT_STEP autoreset, bad actions refused with nothing changed; each task arm
bit-identical to make_env(task, render=False, privileged=True) on the same scene, on the torque
and the end-effector tracks, autoreset at the horizon, the camera images against the single
environment's; and the spaces' sample / contains.
Run: PYTHONPATH=<build>/python python3 -m unittest test_vec_env."""
import unittest

import numpy as np

import manisoft

B = 3
SEED = 20  # arm i starts with seed SEED + i
OBSERVATIONS = ("end_effector", "target", "node_positions", "node_velocities")
INFOS = ("success", "steps", "position_error", "rotation_error", "clipped")
# after a reset the batch reports the new episode's pose error, the single environment none (0)
RESET_INFOS = ("success", "steps", "clipped")


def actions_for(singles, rng):
    """The expert's action of each single environment plus noise (a learner's kind of action)."""
    return np.stack([env.expert_action() + rng.normal(scale=5.0, size=(20, 3)) * (np.arange(20) > 0)[:, None]
                     for env in singles])


class VecAgainstSingle(unittest.TestCase):
    """Arm i of the batch against single environment i: exact equality of every returned value."""

    def assert_arm_equals(self, vec_result, i, single_result, info_keys=INFOS):
        obs, reward, terminated, truncated, info = vec_result
        s_obs, s_reward, s_terminated, s_truncated, s_info = single_result
        for key in OBSERVATIONS:
            self.assertTrue(np.array_equal(obs[key][i], s_obs[key]), f"arm {i} {key}")
        self.assertEqual((reward[i], terminated[i], truncated[i]), (s_reward, s_terminated, s_truncated), f"arm {i}")
        for key in info_keys:
            self.assertEqual(info[key][i], s_info[key], f"arm {i} info {key}")

    def run_against_singles(self, threads):
        horizon = 5
        vec = manisoft.make_vec_env("reach", B, num_threads=threads, seed=SEED, horizon=horizon)
        self.assertEqual(vec.num_threads, threads)
        singles = [manisoft.make_env("reach", seed=SEED + i, horizon=horizon) for i in range(B)]
        obs, info = vec.reset()
        np.testing.assert_array_equal(info["seed"], SEED + np.arange(B))
        for i, env in enumerate(singles):
            s_obs, s_info = env.reset()  # seed SEED + i
            self.assert_arm_equals((obs, np.zeros(B), np.zeros(B, bool), np.zeros(B, bool), info), i,
                                   (s_obs, 0.0, False, False, s_info), RESET_INFOS)
        rng = np.random.default_rng(0)
        for step in range(1, horizon + 1):
            a = actions_for(singles, rng)
            result = vec.step(a)
            for i, env in enumerate(singles):
                self.assert_arm_equals(result, i, env.step(a[i]))
            if step == 2:  # reset arm 1 alone (its own seed 99): the arms' episodes fall out of step
                before = {key: np.array(obs_value) for key, obs_value in result[0].items()}
                steps_before = np.array(result[4]["steps"])
                obs, info = vec.reset(seed=[0, 99, 0], options={"reset_mask": np.array([False, True, False])})
                s_obs, s_info = singles[1].reset(seed=99)
                self.assert_arm_equals((obs, np.zeros(B), np.zeros(B, bool), np.zeros(B, bool), info), 1,
                                       (s_obs, 0.0, False, False, s_info), RESET_INFOS)
                for i in (0, 2):  # untouched
                    for key in OBSERVATIONS:
                        self.assertTrue(np.array_equal(obs[key][i], before[key][i]), key)
                    self.assertEqual(info["steps"][i], steps_before[i])
                np.testing.assert_array_equal(info["seed"], [SEED, 99, SEED + 2])
                np.testing.assert_array_equal(info["steps"], [2, 0, 2])
        # Arms 0 and 2 reached the horizon in the last step (truncated); arm 1 is at step 3.
        obs, reward, terminated, truncated, info = result
        np.testing.assert_array_equal(truncated, [True, False, True])
        np.testing.assert_array_equal(terminated, [False, False, False])
        # NEXT_STEP: the next step resets arms 0 and 2 (seed + B) and ignores their actions (NaN
        # here: not even checked), returning the new episode's first observation, reward 0, no flags.
        a = actions_for(singles, rng)
        a[0] = np.nan
        a[2] = 1e9
        obs, reward, terminated, truncated, info = result = vec.step(a)
        np.testing.assert_array_equal(info["seed"], [SEED + B, 99, SEED + 2 + B])
        np.testing.assert_array_equal(info["steps"], [0, 4, 0])
        for i in (0, 2):
            s_obs, s_info = singles[i].reset(seed=SEED + i + B)
            self.assert_arm_equals(result, i, (s_obs, 0.0, False, False, s_info), RESET_INFOS)
        self.assert_arm_equals(result, 1, singles[1].step(a[1]))
        # and the new episodes go on like fresh single environments (arm 1 reaches its horizon)
        a = actions_for(singles, rng)
        result = vec.step(a.tolist())  # lists are accepted
        for i, env in enumerate(singles):
            self.assert_arm_equals(result, i, env.step(a[i]))
        np.testing.assert_array_equal(result[3], [False, True, False])
        vec.close()

    def test_one_thread(self):
        self.run_against_singles(1)

    def test_two_threads(self):
        self.run_against_singles(2)


class VecEnvApi(unittest.TestCase):
    def setUp(self):
        self.vec = manisoft.make_vec_env("reach", B, num_threads=2, seed=SEED)

    def tearDown(self):
        self.vec.close()

    def test_attributes_and_spaces(self):
        vec = self.vec
        self.assertEqual(vec.num_envs, B)
        self.assertEqual(vec.metadata["autoreset_mode"], "NextStep")  # Gymnasium 1.x's AutoresetMode.NEXT_STEP value
        self.assertIs(vec.metadata["autoreset_mode"], manisoft.AutoresetMode.NEXT_STEP)
        single = manisoft.make_env("reach").action_space
        self.assertEqual(vec.single_action_space, single)
        self.assertEqual(vec.action_space.shape, (B, 20, 3))
        for i in range(B):
            np.testing.assert_array_equal(vec.action_space.high[i], single.high)
        self.assertEqual(list(vec.single_observation_space.keys()), list(OBSERVATIONS))
        self.assertEqual(vec.observation_space["node_positions"].shape, (B, 11, 3))
        self.assertEqual(manisoft.make_vec_env("reach", 1).num_threads, __import__("os").cpu_count())

    def test_returns_arrays_of_leading_dimension_b_read_only(self):
        obs, info = self.vec.reset()
        self.assertTrue(self.vec.observation_space.contains(obs))
        obs, reward, terminated, truncated, info = self.vec.step(np.zeros((B, 20, 3), np.float32))
        self.assertEqual((reward.shape, reward.dtype), ((B,), np.float64))
        self.assertEqual((terminated.dtype, truncated.dtype), (np.bool_, np.bool_))
        for key in INFOS + ("max_node_speed", "seed"):
            self.assertEqual(info[key].shape, (B,), key)
            mask = info["_" + key]  # Gymnasium's vector info convention: which arms have the key (all)
            self.assertEqual((mask.dtype, mask.tolist()), (np.bool_, [True] * B), key)
        self.assertEqual(sorted(k for k in info if not k.startswith("_")), sorted(k[1:] for k in info if k.startswith("_")))
        self.assertTrue(self.vec.observation_space.contains(obs))
        with self.assertRaises(ValueError):  # a view of the batch's buffer: read-only
            obs["end_effector"][0, 0, 0] = 1.0
        kept = np.array(obs["node_positions"])
        self.vec.step(np.zeros((B, 20, 3)))
        self.assertFalse(np.array_equal(kept, obs["node_positions"]))  # the view shows the new step

    def test_bad_action_refused_naming_the_arm_and_nothing_changes(self):
        good = manisoft.make_vec_env("reach", B, num_threads=2, seed=SEED)
        actions = np.full((B, 20, 3), 3.0)
        for vec in (self.vec, good):
            vec.reset()
            vec.step(actions)
        bad = actions.copy()
        bad[2, 4, 1] = np.nan
        with self.assertRaisesRegex(ValueError, r"arm 2: action entry \(4, 1\) = nan"):
            self.vec.step(bad)
        with self.assertRaisesRegex(ValueError, r"shape \(3, 20, 3\)"):
            self.vec.step(np.zeros((B, 19, 3)))
        with self.assertRaisesRegex(ValueError, "dtype must be real"):
            self.vec.step(np.zeros((B, 20, 3), complex))
        with self.assertRaisesRegex(ValueError, "reset_mask"):
            self.vec.reset(options={"reset_mask": [1, 0, 0]})
        with self.assertRaisesRegex(ValueError, "num_envs"):
            self.vec.reset(seed=[1, 2])
        a = self.vec.step(actions)
        b = good.step(actions)
        for key in OBSERVATIONS:
            self.assertTrue(np.array_equal(a[0][key], b[0][key]), key)
        np.testing.assert_array_equal(a[1], b[1])
        np.testing.assert_array_equal(a[4]["steps"], [2, 2, 2])
        good.close()

    def test_seeds(self):
        _, info = self.vec.reset()
        np.testing.assert_array_equal(info["seed"], SEED + np.arange(B))
        _, info = self.vec.reset()  # None: each arm's next seed (+ num_envs)
        np.testing.assert_array_equal(info["seed"], SEED + B + np.arange(B))
        _, info = self.vec.reset(seed=7)
        np.testing.assert_array_equal(info["seed"], 7 + np.arange(B))

    def test_closed(self):
        self.vec.close()
        with self.assertRaisesRegex(RuntimeError, "closed"):
            self.vec.reset()
        with self.assertRaisesRegex(ValueError, "unknown environment 'PICK'"):
            manisoft.make_vec_env("PICK", 2)


class Spaces(unittest.TestCase):
    def test_box(self):
        box = manisoft.Box(-np.array([1.0, 2.0]), np.array([1.0, np.inf]), (2,))
        box.seed(5)
        first = [box.sample() for _ in range(20)]
        box.seed(5)
        self.assertTrue(all(np.array_equal(a, box.sample()) for a in first))  # repeatable
        for x in first:
            self.assertTrue(box.contains(x))
            self.assertEqual(x.dtype, np.float64)
        self.assertTrue(box.contains(np.array([1.0, 1e300])))
        self.assertFalse(box.contains(np.array([1.0 + 1e-12, 0.0])))  # above high
        self.assertFalse(box.contains(np.array([0.0, -2.5])))  # below low
        self.assertFalse(box.contains(np.array([np.nan, 0.0])))
        self.assertFalse(box.contains(np.zeros(3)))  # shape
        self.assertFalse(box.contains(np.zeros(2, complex)))  # dtype
        self.assertTrue(box.contains([0.5, 3]))  # a list, taken as float64

    def test_integer_box_and_others(self):
        image = manisoft.Box(0, 255, (2, 3, 3), np.uint8)
        image.seed(1)
        self.assertTrue(image.contains(image.sample()))
        self.assertFalse(image.contains(np.zeros((2, 3, 3))))  # float64 does not cast to uint8 safely
        text = manisoft.Text(10, min_length=1)
        text.seed(2)
        self.assertTrue(text.contains(text.sample()))
        self.assertFalse(text.contains(5))
        self.assertFalse(text.contains(""))
        poses = manisoft.Sequence(manisoft.Box(-np.inf, np.inf, (4, 4)), seed=3)
        self.assertTrue(poses.contains(poses.sample()))
        self.assertTrue(poses.contains(np.zeros((3, 4, 4))))
        self.assertFalse(poses.contains(np.zeros((3, 4, 3))))

    def test_environment_spaces(self):
        env = manisoft.make_env("reach")
        space = env.action_space
        space.seed(0)
        a = space.sample()
        self.assertTrue(space.contains(a))
        self.assertTrue((a[0] == 0).all())  # element 0 takes no torque: low = high = 0
        space.seed(0)
        self.assertTrue(np.array_equal(a, env.action_space.sample()))
        too_big = np.zeros((20, 3))
        too_big[3, 2] = 75.0 + 1e-9  # twist limit 75 N m
        self.assertFalse(space.contains(too_big))
        obs_space = env.observation_space
        obs_space.seed(4)
        sample = obs_space.sample()
        self.assertTrue(obs_space.contains(sample))
        del sample["time"]
        self.assertFalse(obs_space.contains(sample))  # a key missing


TASK_OBSERVATIONS = ("rod_nodes", "end_effector", "gripper_pose", "gripper_width", "gripper_state")


class TaskVecAgainstSingle(unittest.TestCase):
    """make_vec_env(task): arm i against make_env(task, render=False, privileged=True) reset to the
    same scene and driven by the same actions (the single environment's expert, with noise)."""

    def assert_arm_equals(self, vec_result, i, single_result):
        obs, reward, terminated, truncated, info = vec_result
        s_obs, s_reward, s_terminated, s_truncated, s_info = single_result
        for key in TASK_OBSERVATIONS:
            self.assertTrue(np.array_equal(obs[key][i], s_obs[key]), f"arm {i} {key}")
        count = obs["object_count"][i]
        self.assertEqual(count, len(s_obs["object_poses"]))
        self.assertTrue(np.array_equal(obs["object_poses"][i][:count], np.asarray(s_obs["object_poses"])), f"arm {i} object_poses")
        self.assertFalse(obs["object_poses"][i][count:].any())
        self.assertEqual(obs["instruction"][i], s_obs["instruction"])
        self.assertEqual((reward[i], terminated[i], truncated[i]), (s_reward, s_terminated, s_truncated), f"arm {i}")
        self.assertEqual((info["success"][i], info["steps"][i], info["failure"][i]), (s_info["success"], s_info["steps"], s_info["failure"]))

    def run_against_singles(self, threads, steps=120):
        vec = manisoft.make_vec_env("ALN", B, num_threads=threads, setting="clean", seed=0)
        self.assertEqual((vec.num_threads, vec.single_action_space.shape, vec.action_space.shape), (threads, (61,), (B, 61)))
        obs, info = vec.reset(seed=4)  # arm i: scene index 4 + i
        np.testing.assert_array_equal(info["seed"], 4 + np.arange(B))
        singles = [manisoft.make_env("ALN", "clean", seed=0, render=False, privileged=True) for _ in range(B)]
        for i, env in enumerate(singles):
            s_obs, s_info = env.reset(options={"index": 4 + i})
            self.assert_arm_equals((obs, np.zeros(B), np.zeros(B, bool), np.zeros(B, bool), info), i, (s_obs, 0.0, False, False, s_info))
        for key in TASK_OBSERVATIONS + ("object_poses", "object_count"):
            self.assertTrue(vec.single_observation_space[key].contains(obs[key][0]), key)
        rng = np.random.default_rng(1)
        for _ in range(steps):
            a = np.stack([env.expert_action() for env in singles])
            a[:, 3:-1] += rng.normal(scale=1.0, size=(B, 57))  # element 0 takes no torque, S stays
            result = vec.step(a)
            for i, env in enumerate(singles):
                self.assert_arm_equals(result, i, env.step(a[i]))
        vec.close()

    def test_one_thread(self):
        self.run_against_singles(1)

    def test_two_threads(self):
        self.run_against_singles(2)

    def test_autoreset_after_a_terminal_failure_and_at_the_horizon(self):
        """Zero torques: in COLL scene 10 the falling arm knocks the object off the table
        (terminated, object_off_table), scene 11 runs to the horizon (truncated, timeout). Each arm
        against a single environment reset to the next index (+ B) at the step after its episode
        ended, as NEXT_STEP prescribes, over the whole horizon."""
        vec = manisoft.make_vec_env("COLL", 2, num_threads=2, seed=0, first_index=10)
        obs, info = vec.reset()
        np.testing.assert_array_equal(info["seed"], [10, 11])
        zero = np.zeros((2, 61))
        bad = zero.copy()
        bad[1, 7] = np.nan
        with self.assertRaisesRegex(ValueError, r"arm 1: action entry 7 \(element 2, component d2\) = nan is not finite"):
            vec.step(bad)
        singles = [manisoft.make_env("COLL", "clean", seed=0, render=False, privileged=True) for _ in range(2)]
        index = [10, 11]
        for i, env in enumerate(singles):
            env.reset(options={"index": index[i]})
        ended = [None, None]  # the single episode's last result, until the arm resets
        events = []
        for step in range(manisoft.HORIZON + 1):
            actions = zero.copy()
            actions[[i for i in range(2) if ended[i]]] = np.nan  # an ending arm's action is ignored, not even checked
            result = vec.step(actions)
            for i, env in enumerate(singles):
                if ended[i]:
                    index[i] += 2
                    s_obs, s_info = env.reset(options={"index": index[i]})
                    expected = (s_obs, 0.0, False, False, s_info)
                    events.append((step, i, index[i], ended[i][4]["failure"]))
                    ended[i] = None
                else:
                    expected = env.step(zero[i])
                    if expected[2] or expected[3]:
                        ended[i] = expected
                self.assert_arm_equals(result, i, expected)
                self.assertEqual(result[4]["seed"][i], index[i])
        # arm 0 restarted after its terminal failure, arm 1 after the horizon
        self.assertEqual(events[0][1:], (0, 12, "object_off_table"))
        self.assertIn((manisoft.HORIZON, 1, 13, "timeout"), events)
        with self.assertRaisesRegex(ValueError, "unknown environment 'PICK'"):
            manisoft.make_vec_env("PICK", 2)
        vec.close()

    def test_end_effector_track_against_singles(self):
        """action_mode="ee_pose": arm i against make_env(task, action_mode="ee_pose") on the same scene
        and targets (around the home pose, closing the gripper after 10 commands), two threads, with
        the commands' outcomes and control steps; a bad entry is refused by name."""
        vec = manisoft.make_vec_env("COLL", B, num_threads=2, seed=0, action_mode="ee_pose", action_repeat=12)
        self.assertEqual((vec.single_action_space.shape, vec.action_space.shape, vec.action_repeat), ((7,), (B, 7), 12))
        obs, info = vec.reset(seed=7)
        singles = [manisoft.make_env("COLL", "clean", seed=0, render=False, privileged=True, action_mode="ee_pose", action_repeat=12)
                   for _ in range(B)]
        home = np.array(obs["end_effector"][:, :3, 3])
        for i, env in enumerate(singles):
            s_obs, s_info = env.reset(options={"index": 7 + i})
            self.assert_arm_equals((obs, np.zeros(B), np.zeros(B, bool), np.zeros(B, bool), info), i, (s_obs, 0.0, False, False, s_info))
        bad = np.zeros((B, 7))
        bad[2, 4] = np.inf
        with self.assertRaisesRegex(ValueError, r"arm 2: action entry 4 \(ry\) = inf is not finite"):
            vec.step(bad)
        rng = np.random.default_rng(3)
        commands = set()
        for k in range(25):
            a = np.zeros((B, 7))
            a[:, :3] = home + rng.normal(scale=0.05, size=(B, 3)) - [0, 0, 0.004 * k]
            a[:, 3:6] = rng.normal(scale=0.1, size=(B, 3))
            a[:, 6] = k >= 10
            result = vec.step(a)
            for i, env in enumerate(singles):
                single = env.step(a[i])
                self.assert_arm_equals(result, i, single)
                self.assertEqual((result[4]["ee_command"][i], result[4]["control_steps"][i]),
                                 (single[4]["ee_command"], single[4]["control_steps"]))
                commands.add(single[4]["ee_command"])
        self.assertIn("line", commands)
        np.testing.assert_array_equal(result[0]["gripper_state"], 1)
        with self.assertRaisesRegex(ValueError, "action_mode = 'joint' must be 'torque' or 'ee_pose'"):
            manisoft.make_vec_env("COLL", 1, action_mode="joint")
        vec.close()

    def test_images_against_singles(self):
        """render=True: each arm's camera image equals make_env(task, render=True) in the same state,
        pixel for pixel, after the reset, after end-effector commands and after one arm is reset to
        another scene; two threads with three arms, so one worker draws one arm and the other draws
        two, each with its own renderer (incremental frames)."""
        camera = {"width": 64, "height": 48}
        vec = manisoft.make_vec_env("ALN", B, num_threads=2, seed=0, action_mode="ee_pose", action_repeat=12, render=True, camera=camera)
        self.assertEqual(vec.single_observation_space["image"].shape, (48, 64, 3))
        singles = [manisoft.make_env("ALN", "clean", seed=0, camera=camera, action_mode="ee_pose", action_repeat=12) for _ in range(B)]
        obs, _ = vec.reset(seed=2)
        s_obs = [env.reset(options={"index": 2 + i})[0] for i, env in enumerate(singles)]

        def assert_images(obs, s_obs):
            self.assertEqual((obs["image"].shape, obs["image"].dtype, obs["image"].flags.writeable), ((B, 48, 64, 3), np.uint8, False))
            for i in range(B):
                self.assertTrue(np.array_equal(obs["image"][i], s_obs[i]["image"]), f"arm {i}")
                self.assertTrue(vec.single_observation_space["image"].contains(obs["image"][i]))

        assert_images(obs, s_obs)
        first = np.array(obs["image"])
        home = np.array(obs["end_effector"][:, :3, 3])
        rng = np.random.default_rng(5)
        for k in range(4):
            a = np.zeros((B, 7))
            a[:, :3] = home + rng.normal(scale=0.08, size=(B, 3))
            obs = vec.step(a)[0]
            s_obs = [env.step(a[i])[0] for i, env in enumerate(singles)]
            assert_images(obs, s_obs)
        self.assertFalse(np.array_equal(first, obs["image"]))  # the arms moved
        obs, _ = vec.reset(seed=[0, 9, 0], options={"reset_mask": np.array([False, True, False])})
        s_obs[1] = singles[1].reset(options={"index": 9})[0]
        assert_images(obs, s_obs)
        vec.close()
        with self.assertRaisesRegex(ValueError, "camera is given but render=False"):
            manisoft.make_vec_env("ALN", 1, camera=camera)


if __name__ == "__main__":
    unittest.main()
