"""Bad inputs to the Python module and to evaluate.py, as docs/bad-inputs.md lists them: each call
raises the exception the row names (or the program exits 2) with a message naming the argument,
the option or the entry. What each refusal leaves unchanged is tested beside the environment's other
behaviour (test_task_env, test_reach_env, test_vec_env); this test keeps the table true."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import manisoft

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from bad_input_table import Section, cell  # noqa: E402

TABLE = Section("The Python module and evaluate.py", """
A bad argument to the `manisoft` module raises `ValueError` (a bad value: the argument, option or
entry is named) or `RuntimeError` (a call out of order) and changes nothing: the environment steps
on as if the call had not been made. `evaluate.py` exits 2 with one line naming the flag. `env` is
`manisoft.make_env("COLL", "clean", seed=0, render=False, privileged=True)` after `env.reset(options={"index": 0})`,
`zero` its zero action, `ee` the same with `action_mode="ee_pose"`, `vec` is `manisoft.make_vec_env("reach", 2)` after `vec.reset(seed=0)`.
Test `python_bad_inputs` (`tests/python/test_bad_inputs.py`).
""", ["call", "raises", "message"])


def coll_scene(env, edit):
    scene = json.loads(env.scene_json())
    edit(scene)
    return json.dumps(scene)


def in_the_basket(scene):
    basket = scene["objects"][0]["pose"]["position"]
    scene["objects"][1]["pose"]["position"] = [basket[0], basket[1], basket[2] + 0.005]


class BadInputs(unittest.TestCase):
    def refused(self, shown, call, exception, words):
        with self.assertRaises(exception) as caught:
            call()
        message = str(caught.exception).splitlines()[0]
        TABLE.add(f"`{cell(shown)}`", exception.__name__, cell(message))
        self.assertIn(words, str(caught.exception), shown)

    def test_bad_calls_are_refused_as_the_table_says(self):
        self.refused('make_env("PICK")', lambda: manisoft.make_env("PICK"), ValueError, "unknown environment 'PICK'")
        self.refused('make_env("COLL", "foggy")', lambda: manisoft.make_env("COLL", "foggy"), ValueError, "foggy")
        self.refused('make_env("COLL", camera={"zoom": 2})', lambda: manisoft.make_env("COLL", camera={"zoom": 2}), ValueError,
                     "camera: unknown key 'zoom'")
        env = manisoft.make_env("COLL", "clean", seed=0, render=False, privileged=True)
        zero = np.zeros(env.action_space.shape)
        self.refused("env.step(zero) before reset", lambda: env.step(zero), RuntimeError, "reset")
        env.reset(options={"index": 0})
        nan = zero.copy()
        nan[7] = np.nan
        s_inf = zero.copy()
        s_inf[-1] = np.inf
        for shown, action, words in [("env.step(np.zeros(60))", np.zeros(60), "shape (61,)"),
                                     ("env.step(np.zeros((20, 3)))", np.zeros((20, 3)), "shape (61,)"),
                                     ('env.step(np.array(["a"] * 61))', np.array(["a"] * 61), "dtype must be real"),
                                     ("env.step(zero with [7] = nan)", nan, "entry 7 (element 2, component d2) is not finite"),
                                     ("env.step(zero with [60] = inf)", s_inf, "(S) is not finite"),
                                     ("env.step([0.0, [1.0, 2.0]])", [0.0, [1.0, 2.0]], "step: action must be an array of numbers")]:
            self.refused(shown, lambda: env.step(action), ValueError, words)
        for shown, options, words in [('{"index": -1}', {"index": -1}, "options['index'] must be an integer in [0, 2^64), got -1"),
                                      ('{"index": "3"}', {"index": "3"}, "got '3' (str)"),
                                      ('{"index": 2.7}', {"index": 2.7}, "got 2.7"),
                                      ('{"index": 2 ** 70}', {"index": 2 ** 70}, "got 1180591620717411303424"),
                                      ('{"level": 2}', {"level": 2}, "unknown option 'level'"),
                                      ('{"instruction": "paraphrased"}', {"instruction": "paraphrased"}, "'paraphrased'"),
                                      ('{"scene": "{"}', {"scene": "{"}, "not valid JSON"),
                                      ('{"scene": (objects[1] listed twice)}',
                                       {"scene": coll_scene(env, lambda s: s["objects"].append(dict(s["objects"][1])))}, "interpenetration"),
                                      ('{"scene": (objects[1] at z 1e308)}',
                                       {"scene": coll_scene(env, lambda s: s["objects"][1]["pose"]["position"].__setitem__(2, 1e308))},
                                       "objects[1].pose position z = 1e+308 is not on the table"),
                                      ('{"scene": (the object already in the basket)}', {"scene": coll_scene(env, in_the_basket)},
                                       "the goal already holds before any step (inside")]:
            self.refused(f"env.reset(options={shown})", lambda: env.reset(options=options), ValueError, words)
        self.refused("env.reset(seed=-1)", lambda: env.reset(seed=-1), ValueError, "seed must be an integer in [0, 2^64), got -1")
        self.refused("env.render() without render=True", env.render, RuntimeError, "render=True")
        self.assertEqual(env.step(zero)[4]["steps"], 1)  # every refused call above changed nothing
        env.close()
        self.refused("env.step(zero) after env.close()", lambda: env.step(zero), RuntimeError, "closed")
        self.refused('make_env("COLL", action_mode="joint")', lambda: manisoft.make_env("COLL", action_mode="joint"), ValueError,
                     "action_mode = 'joint'")
        ee = manisoft.make_env("COLL", "clean", seed=0, render=False, action_mode="ee_pose")
        ee.reset(options={"index": 0})
        self.refused("ee.step(ee pose with rz = nan)", lambda: ee.step([0.5, 0, 0.9, 0, 0, np.nan, 0]), ValueError,
                     "entry 5 (rz) is not finite")
        self.refused("ee.step(zero)", lambda: ee.step(zero), ValueError, "must have shape (7,)")
        self.refused("ee.expert_action()", ee.expert_action, RuntimeError, "torques")
        ee.close()
        vec = manisoft.make_vec_env("reach", 2)
        vec.reset(seed=0)
        bad = np.zeros(vec.action_space.shape)
        bad[1, 4] = np.nan
        self.refused("vec.step(zeros with [1, 4] = nan)", lambda: vec.step(bad), ValueError, "arm 1")
        self.refused("vec.step(np.zeros(3))", lambda: vec.step(np.zeros(3)), ValueError, "shape")
        self.refused('make_vec_env("reach", 0)', lambda: manisoft.make_vec_env("reach", 0), ValueError, "num_envs")
        self.refused('make_vec_env("reach", 2, stability_beta=-1)', lambda: manisoft.make_vec_env("reach", 2, stability_beta=-1), ValueError,
                     "beta = -1")
        vec.close()
        vec_ee = manisoft.make_vec_env("COLL", 2, num_threads=1, action_mode="ee_pose")
        vec_ee.reset(seed=0)
        bad = np.zeros((2, 7))
        bad[1, 5] = np.nan
        self.refused('make_vec_env("COLL", 2, action_mode="ee_pose").step(zeros with [1, 5] = nan)', lambda: vec_ee.step(bad), ValueError,
                     "arm 1: action entry 5 (rz) = nan")
        vec_ee.close()
        self.refused('make_vec_env("COLL", 2, action_mode="ee_pose", action_repeat=0)',
                     lambda: manisoft.make_vec_env("COLL", 2, action_mode="ee_pose", action_repeat=0), ValueError, "action_repeat = 0")
        self.refused('make_vec_env("COLL", 2, camera={"width": 64})', lambda: manisoft.make_vec_env("COLL", 2, camera={"width": 64}),
                     ValueError, "render=False")
        self.refused('make_vec_env("COLL", 2, render=True, camera={"width": 0})',
                     lambda: manisoft.make_vec_env("COLL", 2, render=True, camera={"width": 0}), ValueError, "width")
        self.evaluate_flags()
        failures = []
        TABLE.finish(failures)
        self.assertEqual(failures, [])

    def evaluate_flags(self):
        with tempfile.TemporaryDirectory() as scratch:
            a_file = os.path.join(scratch, "a_file")
            open(a_file, "w").close()
            for argv, words in [(["--policy", "python:no_such_module:act"], "no_such_module"), (["--jobs", "0"], "--jobs"),
                                (["--indices", "3", "-1"], "--indices"), (["--chunk-steps", "0"], "--chunk-steps"),
                                (["--action-mode", "joint"], "--action-mode"), (["--action-repeat", "0"], "--action-repeat"),
                                (["--observation", "privileged"], "--observation privileged"),
                                (["--out", os.path.join(a_file, "out")], "--out")]:
                args = argv + ([] if "--out" in argv else ["--out", os.path.join(scratch, "out")])
                done = subprocess.run([sys.executable, "-m", "evaluate", "--task", "COLL"] + args, capture_output=True, text=True, timeout=120)
                last = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else ""
                TABLE.add(f"`evaluate.py {cell(' '.join(argv), scratch)}`", f"exit {done.returncode}", cell(last, scratch))
                self.assertEqual(done.returncode, 2, done.stderr)
                self.assertIn(words, done.stderr)


if __name__ == "__main__":
    unittest.main()
