#!/usr/bin/env python3
"""verify_dataset against corrupted copies of a small generated dataset, and generate_dataset's
resume rule.

generate_dataset writes two ALN episodes (one clean, one randomized); verify_dataset accepts the
dataset and replays it. Each corruption below is applied with h5py (or to the raw bytes) to a copy,
and verify_dataset must exit 1 with the expected words (file, dataset or attribute, element, rule).
An action edited within the limits and re-signed with a digest computed here from the documented
byte stream (include/manisoft/dataset/episode_digest.hpp) passes the checks but not --replay, which
names the step after it. A resume with other arguments is refused naming each differing flag with
both values, and changes no file. Every case is a row of docs/bad-inputs.md's section on dataset
files (tests/bad_input_table.py).

Usage: verify_dataset_corruptions.py GENERATE_DATASET VERIFY_DATASET
"""
import hashlib
import os
import shutil
import struct
import subprocess
import sys
import tempfile

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from bad_input_table import Section, cell  # noqa: E402

GENERATE, VERIFY = sys.argv[1], sys.argv[2]
ARGS = ["--tasks", "ALN", "--clean", "1", "--randomized", "1", "--seed", "4"]
MASK64 = (1 << 64) - 1


def fnv1a64(h, data):
    for b in data:
        h = ((h ^ b) * 0x100000001B3) & MASK64
    return h


def digest(group):
    """The content digest of an episode group, from the byte stream episode_digest.hpp documents."""
    h = 0xCBF29CE484222325
    names = []
    group.visititems(lambda name, obj: names.append(name) if isinstance(obj, h5py.Dataset) else None)
    for name in sorted(names, key=lambda s: s.encode()):
        d = group[name]
        h = fnv1a64(h, name.encode() + b"\0" + struct.pack("<Q", d.ndim) + b"".join(struct.pack("<Q", s) for s in d.shape))
        h = fnv1a64(h, np.ascontiguousarray(d[()]).astype(d.dtype.newbyteorder("<")).tobytes())
    for name in sorted(group.attrs, key=lambda s: s.encode()):
        if name == "digest":
            continue
        v = group.attrs[name]
        v = v.encode() + b"\0" if isinstance(v, str) else np.asarray(v).astype(np.asarray(v).dtype.newbyteorder("<")).tobytes()
        h = fnv1a64(h, name.encode() + b"\0" + v)
    return "fnv1a64:%016x" % h


def verify(d, *extra):
    p = subprocess.run([VERIFY, d, *extra], capture_output=True, text=True)
    return p.returncode, (p.stdout + p.stderr).strip()


def flip_raw(path, dataset, element, mask):
    """XORs byte `element` of a contiguous (uncompressed) dataset in the file itself."""
    with h5py.File(path, "r") as f:
        offset = f[dataset].id.get_offset()
    assert offset is not None, dataset
    with open(path, "r+b") as raw:
        raw.seek(offset + element)
        b = raw.read(1)[0]
        raw.seek(offset + element)
        raw.write(bytes([b ^ mask]))


def tree_hash(d):
    out = hashlib.sha256()
    for root, _, files in sorted(os.walk(d)):
        for name in sorted(files):
            with open(os.path.join(root, name), "rb") as f:
                out.update(name.encode() + f.read())
    return out.hexdigest()


work = tempfile.mkdtemp(prefix="manisoft_verify_")
base = os.path.join(work, "base")
subprocess.run([GENERATE, *ARGS, "--out", base], check=True, stdout=subprocess.DEVNULL)
with h5py.File(os.path.join(base, "episodes", "demo_0.hdf5"), "r") as f:
    g = f["data/demo_0"]
    T = g["actions"].shape[0]
    S_COL = g["actions"].shape[1] - 1
    assert digest(g) == g.attrs["digest"], "the documented digest differs from the written one"
    EDIT_STEP = T // 2
    edit_value = g["actions"][EDIT_STEP, 3 * 4 + 1]

