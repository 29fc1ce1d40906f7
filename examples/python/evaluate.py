#!/usr/bin/env python3
"""Evaluates a policy on ManiSoft's held-out scenes and writes the paper's tables.

    PYTHONPATH=build/<config>/python /usr/bin/python3 examples/python/evaluate.py \\
        --task all --setting clean --policy expert --episodes-per-category 20 --seed 0 --out eval/expert

Policies (--policy):
  expert                 the rule-based expert (privileged: it reads the simulator's state)
  random                 uniform torques within the actuation limits, S uniform in {0, 1}
  replay:DIR             the actions saved by an earlier run with --save-actions (DIR/actions/*.npy)
  python:MODULE:FUNC     FUNC(obs) -> one action (3n+1,) or a chunk (H, 3n+1); obs: {"image": uint8
                         H x W x 3, "instruction": str}; MODULE is imported (the working directory
                         and --python-path are searched)
  ws://HOST:PORT         a policy server speaking openpi's websocket protocol: it sends its metadata on
                         connect, then answers each msgpack request {"observation/image": H x W x 3
                         uint8, "prompt": str} with {"actions": H x (3n+1)} (numpy arrays in openpi's
                         msgpack encoding)
A chunk's first --chunk-steps actions are executed before the policy is asked again.
--action-mode ee_pose evaluates on the end-effector track instead of the paper's torque track: an
action is 7 floats (target position, rotation vector, S; manisoft.make_env(..., action_mode=
"ee_pose")) tracked by the model executor for --action-repeat control steps (default 36: 20 Hz);
the expert then sends the targets it tracked at each control step of its own episode on the torque
track (run first), every --action-repeat steps.
--observation privileged hands a python: policy the environment's privileged state instead of the
image (make_env(..., render=False, privileged=True)) and, as obs["scene"], the episode's scene JSON
(its objects, assets and goal): the bound a perfect perception gives. A python: module's reset(),
if it has one, is called before each episode.

Scenes: the evaluation split (never drawn by dataset generation), eval indices 0, 1, 2, ... of each
task and setting, the first K of each target-object category (STK: K in all); horizon T = manisoft.HORIZON (1500).
Episodes alternate seen and unseen instructions where the scene has them (randomized scenes).
A policy that raises (SystemExit included) or returns a malformed action fails the episode with
that reason; the evaluation goes on. A python: policy is called in a helper thread so that
--policy-timeout holds while it runs: one that has not answered by then fails its episode
(policy_timeout) and, as its call is still running, stops the evaluation (exit 1; --resume goes
on with a fresh process). A ws:// server that does not answer in time fails the episode and is
reconnected.

Output in --out: episodes.jsonl (each episode appended as it finishes, with run.json, the
arguments of the run), then episodes.csv (one row an episode), results.csv and results.md (ACC %
with its 95% Wilson interval and #Steps, the mean length of successes, per task, category and
setting; seen vs unseen instructions; failure reasons) and summary.json once every episode has
run. An interrupted run (Ctrl-C: exit 130) keeps its finished episodes; --resume with the same
arguments runs the others. Exit 0 when every episode ran (whatever its outcome), 1 on an error,
2 on bad flags.
"""
import argparse
import asyncio
import atexit
import csv
import importlib
import importlib.util
import json
import math
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections import Counter, defaultdict

import numpy as np

import manisoft

TASKS = tuple(t["name"] for t in manisoft.tasks())
BY_CATEGORY = {t["name"]: t["by_category"] for t in manisoft.tasks()}
SETTINGS = ("clean", "randomized")
HORIZON = manisoft.HORIZON


# ---- statistics

def wilson_interval(successes, n, z=1.959963984540054):
    """95% Wilson score interval of a binomial proportion (in [0, 1])."""
    if n == 0:
        return (0.0, 1.0)
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return (max(0.0, centre - half), min(1.0, centre + half))


# ---- scenes

def target_category(scene_text):
    """The category of a scene's target object ("bottle" of "bottle/05", manisoft.target_object);
    "all" for a task whose episodes are not grouped by category (manisoft.tasks()'s by_category)."""
    scene = json.loads(scene_text)
    if not BY_CATEGORY[scene["task"]]:
        return "all"
    return scene["objects"][manisoft.target_object(scene_text)]["asset_id"].split("/")[0]


