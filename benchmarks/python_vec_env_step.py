#!/usr/bin/env python3
"""Reach control steps a minute from Python: a Python loop over B single environments
(manisoft.make_env("reach")) against one vector environment (manisoft.make_vec_env("reach", B,
num_threads), 2 and 1 threads) for B = 1, 8, 64, in the same run. Every arm takes a fixed mild action (a few N m
per element, as bench_env's BatchedReachEnv benchmark) and no episode ends while timed (the
horizon is the default 1500; --steps < 1500). Prints min and median over --repeats of the wall
time of --steps batch steps, as control steps a minute (arms x steps / wall time).
With --env TASK the same for a task (make_env(TASK, render=False, privileged=True) against
make_vec_env(TASK, B)): arms get zero torques with the gripper open, so the arm falls onto the
table and the objects: each step has the rod, the gripper, the objects and their contacts; an
episode that ends (an object knocked off the table) resets within the timing, as a vector
environment's autoreset does. --render W H adds the camera image of every arm at every step
(make_env(TASK, render=True, camera=...) against make_vec_env(TASK, B, render=True, camera=...):
a renderer per single environment against one per arm of the vector environment, drawn on its
worker thread).
Run: PYTHONPATH=build/<config>/python /usr/bin/python3 benchmarks/python_vec_env_step.py [--env ALN]
"""
import argparse
import statistics
import time

import numpy as np

import manisoft


def mild_action(rows):
    a = np.zeros((rows, 3))
    a[1:] = [4.0, -2.0, 1.0]
    return a


def env_action(env):
    return mild_action(20) if env == "reach" else np.zeros(61)


def make_single(env, i, camera):
    """A single environment of `env`, reset (a task: to scene index i, as make_vec_env's arm i)."""
    if env == "reach":
        single = manisoft.make_env("reach", seed=i)
        single.reset()
        return single
    single = manisoft.make_env(env, "clean", seed=0, render=camera is not None, camera=camera, privileged=True)
    single.reset(options={"index": i})
    return single


def time_loop(envs, steps, action):
    t0 = time.perf_counter()
    for _ in range(steps):
        for env in envs:
            if any(env.step(action)[2:4]):  # a task episode that ended (the falling arm knocked an object off)
                env.reset()
    return time.perf_counter() - t0


def time_vec(vec, steps, action):
    """Steps on from where the last repetition left the arms (as time_loop does)."""
    actions = np.broadcast_to(action, (vec.num_envs,) + action.shape).copy()
    t0 = time.perf_counter()
    for _ in range(steps):
        vec.step(actions)
    return time.perf_counter() - t0


def report(name, arms, threads, steps, walls):
    rates = [arms * steps / w * 60 / 1e6 for w in walls]
    print(f"{name:22s} {arms:4d} arms {threads} threads: wall per batch step min {min(walls) / steps * 1e6:9.1f} us, "
          f"median {statistics.median(walls) / steps * 1e6:9.1f} us; control steps a minute best {max(rates):5.2f} M, "
          f"median {statistics.median(rates):5.2f} M", flush=True)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--steps", type=int, default=100, help="batch steps a repeat (< 1500: no episode ends)")
    p.add_argument("--threads", type=int, nargs="+", default=[2, 1], help="make_vec_env's num_threads, each measured")
    p.add_argument("--arms", type=int, nargs="+", default=[1, 8, 64])
    p.add_argument("--env", default="reach", help="reach, or a task (COLL, ALN, STK, ARR, OVR)")
    p.add_argument("--render", type=int, nargs=2, metavar=("W", "H"), help="a task: every arm's camera image at W x H pixels, every step")
    args = p.parse_args()
    if args.render and args.env == "reach":
        p.error("--render needs a task (--env)")
    camera = {"width": args.render[0], "height": args.render[1]} if args.render else None
    options = {"render": True, "camera": camera} if camera else {}
    action = env_action(args.env)
    for arms in args.arms:
        envs = [make_single(args.env, i, camera) for i in range(arms)]
        report("Python loop, make_env", arms, 1, args.steps, [time_loop(envs, args.steps, action) for _ in range(args.repeats)])
        for threads in args.threads:
            vec = manisoft.make_vec_env(args.env, arms, num_threads=threads, seed=0, **options)
            vec.reset()
            report("make_vec_env", arms, threads, args.steps, [time_vec(vec, args.steps, action) for _ in range(args.repeats)])
            vec.close()
        for env in envs:
            env.close()


if __name__ == "__main__":
    main()