failures = []
TABLE = Section("Dataset files", """
`verify_dataset DIR` checks every file of a dataset that `generate_dataset` wrote: the schema (each
dataset and attribute, shapes, dtypes, value ranges), the scene JSON, the index and its splits, and
each episode's content digest; `--replay` re-simulates the episodes and names the first differing
step. The dataset is two ALN episodes (`generate_dataset --tasks ALN --clean 1 --randomized 1
--seed 4`), corrupted as the first column says (with h5py or in the file's bytes). A resume
(`generate_dataset ... --resume`) with other arguments than the run that wrote the dataset is
refused naming each differing flag, and changes no file. Test `verify_dataset_corruptions`
(`tests/dataset/verify_dataset_corruptions.py`).
""", ["corruption", "command", "exit", "message"])
code, text = verify(base, "--replay")
if code != 0 or "OK: 2 episodes" not in text or "2 episodes replayed bit for bit" not in text:
    failures.append(f"the generated dataset: exit {code}: {text}")
code, text = verify(base, "--replay", "--sample", "1")
if code != 0 or "1 episodes replayed" not in text:
    failures.append(f"--sample 1: exit {code}: {text}")

CASES = []


def case(expected, *extra):
    def register(corrupt):
        CASES.append((corrupt.__name__, corrupt, expected, extra))
        return corrupt
    return register


def demo0(d):
    return h5py.File(os.path.join(d, "episodes", "demo_0.hdf5"), "r+")


def index(d):
    return h5py.File(os.path.join(d, "dataset.hdf5"), "r+")


def set_attribute(name, value):
    def corrupt(d):
        with demo0(d) as f:
            f["data/demo_0"].attrs[name] = value
    return corrupt


def set_element(dataset, element, value):
    def corrupt(d):
        with demo0(d) as f:
            f["data/demo_0/" + dataset][element] = value
    return corrupt


for name, attribute, value, expected in [
        ("success_false", "success", 0.0, "attribute 'success' = 0 but the last reward is 1"),
        ("scene_not_json", "scene", '{"format": "manisoft.scene/1", "task": ', "attribute 'scene': not valid JSON"),
        ("scene_json_not_a_scene", "scene", '{"format": "manisoft.scene/1", "task": "ALN"}', "attribute 'scene': setting: missing field"),
        ("task_not_the_scenes", "task", "STK", "attribute 'task' = 'STK' but the scene attribute says 'ALN'"),
        ("unknown_attribute", "note", "added later", "unexpected attribute 'note'"),
        ("num_samples_wrong", "num_samples", np.int64(T + 1), f"num_samples = {T + 1} but actions has {T} rows"),
        ("steps_wrong", "steps", float(T - 1), f"attribute 'steps' = {T - 1} but the episode has {T} steps"),
        ("failure_with_success", "failure", "timeout", "attribute 'failure' = 'timeout' with success = 1"),
        ("instructions_changed", "instructions_seen", '["pick up the thing"]', "attribute 'instructions_seen' = '[\"pick up the thing\"]'"),
        ("seed_not_the_scenes", "seed", 5.0, "attribute 'seed' = 5 but the scene attribute says 4")]:
    CASES.append((name, set_attribute(attribute, value), expected, ()))

for name, dataset, element, value, expected in [
        ("action_1e30", "actions", (10, 7), 1e30,
         "/data/demo_0/actions: element [10, 7] (step 10, element 2, component d2) = 1e+30 is outside the actuation limit +-150 N m"),
        ("twist_beyond_limit", "actions", (10, 8), -75.5, "element [10, 8] (step 10, element 2, component d3) = -75.5 is outside the actuation limit +-75 N m"),
        ("base_element_torque", "actions", (3, 1), 0.25, "element [3, 1] (step 3, element 0, component d2) = 0.25 is outside the actuation limit +-0 N m"),
        ("s_is_7", "actions", (12, S_COL), 7, f"element [12, {S_COL}] (step 12, S) = 7: S must be 0 or 1"),
        ("s_is_half", "actions", (0, S_COL), 0.5, f"element [0, {S_COL}] (step 0, S) = 0.5: S must be 0 or 1"),
        ("action_nan", "actions", (4, 5), np.nan, "actions[4, 5] = nan is not finite"),
        ("action_infinite", "actions", (4, 5), -np.inf, "actions[4, 5] = -inf is not finite"),
        ("reward_5", "rewards", 2, 5, "/data/demo_0/rewards: element [2] = 5: rewards are 0"),
        ("last_done_0", "dones", T - 1, 0, f"/data/demo_0/dones: element [{T - 1}] = 0: dones must be 0 before the last step and 1 at it"),
        ("object_pose_nan", "obs/object_poses", (7, 3), np.nan, "obs/object_poses[7, 3] = nan is not finite"),
        ("ee_target_s_not_the_actions", "obs/ee_target", (12, 6), 1, "/data/demo_0/obs/ee_target: element [12, 6] (step 12, S) = 1 but the action's S is 0"),
        ("ee_waypoint_jumps", "obs/ee_waypoint", (5, 0), 2,
         "/data/demo_0/obs/ee_waypoint: element [5, 0] = 2: 0 at the first step, then the step before's (0) or one more")]:
    CASES.append((name, set_element(dataset, element, value), expected, ()))


