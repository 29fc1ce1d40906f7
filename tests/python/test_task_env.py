"""The `manisoft` module's task environments used as a Gymnasium user would: the spaces, the
observation (image and instruction, privileged state on request), the expert finishing a fixed
scene, bit-identical replays, a rendered state matching the environment's own image, and bad input
refused with a clear exception that changes nothing. Run: PYTHONPATH=<build>/python python3 -m unittest."""
import gc
import json
import threading
import unittest

import numpy as np

import manisoft

SMALL = {"width": 96, "height": 80}


def run(env, actions):
    for a in actions:
        obs, *_ = env.step(a)
    return obs


class TaskEnvTest(unittest.TestCase):
    def test_spaces_and_observation(self):
        env = manisoft.make_env("COLL", "clean", seed=0, render=True, camera=SMALL, privileged=True)
        space = env.action_space
        n = env.n_elements
        self.assertEqual(n, 20)
        self.assertIsInstance(space, manisoft.Box)
        self.assertEqual((space.shape, space.dtype), ((3 * n + 1,), np.float64))
        high = space.high
        # Element 0 is the clamped base (no torque); bend limits 150 N m, twist 75 N m; S in [0, 1].
        np.testing.assert_array_equal(high[:3], [0, 0, 0])
        np.testing.assert_array_equal(high[3:-1], np.tile([150.0, 150.0, 75.0], n - 1))
        np.testing.assert_array_equal(space.low[:-1], -high[:-1])
        self.assertEqual((space.low[-1], high[-1]), (0.0, 1.0))
        obs, info = env.reset(options={"index": 3})
        scene = json.loads(env.scene_json())
        self.assertEqual(obs["instruction"], scene["instruction"])
        self.assertEqual((info["task"], info["setting"], info["index"], info["steps"]), ("COLL", "clean", 3, 0))
        spaces = env.observation_space
        self.assertIsInstance(spaces["instruction"], manisoft.Text)
        self.assertIsInstance(obs["instruction"], str)
        image = spaces["image"]
        self.assertEqual((image.shape, image.dtype, image.low.min(), image.high.max()), ((80, 96, 3), np.uint8, 0, 255))
        poses = spaces["object_poses"]  # as many 4 x 4 poses as the scene has objects
        self.assertIsInstance(poses, manisoft.Sequence)
        self.assertEqual(poses.feature_space.shape, (4, 4))
        self.assertEqual(np.asarray(obs["object_poses"]).shape, (len(scene["objects"]), 4, 4))
        for key in ("end_effector", "gripper_pose", "rod_nodes"):
            self.assertEqual((obs[key].shape, obs[key].dtype), (spaces[key].shape, spaces[key].dtype), key)
        # every entry, scalars included, lies in its space
        for key, space in spaces.items():
            self.assertTrue(space.contains(obs[key]), key)
        self.assertTrue(spaces.contains(obs))
        self.assertEqual(obs["image"].shape, (80, 96, 3))
        # The arm is clamped at its mount: node 0 at the scene's base position.
        np.testing.assert_allclose(obs["rod_nodes"][0], scene["arm_mount"]["base_position"], atol=1e-9)
        # Objects start where the scene puts them (asset frame -> world).
        for i, o in enumerate(scene["objects"]):
            np.testing.assert_allclose(obs["object_poses"][i][:3, 3], o["pose"]["position"], atol=2e-3)
        # Not a blank frame: the table, arm and objects give many distinct colours.
        self.assertGreater(len(np.unique(obs["image"].reshape(-1, 3), axis=0)), 50)

    def test_the_default_observation_is_the_papers_image_and_instruction(self):
        env = manisoft.make_env("ALN")  # clean, seed 0, the scene's camera: 514 x 514
        obs, _ = env.reset(options={"index": 1})
        self.assertEqual((obs["image"].shape, obs["image"].dtype), ((514, 514, 3), np.uint8))
        self.assertEqual(obs["instruction"], "Place the shoe at the marker.")
        self.assertNotIn("object_poses", obs)  # privileged state only on request
        state = manisoft.make_env("ALN", render=False)
        state_obs, _ = state.reset(options={"index": 1})
        self.assertNotIn("image", state_obs)
        self.assertEqual(state_obs["instruction"], obs["instruction"])
        env.close()

    def test_expert_finishes_a_fixed_scene(self):
        env = manisoft.make_env("ALN", "clean", seed=0, render=False)
        obs, info = env.reset(options={"index": 1})
        rewards = []
        for _ in range(env.horizon):
            obs, reward, terminated, truncated, info = env.step(env.expert_action())
            rewards.append(reward)
            if terminated or truncated:
                break
        self.assertTrue(info["success"], info)
        self.assertTrue(terminated)
        self.assertFalse(truncated)
        self.assertIsNone(info["failure"])
        self.assertLessEqual(info["steps"], 1500)
        # Success is every named condition of ALN's predicate holding.
        self.assertEqual(info["conditions"], {"position": True, "orientation": True, "released": True, "at_rest": True})
        self.assertEqual(sum(rewards), 1.0)
        self.assertEqual(rewards[-1], 1.0)
        with self.assertRaisesRegex(RuntimeError, "episode is over"):
            env.step(np.zeros(61))

    def test_the_end_effector_track_replays_the_experts_targets(self):
        # the expert's targets recorded on the torque track, sampled at 20 Hz, drive the ee_pose track
        torque = manisoft.make_env("ALN", "clean", seed=0, render=False)
        torque.reset(options={"index": 1, "split": "eval"})
        targets = []
        while True:
            action = torque.expert_action()
            targets.append(torque.expert_target())
            *_, terminated, truncated, info = torque.step(action)
            if terminated or truncated:
                break
        self.assertTrue(info["success"], info)
        env = manisoft.make_env("ALN", "clean", seed=0, render=False, action_mode="ee_pose")
        self.assertEqual((env.action_mode, env.action_repeat), ("ee_pose", 36))
        self.assertEqual(env.action_space.shape, (7,))
        obs, info = env.reset(options={"index": 1, "split": "eval"})
        # every target within the space; the first (the approach: tool down, yawed about the
        # vertical) has the rotation vector (0, 0, yaw) from the home orientation, S open
        self.assertTrue(all(env.action_space.contains(t) for t in targets))
        self.assertLess(abs(targets[0][3]) + abs(targets[0][4]), 1e-9)
        self.assertEqual(targets[0][6], 0.0)
        commands, k = [], 0
        while True:
            obs, reward, terminated, truncated, info = env.step(targets[min(k, len(targets) - 1)])
            commands.append(info["ee_command"])
            k += info["control_steps"]
            if terminated or truncated:
                break
            self.assertEqual(info["control_steps"], 36)
        self.assertTrue(info["success"], info)
        self.assertEqual(k, info["steps"])
        self.assertNotIn("refused", commands)
        self.assertGreaterEqual(commands.count("line"), 4)
        with self.assertRaisesRegex(ValueError, "entry 3 \\(rx\\) is not finite"):
            env.reset(options={"index": 1, "split": "eval"})
            env.step([0.5, 0, 0.9, float("nan"), 0, 0, 0])
        with self.assertRaisesRegex(ValueError, "shape \\(7,\\)"):
            env.step(np.zeros(61))
        self.assertEqual(env.step(targets[0])[4]["steps"], 36)  # nothing changed by the refused ones
        with self.assertRaisesRegex(RuntimeError, "record its targets there"):
            env.expert_target()
        with self.assertRaisesRegex(RuntimeError, "actions are torques"):
            env.expert_action()
        with self.assertRaisesRegex(ValueError, "action_mode = 'joint'"):
            manisoft.make_env("ALN", action_mode="joint")
        with self.assertRaisesRegex(ValueError, "action_repeat = 0"):
            manisoft.make_env("ALN", action_mode="ee_pose", action_repeat=0)

    def test_zero_torques_time_out_at_the_horizon(self):
        env = manisoft.make_env("ALN", "clean", seed=0, render=False)
        env.reset(options={"index": 0})
        action = np.zeros(61)
        for step in range(1, 1501):
            _, reward, terminated, truncated, info = env.step(action)
            if terminated or truncated:
                break
        self.assertEqual(step, 1500)
        self.assertTrue(truncated)
        self.assertFalse(terminated)
        self.assertEqual(info["failure"], "timeout")
        # The arm never moved the object: it is far from its goal pose, released and at rest.
        self.assertFalse(info["conditions"]["position"])
        self.assertTrue(info["conditions"]["released"])

    def test_the_registry_defines_tasks_horizon_and_control_step(self):
        tasks = manisoft.tasks()
        self.assertEqual([t["name"] for t in tasks], ["COLL", "ALN", "STK", "ARR", "OVR"])
        coll = tasks[0]
        self.assertEqual(coll["conditions"], ["inside", "touching_container", "off_table", "released", "at_rest"])
        self.assertEqual([t["by_category"] for t in tasks], [True, True, False, True, True])
        self.assertEqual(manisoft.HORIZON, 1500)
        self.assertEqual(manisoft.CONTROL_DT, 7 * 2e-4)  # 7 substeps of 0.2 ms
        for t in tasks:
            env = manisoft.make_env(t["name"], "clean", seed=0, render=False)
            _, info = env.reset(options={"index": 0})
            self.assertEqual(list(info["conditions"]), t["conditions"])
            self.assertEqual(env.horizon, manisoft.HORIZON)
        # The target object: COLL / ALN / OVR the goal's object, STK the top item, ARR the first placed object.
        sampler = manisoft.SceneSampler()
        for name, pick in (("COLL", lambda g: g["object"]), ("STK", lambda g: g["items"][-1]),
                           ("ARR", lambda g: g["relations"][0]["objects"][0]), ("OVR", lambda g: g["object"])):
            text = sampler.sample(name, "clean", 2, 0)
            self.assertEqual(manisoft.target_object(text), pick(json.loads(text)["goal"]), name)
        with self.assertRaisesRegex(ValueError, "unknown environment 'PUSH' \\(available: COLL, ALN, STK, ARR, OVR, reach\\)"):
            manisoft.make_env("PUSH")

    def test_same_seed_same_episode_and_actions_replay_bit_for_bit(self):
        env = manisoft.make_env("ARR", "randomized", seed=4, render=False, privileged=True)
        env.reset(options={"index": 1})
        actions, states = [], []
        for _ in range(80):
            a = env.expert_action()
            actions.append(a)
            obs, *_ = env.step(a)
            states.append(obs["rod_nodes"].copy())
        other = manisoft.make_env("ARR", "randomized", seed=4, render=False, privileged=True)
        other.reset(options={"index": 1})
        for a, x in zip(actions, states):
            obs, *_ = other.step(a)
            self.assertTrue(np.array_equal(obs["rod_nodes"], x))
        # the same scene through its JSON text
        third = manisoft.make_env("ARR", "randomized", seed=99, render=False, privileged=True)
        third.reset(options={"scene": env.scene_json()})
        self.assertTrue(np.array_equal(run(third, actions)["rod_nodes"], states[-1]))

    def test_renderer_draws_a_given_state_as_the_environment_does(self):
        env = manisoft.make_env("STK", "randomized", seed=0, render=True, camera=SMALL, privileged=True)
        env.reset(options={"index": 2})
        obs = run(env, [env.expert_action() for _ in range(30)])
        image = manisoft.Renderer().render(env.scene_json(), obs["rod_nodes"], obs["gripper_pose"], obs["gripper_width"],
                                           obs["object_poses"], camera=SMALL)
        self.assertTrue(np.array_equal(image, obs["image"]))
        self.assertTrue(np.array_equal(env.render(), obs["image"]))

    def test_instructions_seen_and_unseen(self):
        env = manisoft.make_env("COLL", "randomized", seed=0, render=False)
        scene = json.loads(manisoft.SceneSampler().sample("COLL", "randomized", 5, 0, "eval"))
        for kind in ("seen", "unseen"):
            self.assertTrue(scene["instructions_" + kind])  # randomized scenes have both kinds
            obs, info = env.reset(options={"index": 5, "split": "eval", "instruction": kind, "instruction_index": 1})
            self.assertEqual(info["instruction_kind"], kind)
            lst = scene["instructions_" + kind]
            self.assertEqual(obs["instruction"], lst[1 % len(lst)])
        self.assertEqual(json.loads(env.scene_json())["split"], "eval")

    def test_bad_input_is_refused_and_changes_nothing(self):
        env = manisoft.make_env("COLL", "clean", seed=0, render=False, privileged=True)
        with self.assertRaisesRegex(RuntimeError, "reset"):
            env.step(np.zeros(61))
        env.reset(options={"index": 0})
        good = np.zeros(61)
        good[3:-1] = 5.0
        for bad, pattern in [(np.zeros(60), r"shape \(61,\)"), (np.zeros((20, 3)), r"shape \(61,\)"),
                             (np.array(["a"] * 61), "dtype must be real"), (np.zeros(61, dtype=complex), "dtype must be real")]:
            with self.assertRaisesRegex(ValueError, pattern):
                env.step(bad)
        nan = good.copy()
        nan[7] = np.nan
        with self.assertRaisesRegex(ValueError, r"entry 7 \(element 2, component d2\) is not finite"):
            env.step(nan)
        nan_s = good.copy()
        nan_s[-1] = np.inf
        with self.assertRaisesRegex(ValueError, r"\(S\) is not finite"):
            env.step(nan_s)
        obs, *_ = env.step(good)
        fresh = manisoft.make_env("COLL", "clean", seed=0, render=False, privileged=True)
        fresh.reset(options={"index": 0})
        expected, *_ = fresh.step(good)
        self.assertTrue(np.array_equal(obs["rod_nodes"], expected["rod_nodes"]))
        with self.assertRaisesRegex(ValueError, "unknown option 'level'"):
            env.reset(options={"level": 2})
        with self.assertRaisesRegex(ValueError, "instruction"):
            env.reset(options={"instruction": "paraphrased"})
        with self.assertRaisesRegex(ValueError, "not valid JSON"):
            env.reset(options={"scene": "{"})
        scene = json.loads(env.scene_json())
        scene["objects"].append(dict(scene["objects"][0]))  # a second object where the first stands
        with self.assertRaisesRegex(ValueError, r"reset\(options\['scene'\]\): not a valid scene: interpenetration"):
            env.reset(options={"scene": json.dumps(scene)})
        scene["objects"].pop()
        scene["objects"][0]["pose"]["position"][2] = 1e308
        with self.assertRaisesRegex(ValueError, r"objects\[0\]\.pose position z = 1e\+308 is not on the table"):
            env.reset(options={"scene": json.dumps(scene)})
        self.assertEqual(env.step(good)[4]["steps"], 2)  # the refused resets changed nothing
        with self.assertRaisesRegex(RuntimeError, "render=True"):
            env.render()
        with self.assertRaisesRegex(ValueError, "unknown environment 'PICK'"):
            manisoft.make_env("PICK")
        with self.assertRaisesRegex(ValueError, "setting"):
            manisoft.make_env("COLL", "foggy")
        with self.assertRaisesRegex(ValueError, "camera: unknown key 'zoom'"):
            manisoft.make_env("COLL", camera={"zoom": 2})
        env.close()
        with self.assertRaisesRegex(RuntimeError, "closed"):
            env.step(good)

    def test_bad_options_name_the_option_and_lists_are_actions(self):
        env = manisoft.make_env("ALN", "clean", seed=0, render=False, privileged=True)
        for options, pattern in [({"index": -1}, r"options\['index'\] must be an integer in \[0, 2\^64\), got -1$"),
                                 ({"index": "3"}, r"options\['index'\] .* got '3' \(str\)"),
                                 ({"index": 2.7}, r"options\['index'\] .* got 2.7$"),
                                 ({"index": 2 ** 70}, r"options\['index'\] .* got 1180591620717411303424"),
                                 ({"index": True}, r"options\['index'\] .* got True \(bool\)"),
                                 ({"instruction_index": -2}, r"options\['instruction_index'\]"),
                                 ({"split": 1}, r"options\['split'\] must be a string, got 1"),
                                 ({"scene": None}, r"options\['scene'\] must be a string, got None \(NoneType\)")]:
            with self.assertRaisesRegex(ValueError, pattern):
                env.reset(options=options)
        with self.assertRaisesRegex(ValueError, r"reset: seed must be an integer in \[0, 2\^64\), got -1"):
            env.reset(seed=-1)
        obs, _ = env.reset(options={"index": 1})  # the refused calls changed nothing: index 1 of seed 0
        reference = manisoft.make_env("ALN", "clean", seed=0, render=False, privileged=True)
        expected, _ = reference.reset(options={"index": 1})
        self.assertEqual(obs["instruction"], expected["instruction"])
        action = [0.0] * 61
        obs, *_ = env.step(action)  # a list, as from json or a plain Python policy
        expected, *_ = reference.step(np.zeros(61))
        self.assertTrue(np.array_equal(obs["rod_nodes"], expected["rod_nodes"]))
        with self.assertRaisesRegex(ValueError, r"step: action must be an array of numbers"):
            env.step([0.0, [1.0, 2.0]])
        with self.assertRaisesRegex(ValueError, r"shape \(61,\)"):
            env.step((0.0,) * 60)

    def test_a_rendering_environment_belongs_to_the_thread_that_reset_it(self):
        made = {}

        def worker():
            env = manisoft.make_env("COLL", "clean", seed=0, render=True, camera=SMALL, privileged=True)
            env.reset(options={"index": 0})
            env.step(np.zeros(61))
            made["env"] = env
        t = threading.Thread(target=worker)
        t.start()
        t.join()
        env = made.pop("env")
        steps = env.step  # bound method: the call below comes from this (another) thread
        with self.assertRaisesRegex(RuntimeError, "EGL context bound to the thread that first reset it"):
            steps(np.zeros(61))
        with self.assertRaisesRegex(RuntimeError, "bound to the thread"):
            env.reset(options={"index": 1})
        del env, steps  # deleted on this thread without close(): no abort (EGL_BAD_ACCESS before)
        gc.collect()
        # a non-rendering environment may move between threads
        plain = manisoft.make_env("COLL", "clean", seed=0, render=False, privileged=True)
        plain.reset(options={"index": 0})
        t = threading.Thread(target=lambda: plain.step(np.zeros(61)))
        t.start()
        t.join()
        self.assertEqual(plain.step(np.zeros(61))[4]["steps"], 2)


if __name__ == "__main__":
    unittest.main()