def plan_episodes(task, setting, per_category, seed, max_scan, sampler):
    """(task, setting, index, category) of one task and setting: eval indices in order, the first
    per_category of each target category (STK: per_category in all). Scanning stops when every
    category met has its episodes and the last max(30, 4 per_category) indices brought no new one."""
    counts, plan, last_new = Counter(), [], 0
    for index in range(max_scan):
        category = target_category(sampler.sample(task, setting, index, seed, "eval"))
        if category not in counts:
            last_new = index
        if counts[category] < per_category:
            counts[category] += 1
            plan.append((task, setting, index, category))
        if all(c >= per_category for c in counts.values()) and index - last_new >= max(30, 4 * per_category):
            break
    return plan


# ---- policies

class PolicyFailure(Exception):
    """The policy failed an episode: reason is the machine-readable failure; hung: its call is
    still running (the evaluation cannot go on with it)."""

    def __init__(self, reason, detail, hung=False):
        super().__init__(f"{reason}: {detail}")
        self.reason = reason
        self.detail = detail
        self.hung = hung


class TimedPolicy:
    """Calls a Python policy in a daemon thread and waits at most `timeout` seconds for it: a call
    still running then is abandoned (PolicyFailure "policy_timeout", hung). Whatever the policy
    raises, SystemExit and KeyboardInterrupt included, is raised in the caller."""

    def __init__(self, function, timeout, reset=None):
        self.function, self.timeout, self.reset = function, timeout, reset

    def start(self, task, setting, index):
        """The module's reset(), if it has one, at the start of every episode."""
        del task, setting, index
        if self.reset is not None:
            self.reset()

    def __call__(self, obs):
        box, done = {}, threading.Event()

        def call():
            try:
                box["answer"] = self.function(obs)
            except BaseException as e:  # handed to the caller, which fails the episode with it
                box["error"] = e
            done.set()
        threading.Thread(target=call, name="policy", daemon=True).start()
        if not done.wait(self.timeout):
            raise PolicyFailure("policy_timeout", f"the policy did not answer within {self.timeout} s", hung=True)
        if "error" in box:
            raise box["error"]
        return box["answer"]


def pack_openpi(obj):
    """openpi's msgpack encoding of numpy arrays and scalars."""
    if isinstance(obj, np.ndarray):
        return {b"__ndarray__": True, b"data": obj.tobytes(), b"dtype": obj.dtype.str, b"shape": obj.shape}
    if isinstance(obj, np.generic):
        return {b"__npgeneric__": True, b"data": obj.item(), b"dtype": obj.dtype.str}
    return obj


def unpack_openpi(obj):
    """Decodes openpi's encoding (and msgpack-numpy's, b"nd") back to numpy."""
    if b"__ndarray__" in obj:
        return np.ndarray(buffer=obj[b"data"], dtype=np.dtype(obj[b"dtype"]), shape=obj[b"shape"])
    if b"__npgeneric__" in obj:
        return np.dtype(obj[b"dtype"]).type(obj[b"data"])
    if b"nd" in obj and obj[b"nd"]:
        return np.frombuffer(obj[b"data"], dtype=np.dtype(obj[b"type"])).reshape(obj[b"shape"])
    return obj


