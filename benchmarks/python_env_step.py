#!/usr/bin/env python3
"""Speed of the Python task environment (targets: env.step without rendering at most 20% slower
than the C++ step; with the OpenGL renderer at most 10 ms per step). The expert's actions on COLL
clean train scene 3 are recorded once, then replayed through env.step: without rendering (compare
with bench_task's control_step, the same steps in C++), and with the 514 x 514 camera image.
Prints min and median over --repeats of the mean step time (wall and CPU of this process).
Run: PYTHONPATH=build/<config>/python /usr/bin/python3 benchmarks/python_env_step.py
"""
import argparse
import statistics
import time

import manisoft


def replay(env, actions):
    env.reset(options={"index": 3})
    w0, c0 = time.perf_counter(), time.process_time()
    for a in actions:
        env.step(a)
    return (time.perf_counter() - w0) / len(actions), (time.process_time() - c0) / len(actions)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--render-steps", type=int, default=300, help="steps of the rendered runs")
    args = p.parse_args()
    env = manisoft.make_env("COLL", "clean", seed=0, render=False)
    env.reset(options={"index": 3})
    actions = []
    while True:
        a = env.expert_action()
        actions.append(a)
        *_, terminated, truncated, _ = env.step(a)
        if terminated or truncated:
            break
    variants = [("step, no rendering", env, actions),
                ("step + 514x514 image (shadows)", manisoft.make_env("COLL", "clean", seed=0, render=True), actions[:args.render_steps])]
    for name, e, acts in variants:
        runs = [replay(e, acts) for _ in range(args.repeats)]
        wall = [r[0] * 1e6 for r in runs]
        cpu = [r[1] * 1e6 for r in runs]
        print(f"{name:32s} {len(acts):5d} steps: wall min {min(wall):8.1f} us, median {statistics.median(wall):8.1f} us; "
              f"CPU min {min(cpu):8.1f} us, median {statistics.median(cpu):8.1f} us")


if __name__ == "__main__":
    main()