@case("/data/demo_0/obs/rod_directors: missing dataset")
def rod_directors_deleted(d):
    with demo0(d) as f:
        del f["data/demo_0/obs/rod_directors"]


@case("/data/demo_0/dones: element [3] = 255")
def dones_byte_flipped(d):
    flip_raw(os.path.join(d, "episodes", "demo_0.hdf5"), "data/demo_0/dones", 3, 0xFF)


@case("content digest mismatch")
def object_poses_byte_flipped_still_finite(d):
    flip_raw(os.path.join(d, "episodes", "demo_0.hdf5"), "data/demo_0/obs/object_poses", 4 * (5 * 7 + 2), 0x01)


@case("missing attribute 'task'")
def task_deleted(d):
    with demo0(d) as f:
        del f["data/demo_0"].attrs["task"]


@case("/data/demo_0/rewards: dtype float32, the layout says float64")
def rewards_float32(d):
    with demo0(d) as f:
        g = f["data/demo_0"]
        r = g["rewards"][()]
        del g["rewards"]
        g["rewards"] = r.astype(np.float32)


@case("/data/demo_0/obs/eef_pose: shape")
def eef_pose_wrong_shape(d):
    with demo0(d) as f:
        g = f["data/demo_0/obs"]
        p = g["eef_pose"][()]
        del g["eef_pose"]
        g["eef_pose"] = p[:, :6]


@case("states has")
def states_row_missing(d):
    with demo0(d) as f:
        g = f["data/demo_0"]
        s = g["states"][()]
        del g["states"]
        g["states"] = s[:-1]


@case("/data/demo_0/extra: unexpected member")
def unknown_dataset(d):
    with demo0(d) as f:
        f["data/demo_0/extra"] = np.zeros(3)


@case("missing attribute 'digest'")
def digest_deleted(d):
    with demo0(d) as f:
        del f["data/demo_0"].attrs["digest"]