class WebsocketPolicy:
    """A client of an openpi-style policy server (websockets' asyncio API, Debian's 10.x)."""

    def __init__(self, uri, timeout):
        import msgpack
        import websockets
        self._msgpack, self._websockets, self._uri, self._timeout = msgpack, websockets, uri, timeout
        self._loop = asyncio.new_event_loop()
        self._ws = None
        self.metadata = None

    def _run(self, coroutine):
        try:
            return self._loop.run_until_complete(asyncio.wait_for(coroutine, self._timeout))
        except asyncio.TimeoutError:
            self.close()
            raise PolicyFailure("policy_timeout", f"no answer from {self._uri} within {self._timeout} s") from None

    def _connect(self):
        async def connect():
            ws = await self._websockets.connect(self._uri, compression=None, max_size=None)
            metadata = self._msgpack.unpackb(await ws.recv(), object_hook=unpack_openpi)
            return ws, metadata
        try:
            self._ws, self.metadata = self._run(connect())
        except (OSError, self._websockets.exceptions.WebSocketException) as e:
            raise PolicyFailure("policy_error", f"cannot connect to {self._uri}: {e}") from None

    def __call__(self, obs):
        if self._ws is None:
            self._connect()
        request = {"observation/image": obs["image"], "prompt": obs["instruction"]}

        async def infer():
            await self._ws.send(self._msgpack.packb(request, default=pack_openpi))
            return await self._ws.recv()
        try:
            answer = self._run(infer())
        except self._websockets.exceptions.WebSocketException as e:
            self.close()
            raise PolicyFailure("policy_error", f"{self._uri}: {e}") from None
        if isinstance(answer, str):
            raise PolicyFailure("policy_error", f"the server reported an error: {answer[:500]}")
        reply = self._msgpack.unpackb(answer, object_hook=unpack_openpi)
        if not isinstance(reply, dict) or "actions" not in reply:
            raise PolicyFailure("bad_action", "the server's reply has no 'actions'")
        return reply["actions"]

    def close(self, final=False):
        """Closes the connection (the next call reconnects); final: also the event loop."""
        if self._ws is not None:
            try:
                self._loop.run_until_complete(asyncio.wait_for(self._ws.close(), 1.0))
            except (asyncio.TimeoutError, OSError, self._websockets.exceptions.WebSocketException):
                pass  # the server is gone or slow: nothing left to close cleanly
            self._ws = None
        if final:
            self._loop.close()


class RandomPolicy:
    """Uniform actions; each episode's stream is seeded by (seed, task, setting, index), so the
    result does not depend on which worker runs it."""

    def __init__(self, space, seed):
        self.low, self.high, self.seed = space.low, space.high, seed
        self.rng = None

    def start(self, task, setting, index):
        self.rng = np.random.default_rng([self.seed, TASKS.index(task), SETTINGS.index(setting), index])

    def __call__(self, obs):
        action = self.rng.uniform(self.low, self.high)
        action[-1] = float(self.rng.integers(0, 2))
        return action


class ReplayPolicy:
    """Plays back DIR/actions/<task>_<setting>_<index>.npy (T x (3n+1)), one action a step."""

    def __init__(self, directory):
        self.directory = directory
        self.actions, self.step = None, 0

    def start(self, task, setting, index):
        path = os.path.join(self.directory, "actions", f"{task}_{setting}_{index}.npy")
        if not os.path.exists(path):
            raise PolicyFailure("policy_error", f"no recorded actions: {path}")
        self.actions, self.step = np.load(path), 0

    def __call__(self, obs):
        if self.step >= len(self.actions):
            raise PolicyFailure("policy_error", f"the recording ends after {len(self.actions)} actions")
        self.step += 1
        return self.actions[self.step - 1]


class ExpertTargetsPolicy:
    """The expert on the end-effector track: its episode is first run on the torque track (where
    it acts at the control rate), its end-effector target and S recorded at every control step;
    the action at control step k is the target recorded there (every action_repeat steps)."""

    def __init__(self, args):
        self.args, self.envs, self.targets, self.step = args, {}, None, 0

    def start(self, task, setting, index):
        key = (task, setting)
        if key not in self.envs:
            self.envs[key] = manisoft.make_env(task, setting, seed=self.args.seed, split="eval", render=False)
        env = self.envs[key]
        env.reset(seed=self.args.seed, options={"index": index, "split": "eval"})
        self.targets, self.step = [], 0
        while True:
            action = env.expert_action()
            self.targets.append(env.expert_target())
            *_, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                break

    def __call__(self, obs):
        target = self.targets[min(self.step, len(self.targets) - 1)]
        self.step += self.args.action_repeat
        return target

    def close(self):
        for env in self.envs.values():
            env.close()


