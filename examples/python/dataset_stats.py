#!/usr/bin/env python3
"""dataset_stats DIR [--out OUT]: the paper's figure 4 for a ManiSoft dataset, from the
files (h5py, numpy, matplotlib; the task list and target objects from the manisoft module): trajectory length histogram per task (lengths.png), target
object category frequency (categories.png), heat map of the target objects' initial positions on
the table (heatmap.png), instruction length in words (instructions.png), and stats.md, a Markdown
table per task and setting (episodes, mean / median / max steps). OUT defaults to DIR/stats."""
import argparse
import json
import os
from collections import Counter, defaultdict

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

import manisoft  # noqa: E402


def read(directory):
    rows = []
    with h5py.File(os.path.join(directory, "dataset.hdf5"), "r") as f:
        for name in sorted(f["data"].keys(), key=lambda n: int(n.split("_")[1])):
            demo = f["data"][name]
            a = demo.attrs
            scene = json.loads(a["scene"])
            obj = scene["objects"][manisoft.target_object(a["scene"])]
            instructions = [a["instruction"]] + json.loads(a["instructions_seen"]) + json.loads(a["instructions_unseen"])
            rows.append({"task": a["task"], "setting": a["setting"], "steps": int(a["num_samples"]),
                         "category": obj["asset_id"].split("/")[0], "position": obj["pose"]["position"][:2],
                         "table": scene["table"], "instruction_words": [len(i.split()) for i in instructions]})
    return rows


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("dir")
    p.add_argument("--out")
    args = p.parse_args()
    out = args.out or os.path.join(args.dir, "stats")
    os.makedirs(out, exist_ok=True)
    rows = read(args.dir)
    order = [t["name"] for t in manisoft.tasks()]
    tasks = sorted({r["task"] for r in rows}, key=order.index)

    fig, ax = plt.subplots(figsize=(6, 4))
    bins = np.linspace(0, manisoft.HORIZON, 31)
    ax.hist([[r["steps"] for r in rows if r["task"] == t] for t in tasks], bins=bins, label=tasks, stacked=True)
    ax.set(xlabel="trajectory length (control steps)", ylabel="episodes", title="(a) trajectory lengths per task")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "lengths.png"), dpi=100)

    counts = Counter(r["category"] for r in rows)
    fig, ax = plt.subplots(figsize=(7, 4))
    names = [c for c, _ in counts.most_common()]
    ax.bar(names, [counts[c] for c in names])
    ax.set(ylabel="episodes", title="(b) target object categories")
    ax.tick_params(axis="x", rotation=60)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "categories.png"), dpi=100)

    table = rows[0]["table"]
    cx, cy = table["top_center"][0], table["top_center"][1]
    hx, hy = table["half_x"], table["half_y"]
    xy = np.array([r["position"] for r in rows])
    fig, ax = plt.subplots(figsize=(5, 5 * hy / hx if hx else 5))
    h = ax.hist2d(xy[:, 0], xy[:, 1], bins=[np.linspace(cx - hx, cx + hx, 21), np.linspace(cy - hy, cy + hy, 21)], cmap="viridis")
    fig.colorbar(h[3], ax=ax, label="episodes")
    ax.set(xlabel="x (m)", ylabel="y (m)", title="(c) target object positions on the table", aspect="equal")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "heatmap.png"), dpi=100)

    fig, ax = plt.subplots(figsize=(6, 4))
    ax.hist([w for r in rows for w in r["instruction_words"]], bins=np.arange(0, 41, 2))
    ax.set(xlabel="instruction length (words)", ylabel="instructions", title="instruction lengths")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "instructions.png"), dpi=100)

    groups = defaultdict(list)
    for r in rows:
        groups[(r["task"], r["setting"])].append(r["steps"])
        groups[("all", r["setting"])].append(r["steps"])
        groups[("all", "all")].append(r["steps"])
    lines = [f"# Dataset statistics: {args.dir}", "", "| task | setting | episodes | mean steps | median | max |", "|---|---|---|---|---|---|"]
    for (task, setting), s in sorted(groups.items(), key=lambda kv: (kv[0][0] == "all", kv[0])):
        lines.append(f"| {task} | {setting} | {len(s)} | {np.mean(s):.0f} | {np.median(s):.0f} | {max(s)} |")
    words = [w for r in rows for w in r["instruction_words"]]
    lines += ["", f"Instructions: {len(words)} ({len(words) / len(rows):.1f} a scene), {np.mean(words):.1f} words on average.",
              f"Target categories: {len(counts)}.", ""]
    with open(os.path.join(out, "stats.md"), "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))
    print(f"plots: {out}/lengths.png categories.png heatmap.png instructions.png")


if __name__ == "__main__":
    main()
