#!/usr/bin/env python3
"""Reach control steps a minute from Python: a Python loop over B single environments
(manisoft.make_env("reach")) against one vector environment (manisoft.make_vec_env("reach", B,
num_threads), 2 and 1 threads) for B = 1, 8, 64, in the same run. Every arm takes a fixed mild action (a few N m
per element, as bench_env's BatchedReachEnv benchmark) and no episode ends while timed (the
horizon is the default 1500; --steps < 1500). Prints min and median over --repeats of the wall
time of --steps batch steps, as control steps a minute (arms x steps / wall time).
Run: PYTHONPATH=build/<config>/python /usr/bin/python3 benchmarks/python_vec_env_step.py
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


def time_loop(envs, steps):
    action = mild_action(20)
    for env in envs:
        env.reset()
    t0 = time.perf_counter()
    for _ in range(steps):
        for env in envs:
            env.step(action)
    return time.perf_counter() - t0


def time_vec(vec, steps):
    actions = np.broadcast_to(mild_action(20), (vec.num_envs, 20, 3)).copy()
    vec.reset()
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
    args = p.parse_args()
    for arms in args.arms:
        envs = [manisoft.make_env("reach", seed=i) for i in range(arms)]
        report("Python loop, make_env", arms, 1, args.steps, [time_loop(envs, args.steps) for _ in range(args.repeats)])
        for threads in args.threads:
            vec = manisoft.make_vec_env("reach", arms, num_threads=threads, seed=0)
            report("make_vec_env", arms, threads, args.steps, [time_vec(vec, args.steps) for _ in range(args.repeats)])
            vec.close()
        for env in envs:
            env.close()


if __name__ == "__main__":
    main()