def load_python_policy(spec, extra_path):
    _, module_name, function_name = spec.split(":", 2)
    for p in [os.getcwd()] + list(extra_path):
        if p not in sys.path:
            sys.path.insert(0, p)
    module = importlib.import_module(module_name)
    function = getattr(module, function_name, None)
    if not callable(function):
        raise ValueError(f"--policy {spec}: {module_name} has no callable '{function_name}'")
    reset = getattr(module, "reset", None)
    return function, reset if callable(reset) else None


def check_spec(spec):
    if spec in ("expert", "random") or spec.startswith("ws://"):
        return
    if spec.startswith("replay:") and len(spec) > len("replay:"):
        return
    if spec.startswith("python:") and len(spec.split(":")) == 3 and all(spec.split(":")[1:]):
        return
    raise ValueError(f"--policy {spec!r}: expected expert, random, replay:DIR, python:MODULE:FUNCTION or ws://HOST:PORT")


# ---- episodes

def as_chunk(action, size):
    """The policy's answer as an (H, size) float64 chunk, or PolicyFailure("bad_action")."""
    try:
        a = np.asarray(action, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise PolicyFailure("bad_action", f"not a numeric array ({e})") from None
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != size or a.shape[0] < 1:
        raise PolicyFailure("bad_action", f"shape {np.shape(action)}, expected ({size},) or (H, {size})")
    if not np.all(np.isfinite(a)):
        raise PolicyFailure("bad_action", "not finite")
    return a


class Worker:
    """Runs episodes in one process: one environment per (task, setting), one policy."""

    def __init__(self, args):
        self.args = args
        self.envs = {}
        self.policy = None
        self.current = None

    def env(self, task, setting):
        key = (task, setting)
        if key not in self.envs:
            width, height = self.args.image_size
            privileged = self.args.observation == "privileged"
            needs_image = not (privileged or self.args.policy in ("expert", "random") or self.args.policy.startswith("replay:"))
            self.envs[key] = manisoft.make_env(task, setting, seed=self.args.seed, split="eval", render=needs_image, privileged=privileged,
                                               camera={"width": width, "height": height}, action_mode=self.args.action_mode,
                                               action_repeat=self.args.action_repeat)
        return self.envs[key]

    def make_policy(self, env):
        spec = self.args.policy
        if spec == "expert":
            if self.args.action_mode == "ee_pose":
                return ExpertTargetsPolicy(self.args)
            return lambda obs: self.current.expert_action()
        if spec == "random":
            return RandomPolicy(env.action_space, self.args.seed)
        if spec.startswith("replay:"):
            return ReplayPolicy(spec[len("replay:"):])
        if spec.startswith("python:"):
            function, reset = load_python_policy(spec, self.args.python_path)
            return TimedPolicy(function, self.args.policy_timeout, reset)
        return WebsocketPolicy(spec, self.args.policy_timeout)

    def run(self, episode):
        """One episode: its record (episodes.csv's fields and its plan number) and whether the
        policy hung (its call still running: the evaluation must stop)."""
        task, setting, index, category, number = episode
        env = self.current = self.env(task, setting)
        if self.policy is None:
            self.policy = self.make_policy(env)
        policy = self.policy
        instruction = "seen" if number % 2 == 0 else "unseen"
        t0 = time.perf_counter()
        obs, info = env.reset(seed=self.args.seed, options={"index": index, "split": "eval", "instruction": instruction,
                                                          "instruction_index": number // 2})
        size = env.action_space.shape[0]
        scene = env.scene_json() if self.args.observation == "privileged" else None
        if scene is not None:
            obs["scene"] = scene
        actions, failure, detail, hung = [], info["failure"], "", False
        chunk, used, started = None, 0, True
        try:
            if hasattr(policy, "start"):
                policy.start(task, setting, index)
        except PolicyFailure as e:  # replay: no recording of this episode
            failure, detail, started = e.reason, e.detail, False
        while started and not info["done"]:
            if chunk is None or used >= min(len(chunk), self.args.chunk_steps):
                try:
                    chunk, used = as_chunk(policy(obs), size), 0
                except PolicyFailure as e:
                    failure, detail, hung = e.reason, e.detail, e.hung
                    break
                except KeyboardInterrupt:
                    raise
                except BaseException as e:  # the policy's own error (SystemExit too): the episode fails, the evaluation goes on
                    failure, detail = "policy_error", f"{type(e).__name__}: {e}"
                    break
            action = chunk[used]
            used += 1
            actions.append(action)
            obs, _, terminated, truncated, info = env.step(action)
            if scene is not None:
                obs["scene"] = scene
            failure = info["failure"]
        if self.args.save_actions:
            path = os.path.join(self.args.out, "actions", f"{task}_{setting}_{index}.npy")
            tmp = path + ".tmp.npy"
            np.save(tmp, np.asarray(actions, dtype=np.float64).reshape(-1, size))
            os.replace(tmp, path)
        success = bool(info["success"]) and failure is None
        record = {"task": task, "setting": setting, "category": category, "index": index, "seed": self.args.seed,
                  "instruction_kind": info["instruction_kind"], "success": success, "success_at_end": bool(info["success_at_end"]),
                  "steps": int(info["steps"]), "failure": "" if success else (failure or "policy_error"), "detail": detail,
                  "wall_s": round(time.perf_counter() - t0, 3), "number": number}
        return record, hung

    def close(self):
        if isinstance(self.policy, WebsocketPolicy):
            self.policy.close(final=True)
        if isinstance(self.policy, ExpertTargetsPolicy):
            self.policy.close()
        for env in self.envs.values():
            env.close()


_worker = None


def _worker_init(args, in_pool=False):
    global _worker
    if in_pool:  # Ctrl-C is the parent's to handle: it terminates the pool
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    _worker = Worker(args)
    atexit.register(_worker.close)


def _worker_run(episode):
    return _worker.run(episode)


# ---- tables

def table_rows(episodes):
    """Per (task, setting, category) and per (task, setting) ("all"): n, successes, ACC, Wilson, #Steps."""
    groups = defaultdict(list)
    for e in episodes:
        groups[(e["task"], e["setting"], e["category"])].append(e)
        if e["category"] != "all":
            groups[(e["task"], e["setting"], "all")].append(e)
        groups[("all", e["setting"], "all")].append(e)
    rows = []
    order = {t: i for i, t in enumerate(TASKS + ("all",))}
    for (task, setting, category), eps in sorted(groups.items(), key=lambda kv: (kv[0][1], order[kv[0][0]], kv[0][2] != "all", kv[0][2])):
        ok = [e for e in eps if e["success"]]
        low, high = wilson_interval(len(ok), len(eps))
        rows.append({"task": task, "setting": setting, "category": category, "episodes": len(eps), "successes": len(ok),
                     "acc": 100.0 * len(ok) / len(eps), "acc_low": 100.0 * low, "acc_high": 100.0 * high,
                     "mean_steps": (sum(e["steps"] for e in ok) / len(ok)) if ok else float("nan")})
    return rows


def write_outputs(out, args, episodes, wall):
    fields = ["task", "setting", "category", "index", "seed", "instruction_kind", "success", "success_at_end", "steps", "failure",
              "detail", "wall_s"]
    write_csv(os.path.join(out, "episodes.csv"), fields, episodes)
    rows = table_rows(episodes)
    write_csv(os.path.join(out, "results.csv"), list(rows[0].keys()) if rows else [], rows)
    track = "torque" if args.action_mode == "torque" else f"ee_pose, {args.action_repeat} control steps an action"
    seen = "" if args.observation == "image" else ", privileged observation"
    lines = [f"# ManiSoft evaluation: policy `{args.policy}`, action mode {track}{seen}", "",
             f"Held-out (eval) scenes, seed {args.seed}, " + (f"eval indices {args.indices}" if args.indices else
             f"up to {args.episodes_per_category or '20 (clean) / 40 (randomized)'} episodes per target category") + ", "
             f"horizon {HORIZON}; {len(episodes)} episodes in {wall:.0f} s. ACC: success % with its 95% Wilson interval; "
             "#Steps: mean length of the successful episodes.", ""]
    for setting in args.settings:
        lines += [f"## {setting}", "", "| task | category | episodes | ACC % | 95% interval | #Steps |", "|---|---|---|---|---|---|"]
        for r in rows:
            if r["setting"] == setting:
                steps = "-" if math.isnan(r["mean_steps"]) else f"{r['mean_steps']:.0f}"
                name = f"**{r['category']}**" if r["category"] == "all" else r["category"]
                lines.append(f"| {r['task']} | {name} | {r['episodes']} | {r['acc']:.1f} | {r['acc_low']:.1f}-{r['acc_high']:.1f} | {steps} |")
        lines.append("")
    lines += ["## Instructions seen vs unseen in training", "", "| setting | instructions | episodes | ACC % |", "|---|---|---|---|"]
    kinds = defaultdict(list)
    for e in episodes:
        kinds[(e["setting"], e["instruction_kind"])].append(e["success"])
    for (setting, kind), s in sorted(kinds.items()):
        lines.append(f"| {setting} | {kind} | {len(s)} | {100.0 * sum(s) / len(s):.1f} |")
    lines += ["", "## Failure reasons", "", "| task | setting | reason | episodes |", "|---|---|---|---|"]
    for (task, setting, reason), n in sorted(Counter((e["task"], e["setting"], e["failure"]) for e in episodes if not e["success"]).items()):
        lines.append(f"| {task} | {setting} | {reason} | {n} |")
    write_text(os.path.join(out, "results.md"), "\n".join(lines) + "\n")
    summary = {"policy": args.policy, "observation": args.observation, "action_mode": args.action_mode, "action_repeat": args.action_repeat, "seed": args.seed, "episodes": len(episodes), "wall_s": round(wall, 1),
               "success_rate": sum(e["success"] for e in episodes) / max(1, len(episodes)),
               "tables": [{k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in r.items()} for r in rows if r["category"] == "all"]}
    write_text(os.path.join(out, "summary.json"), json.dumps(summary, indent=2, allow_nan=False) + "\n")
    return rows


def write_text(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def write_csv(path, fields, rows):
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.3f}" if isinstance(v, float) else v) for k, v in r.items()})
    os.replace(tmp, path)


def parse_args(argv):
    p = argparse.ArgumentParser(description="Evaluate a policy on ManiSoft's held-out scenes (the paper's tables)")
    p.add_argument("--task", default="all", choices=TASKS + ("all",))
    p.add_argument("--setting", default="clean", choices=SETTINGS + ("all",))
    p.add_argument("--policy", default="expert", help="expert | random | replay:DIR | python:MODULE:FUNCTION | ws://HOST:PORT")
    p.add_argument("--episodes-per-category", type=int, default=None,
                   help="episodes per target category (default: the paper's protocol, 20 clean and 40 randomized)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", required=True)
    p.add_argument("--jobs", type=int, default=1, help="worker processes")
    p.add_argument("--chunk-steps", type=int, default=1, help="actions of a chunk executed before asking the policy again")
    p.add_argument("--action-mode", default="torque", choices=("torque", "ee_pose"),
                   help="torque: the paper's 3n + 1 torques and S a control step; ee_pose: an end-effector target "
                        "(position, rotation vector) and S tracked by the model executor for --action-repeat control steps")
    p.add_argument("--action-repeat", type=int, default=36, help="control steps an ee_pose action is tracked (36: 20 Hz)")
    p.add_argument("--observation", default="image", choices=("image", "privileged"),
                   help="what a python: policy sees: the image and instruction, or the privileged state and the scene JSON")
    p.add_argument("--policy-timeout", type=float, default=60.0, help="seconds a policy call may take")
    p.add_argument("--image-size", type=int, nargs=2, default=[514, 514], metavar=("W", "H"))
    p.add_argument("--save-actions", action="store_true", help="write each episode's actions to OUT/actions/ (for replay:OUT)")
    p.add_argument("--python-path", action="append", default=[], help="extra directory to import python: policies from")
    p.add_argument("--max-scan", type=int, default=None, help="eval indices scanned per task and setting to fill the categories")
    p.add_argument("--indices", type=int, nargs="+", default=None, help="run these eval indices of each task and setting instead")
    p.add_argument("--resume", action="store_true", help="go on with the run in --out (the same arguments): run the episodes it has not finished")
    args = p.parse_args(argv)
    try:
        check_spec(args.policy)
    except ValueError as e:
        p.error(str(e))
    for name in ("jobs", "chunk_steps", "action_repeat"):
        if getattr(args, name) < 1:
            p.error(f"--{name.replace('_', '-')} must be >= 1")
    if args.episodes_per_category is not None and args.episodes_per_category < 1:
        p.error("--episodes-per-category must be >= 1")
    if not args.policy_timeout > 0:
        p.error("--policy-timeout must be > 0")
    if args.observation == "privileged" and not args.policy.startswith("python:"):
        p.error(f"--observation privileged is for python: policies (--policy {args.policy} sees what it always sees)")
    for name in ("indices", "max_scan"):
        values = getattr(args, name)
        for v in values if isinstance(values, list) else [values]:
            if v is not None and v < 0:
                p.error(f"--{name.replace('_', '-')} must be >= 0 (got {v})")
    if args.policy.startswith("python:"):
        module = args.policy.split(":")[1]
        for path in [os.getcwd()] + list(args.python_path):
            if path not in sys.path:
                sys.path.insert(0, path)
        try:
            found = importlib.util.find_spec(module) is not None
        except (ImportError, ValueError):
            found = False
        if not found:
            p.error(f"--policy {args.policy}: no module named '{module}' in the working directory, --python-path or sys.path")
    try:
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, ".write_check"), "w"):
            pass
        os.remove(os.path.join(args.out, ".write_check"))
    except OSError as e:
        p.error(f"--out {args.out}: cannot write there ({e.strerror or e})")
    args.tasks = TASKS if args.task == "all" else (args.task,)
    args.settings = SETTINGS if args.setting == "all" else (args.setting,)
    return args


# ---- the run's progress: run.json (its arguments) and episodes.jsonl (each finished episode)

RUN_ARGUMENTS = ("policy", "seed", "tasks", "settings", "episodes_per_category", "indices", "max_scan", "chunk_steps",
                 "policy_timeout", "image_size", "action_mode", "action_repeat", "observation")


def run_arguments(args):
    """What defines a run's episodes and their outcomes (compared on --resume)."""
    return {k: (list(v) if isinstance(v, (list, tuple)) else v) for k, v in ((k, getattr(args, k)) for k in RUN_ARGUMENTS)}


def flag_error(message):
    """A bad flag: one line on stderr, exit 2 (as argparse does)."""
    print(f"evaluate.py: error: {message}", file=sys.stderr)
    raise SystemExit(2)


def finished_episodes(args, plan):
    """The episodes of the run in --out already finished, by plan number: none for a new run. A
    folder holding another run is refused (without --resume, or with other arguments)."""
    run_path, progress_path = os.path.join(args.out, "run.json"), os.path.join(args.out, "episodes.jsonl")
    if not os.path.exists(run_path):
        if os.path.exists(progress_path):
            flag_error(f"--out {args.out}: episodes.jsonl without run.json: not a run of evaluate.py; choose another folder")
        write_text(run_path, json.dumps(run_arguments(args), indent=2) + "\n")
        return {}
    try:
        with open(run_path) as f:
            before = json.load(f)
    except (OSError, ValueError) as e:
        flag_error(f"{run_path}: unreadable ({e}); choose another --out")
    if not args.resume:
        flag_error(f"--out {args.out} holds a run already (run.json): pass --resume to go on with it, or choose another folder")
    for key, value in run_arguments(args).items():
        if before.get(key) != value:
            flag_error(f"--resume: --{key.replace('_', '-')} differs from the run in {args.out} (it ran with {before.get(key)!r}, now {value!r})")
    done = {}
    if os.path.exists(progress_path):
        with open(progress_path) as f:
            lines = f.read().split("\n")
        for number, line in enumerate(lines[:-1], 1):  # the text after the last newline: a line cut by a kill, run again
            try:
                record = json.loads(line)
                task, setting, index = plan[record["number"]][:3]
                if (record["task"], record["setting"], record["index"]) != (task, setting, index):
                    raise ValueError(f"episode {record['number']} is {record['task']} {record['setting']} {record['index']} here, "
                                     f"{task} {setting} {index} in the plan")
            except (ValueError, KeyError, IndexError, TypeError) as e:
                raise RuntimeError(f"{progress_path}:{number}: not an episode of this run ({e})") from None
            done[record["number"]] = record
    return done


def append_episode(path, record):
    """Appends one finished episode to episodes.jsonl, on disk before the next one starts."""
    with open(path, "a") as f:
        f.write(json.dumps(record) + "\n")
        f.flush()
        os.fsync(f.fileno())


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if args.save_actions:
        os.makedirs(os.path.join(args.out, "actions"), exist_ok=True)
    t0 = time.perf_counter()
    sampler = manisoft.SceneSampler()
    plan = []
    for setting in args.settings:
        k = args.episodes_per_category or (20 if setting == "clean" else 40)
        for task in args.tasks:
            if args.indices:
                plan += [(task, setting, i, target_category(sampler.sample(task, setting, i, args.seed, "eval"))) for i in args.indices]
            else:
                plan += plan_episodes(task, setting, k, args.seed, args.max_scan or 60 * k, sampler)
    try:
        done = finished_episodes(args, plan)
    except RuntimeError as e:
        print(f"evaluate.py: {e}", file=sys.stderr)
        return 1
    todo = [p + (n,) for n, p in enumerate(plan) if n not in done]
    print(f"{len(plan)} episodes ({', '.join(f'{t} {s}: {sum(1 for p in plan if p[:2] == (t, s))}' for t in args.tasks for s in args.settings)})"
          + (f"; {len(done)} finished before, {len(todo)} to run" if done else ""), flush=True)
    stopped = run_episodes(args, todo, done, len(plan))
    if stopped:
        print(f"evaluate.py: {stopped}; the {len(done)} finished episodes are in {os.path.join(args.out, 'episodes.jsonl')}: "
              "--resume with the same arguments runs the others", file=sys.stderr, flush=True)
        return 130 if stopped == "interrupted" else 1
    results = [{k: v for k, v in done[n].items() if k != "number"} for n in sorted(done)]
    rows = write_outputs(args.out, args, results, time.perf_counter() - t0)
    for r in rows:
        if r["category"] == "all":
            print(f"{r['task']:>4} {r['setting']:<10} ACC {r['acc']:5.1f}% [{r['acc_low']:.1f}, {r['acc_high']:.1f}] over {r['episodes']} episodes")
    print(f"tables: {os.path.join(args.out, 'results.md')}")
    return 0


def run_episodes(args, todo, done, total):
    """Runs `todo` (in worker processes with --jobs > 1), adding each finished episode to `done`
    and to episodes.jsonl; returns why the run stopped early ("" when every episode ran)."""
    progress = os.path.join(args.out, "episodes.jsonl")
    pool = None
    try:
        if args.jobs == 1:
            _worker_init(args)
            results = map(_worker_run, todo)
        else:
            pool = multiprocessing.get_context("spawn").Pool(args.jobs, initializer=_worker_init, initargs=(args, True))
            results = pool.imap_unordered(_worker_run, todo)
        for record, hung in results:
            append_episode(progress, record)
            done[record["number"]] = record
            ok = sum(e["success"] for e in done.values())
            print(f"[{len(done)}/{total}] {record['task']} {record['setting']} {record['category']} index {record['index']}: "
                  f"{'success' if record['success'] else record['failure']} after {record['steps']} steps ({record['wall_s']:.1f} s); "
                  f"success so far {ok}/{len(done)}", flush=True)
            if hung:
                return f"the policy did not answer within --policy-timeout {args.policy_timeout} s and is still running: the evaluation stops"
        return ""
    except KeyboardInterrupt:
        return "interrupted"
    finally:
        if pool is not None:
            pool.terminate()
            pool.join()
        elif _worker is not None:
            atexit.unregister(_worker.close)
            _worker.close()


if __name__ == "__main__":
    sys.exit(main())