@case("demo_1.hdf5: cannot open the HDF5 file (truncated or corrupted?)")
def episode_truncated(d):
    p = os.path.join(d, "episodes", "demo_1.hdf5")
    os.truncate(p, os.path.getsize(p) // 2)


@case("demo_1.hdf5: not a readable HDF5 file (missing")
def episode_file_missing(d):
    os.remove(os.path.join(d, "episodes", "demo_1.hdf5"))


@case("episodes/demo_2.hdf5 is not in the index")
def episode_not_in_index(d):
    shutil.copy(os.path.join(d, "episodes", "demo_1.hdf5"), os.path.join(d, "episodes", "demo_2.hdf5"))


@case("demo_5.hdf5")
def index_links_missing_demo(d):
    with index(d) as f:
        f["data/demo_5"] = h5py.ExternalLink("episodes/demo_5.hdf5", "/data/demo_5")


@case("/mask/valid: demo_0 is in more than one split")
def mask_duplicate(d):
    with index(d) as f:
        del f["mask/valid"]
        f["mask/valid"] = np.array([b"demo_0"], dtype="S6")


@case("/mask/train: names demo_9, which is not in /data")
def mask_names_missing_demo(d):
    with index(d) as f:
        train = list(f["mask/train"][()]) + [b"demo_9"]
        del f["mask/train"]
        f["mask/train"] = np.array(train, dtype="S6")


@case("/data: total = ")
def index_total_wrong(d):
    with index(d) as f:
        f["data"].attrs["total"] = np.int64(f["data"].attrs["total"] + 1)


@case("differs from the index's env_args")
def index_of_another_run(d):
    with index(d) as f:
        f["data"].attrs["env_args"] = f["data"].attrs["env_args"].replace('"seed":4', '"seed":6')


@case("dataset.hdf5: not a readable HDF5 file")
def index_missing(d):
    os.remove(os.path.join(d, "dataset.hdf5"))


@case(f"/data/demo_0: replay: first differing step {EDIT_STEP + 1}: states [{EDIT_STEP + 1}, ", "--replay")
def action_edited_and_resigned(d):
    with demo0(d) as f:
        g = f["data/demo_0"]
        g["actions"][EDIT_STEP, 3 * 4 + 1] = edit_value + (-0.5 if edit_value > 0 else 0.5)
        g.attrs["digest"] = digest(g)
    code, text = verify(d)  # in range and signed: only the replay can tell
    if code != 0:
        failures.append(f"action_edited_and_resigned without --replay: exit {code}: {text}")


rows = []
for name, corrupt, expected, extra in CASES:
    d = os.path.join(work, name)
    shutil.copytree(base, d)
    corrupt(d)
    code, text = verify(d, *extra)
    last = text.splitlines()[-1] if text else ""
    rows.append(f"  {name}: exit {code}: {last}")
    TABLE.add(name.replace("_", " "), "`verify_dataset DIR" + "".join(" " + e for e in extra) + "`", str(code), cell(last, work))
    if code != 1 or expected not in text:
        failures.append(f"{name}: exit {code}, expected exit 1 with '{expected}', got: {text}")
    shutil.rmtree(d)

# the resume rule: other arguments are refused naming each one with both values; nothing changes
before = tree_hash(base)
for changed, words in [(["--seed", "6"], ["--seed is 6 here, 4 there"]),
                       (["--clean", "2", "--seed", "6"], ["--clean is 2 here, 1 there", "--seed is 6 here, 4 there"]),
                       (["--tasks", "ALN,ARR"], ['--tasks is ["ALN","ARR"] here, ["ALN"] there']),
                       (["--images", "every:10"], ["--images (every:K) is 10 here, 0 there"]),
                       (["--max-draws", "7"], ["--max-draws is 7 here, 100 there"])]:
    args = list(ARGS)
    for flag, value in zip(changed[::2], changed[1::2]):
        if flag in args:
            args[args.index(flag) + 1] = value
        else:
            args += [flag, value]
    p = subprocess.run([GENERATE, *args, "--out", base, "--resume"], capture_output=True, text=True)
    rows.append(f"  resume {' '.join(changed)}: exit {p.returncode}: {p.stderr.strip()}")
    TABLE.add("resumed with other arguments", f"`generate_dataset ... {' '.join(changed)} --resume`", str(p.returncode),
              cell(p.stderr.strip().splitlines()[0] if p.stderr.strip() else "", work))
    if p.returncode != 1 or not all(w in p.stderr for w in words):
        failures.append(f"resume with {changed}: exit {p.returncode}, expected 1 naming {words}: {p.stderr}")
p = subprocess.run([GENERATE, *ARGS, "--out", base, "--resume"], capture_output=True, text=True)
if p.returncode != 0:
    failures.append(f"resume with the same arguments: exit {p.returncode}: {p.stderr}")
if tree_hash(base) != before:
    failures.append("a refused (or empty) resume changed files in the dataset")

print("\n".join(rows))
TABLE.finish(failures)
shutil.rmtree(work)
if failures:
    print("FAIL:\n" + "\n".join(failures))
    sys.exit(1)
print(f"verify_dataset: {len(CASES)} corruptions rejected, the edited action found by --replay at step {EDIT_STEP + 1}; resume rule OK")
