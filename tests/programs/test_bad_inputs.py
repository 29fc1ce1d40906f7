"""Bad inputs to the command-line programs, run as a user types them: each is refused with a
non-zero exit status and a message that names the flag and the value, the key and the file, or
the file that could not be written, and leaves no output that looks complete.

    test_bad_inputs.py BIN_DIR SCRATCH_DIR [--write-table]

BIN_DIR holds the example programs. rod_sim, reach_eval, scene_sample and render_scene are
required (the tests build them); run_task, generate_dataset and pick_place_eval are checked when
they are there (builds that only check them for warnings do not make them). Every case is listed
as it runs: program, input, exit status and the message's first line.

docs/bad-inputs.md holds the table of these cases as they run (the scratch folder written DIR):
every row of a program built here must be in it and every row of it that names such a program
must come out of this run, so the table cannot go stale. --write-table rewrites it from this run
(keeping the rows of programs not built here).
"""
import json
import os
import re
import shutil
import subprocess
import sys

BIN, SCRATCH = sys.argv[1], sys.argv[2]
WRITE_TABLE = "--write-table" in sys.argv[3:]
TABLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "docs", "bad-inputs.md")
failures = []
rows = []  # (program, input, exit status, message) of each refused case, as the table shows them


def program(name, required=True):
    path = os.path.join(BIN, name)
    if os.path.exists(path):
        return path
    if required:
        failures.append(f"{name}: not built ({path})")
    else:
        print(f"-- {name}: not built here, its cases are skipped")
    return None


def scratch(name):
    return os.path.join(SCRATCH, name)


def run(prog, args):
    done = subprocess.run([prog] + args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=120)
    return done.returncode, done.stdout


def refused(prog, args, expected, absent=(), code=None):
    """`prog args` exits non-zero (`code` if given), prints every string of `expected` and leaves
    none of the paths `absent` (nor their temporary .tmp files)."""
    if prog is None:
        return
    rc, out = run(prog, args)
    first = next((line for line in out.splitlines() if line.strip()), "")
    print(f"{os.path.basename(prog)} {' '.join(args)}\n    exit {rc}: {first}")
    rows.append(table_row(os.path.basename(prog), args, rc, first))
    problems = []
    if rc == 0 or (code is not None and rc != code):
        problems.append(f"exit status {rc}, expected {code if code is not None else 'non-zero'}")
    problems += [f"the message lacks {e!r}" for e in expected if e not in out]
    problems += [f"{p} was left behind" for p in absent for p in (p, p + ".tmp") if os.path.exists(p)]
    if problems:
        failures.append(f"{os.path.basename(prog)} {' '.join(args)}: " + "; ".join(problems) + "\n" + out)


def table_row(name, args, rc, message):
    """One line of docs/bad-inputs.md: the scratch folder written DIR, '|' escaped, decimals cut
    to 6 places (the last digits of a divergence may differ between compilers)."""
    cell = lambda text: re.sub(r"(\d\.\d{6})\d+", r"\1", text.replace(SCRATCH, "DIR").replace("|", "\\|"))
    return f"| `{name}` | `{cell(' '.join(args))}` | {rc} | {cell(message)} |"


TABLE_HEAD = """# Bad inputs and what the programs say

Each row is a bad input tried on a command-line program and the first line of what the program
says, with its exit status (1: refused by the library or a file that cannot be written; 2: a bad
flag). The test `bad_inputs` (`tests/programs/test_bad_inputs.py`) runs every row and fails when
this table no longer matches what the programs print; `test_bad_inputs.py BIN_DIR SCRATCH
--write-table` rewrites it. In every case nothing that looks like a complete output is left
behind (checked by the same test). DIR stands for the test's scratch folder.

| program | input | exit | message |
|---|---|---|---|
"""


def check_table():
    """The table against this run: see the module's docstring."""
    built = {r.split("`")[1] for r in rows}
    try:
        documented = [line for line in open(TABLE).read().splitlines() if line.startswith("| `")]
    except OSError:
        documented = []
    kept = [r for r in documented if r.split("`")[1] not in built]
    if WRITE_TABLE:
        with open(TABLE, "w") as f:
            f.write(TABLE_HEAD + "\n".join(rows + kept) + "\n")
        print(f"-- wrote {TABLE}: {len(rows)} rows from this run, {len(kept)} kept")
        return
    missing = [r for r in rows if r not in documented]
    stale = [r for r in documented if r.split("`")[1] in built and r not in rows]
    if missing or stale:
        failures.append(f"{TABLE} does not match this run (rewrite it with --write-table):\n"
                        + "".join(f"  not in the table: {r}\n" for r in missing) + "".join(f"  not printed any more: {r}\n" for r in stale))


def accepted(prog, args):
    if prog is None:
        return ""
    rc, out = run(prog, args)
    if rc != 0:
        failures.append(f"{os.path.basename(prog)} {' '.join(args)}: exit {rc}, expected 0\n{out}")
    return out


def rod_sim_cases():
    rod_sim = program("rod_sim")
    out = scratch("rod.csv")
    refused(rod_sim, ["--t-end", "1e300", "--out", out], ["--t-end 1e+300 s is 5e+303 steps", "at most 1e+08 steps"], [out], 2)
    refused(rod_sim, ["--t-end", "1e10", "--out", out], ["--t-end 1e+10 s", "(--t-end <= 20000 s at this --dt)"], [out], 2)
    refused(rod_sim, ["--dt", "0", "--out", out], ["--dt must be > 0 (got 0)"], [out], 2)
    refused(rod_sim, ["--dt", "nan", "--out", out], ["--dt must be a finite number (got nan)"], [out], 2)
    refused(rod_sim, ["--damping", "uniform:-5", "--out", out], ["--damping value must be >= 0 (got -5)"], [out], 2)
    refused(rod_sim, ["--n", "1", "--out", out], ["--n must be in [2, 1000000] (got 1)"], [out], 2)
    refused(rod_sim, ["--frobnicate", "--out", out], ["--frobnicate"], [out], 2)
    refused(rod_sim, ["--t-end", "0.02", "--out", "/dev/full"], ["writing '/dev/full' failed"], code=1)
    # dt 1e-3 is above the stability limit: the rod diverges at step 16, before the first 0.1 s row
    refused(rod_sim, ["--dt", "1e-3", "--allow-unstable", "--t-end", "1", "--record-every", "0.005", "--out", out], ["diverged"], [out], 1)
    if rod_sim and "--t-end" not in accepted(rod_sim, ["--help"]):
        failures.append("rod_sim --help does not list --t-end")
    # the run that succeeds writes its file: 0.02 s every 0.01 s is 3 rows after the header
    accepted(rod_sim, ["--t-end", "0.02", "--out", out])
    if rod_sim and (not os.path.exists(out) or len(open(out).read().splitlines()) != 4):
        failures.append(f"rod_sim --t-end 0.02: {out} should hold a header and 3 rows")


def reach_eval_cases():
    reach_eval = program("reach_eval")
    out = scratch("reach.csv")
    refused(reach_eval, ["--seed", "1", "--damping", "uniform:-5", "--out", out], ["--damping value must be >= 0 (got -5)"], [out], 2)
    # the limit: the bend limit 150 N m over g L = 9.81 m/s^2 x 1 m
    refused(reach_eval, ["--seed", "1", "--load-kg", "1e30", "--out", out], ["--load-kg must be in [0, 15.29051988] (got 1e30)"], [out], 2)
    refused(reach_eval, ["--seed", "-1", "--out", out], ["--seed must be in [0, 1e+15] (got -1)"], [out], 2)
    refused(reach_eval, ["--seed", "1", "--tol-pos", "0", "--out", out], ["--tol-pos must be > 0 (got 0)"], [out], 2)
    refused(reach_eval, ["--seed", "1", "--targets", "1", "--out", "/dev/full"], ["writing '/dev/full' failed"], code=1)
    if reach_eval and "--load-kg" not in accepted(reach_eval, ["--help"]):
        failures.append("reach_eval --help does not list --load-kg")


def edited(source, target, pattern, replacement):
    """`source` with the first match of the regular expression `pattern` replaced, as `target`."""
    text = open(source).read()
    if not re.search(pattern, text):
        failures.append(f"{source} has no {pattern!r} to edit")
    open(target, "w").write(re.sub(pattern, replacement, text, count=1))
    return target


def trace_of(scene_file, path):
    """A trace in run_task's layout posing the objects of `scene_file` where the scene puts them."""
    scene = json.load(open(scene_file))
    columns = ["step", "time", "phase", "S", "finger_width", "held"]
    pose = lambda name: [f"{name}_{c}" for c in ("px", "py", "pz", "qw", "qx", "qy", "qz")]
    columns += pose("gripper")
    for i in range(21):
        columns += [f"node{i}_x", f"node{i}_y", f"node{i}_z"]
    row = [0, 0, 7, 0, 0.1, -1, 0.3, 0.0, 1.0, 0, 1, 0, 0]
    for i in range(21):
        row += [0.05 * i - 0.5, 0.0, 1.2]
    for i, o in enumerate(scene["objects"]):
        columns += pose(f"object{i}")
        row += o["pose"]["position"] + [1, 0, 0, 0]
    with open(path, "w") as f:
        f.write(",".join(columns) + "\n" + ",".join(str(v) for v in row) + "\n")
    return path


def scene_cases():
    scene_sample, render_scene = program("scene_sample"), program("render_scene")
    aln, arr = scratch("aln.json"), scratch("arr.json")
    refused(scene_sample, ["--task", "ALN", "--setting", "clean", "--index", "-1", "--seed", "0", "--out", aln], ["--index must be >= 0 (got -1)"], [aln], 2)
    refused(scene_sample, ["--task", "ALN", "--setting", "clean", "--index", "0", "--seed", "-1", "--out", aln], ["--seed must be >= 0 (got -1)"], [aln], 2)
    refused(scene_sample, ["--task", "ALN", "--setting", "clean", "--index", "0", "--seed", "0", "--out", "/dev/full"],
            ["writing the scene file '/dev/full' failed"], code=1)
    accepted(scene_sample, ["--task", "ALN", "--setting", "clean", "--index", "0", "--seed", "0", "--out", aln, "--quiet"])
    accepted(scene_sample, ["--task", "ARR", "--setting", "clean", "--index", "0", "--seed", "0", "--out", arr, "--quiet"])
    if not (os.path.exists(aln) and os.path.exists(arr)):
        failures.append("scene_sample wrote no scene: the scene file cases are skipped")
        return aln, None
    images = scratch("images")
    huge = edited(aln, scratch("huge.json"), r'"half_x": [-+0-9.e]+', '"half_x": 1e400')
    refused(render_scene, ["--scene", huge, "--out", images], [huge, "1e400"], [images])
    duplicate = edited(aln, scratch("duplicate.json"), '"friction": ', '"friction": 0.1, "friction": ')
    refused(render_scene, ["--scene", duplicate, "--out", images], [duplicate + ": table.friction: duplicate key"], [images])
    misspelled = edited(aln, scratch("misspelled.json"), '"rolling_resistance"', '"rolling_resistence"')
    refused(render_scene, ["--scene", misspelled, "--out", images], [misspelled + ": table.rolling_resistence: unknown field"], [images])
    # one scene drawn at another scene's trace: ARR's objects are not ALN's
    arr_trace = trace_of(arr, scratch("arr.csv"))
    refused(render_scene, ["--scene", aln, "--trace", arr_trace, "--out", images], [arr_trace, "recorded in another scene"], [images])
    # a frame that fails to draw (a zero quaternion) after the output folder was made: the new folders go again
    zero = edited(arr_trace, scratch("zero_quaternion.csv"), r"(\n(?:[^,]*,){9})0,1,0,0,", r"\g<1>0,0,0,0,")  # gripper_qw..qz
    nested = os.path.join(SCRATCH, "new", "images")
    refused(render_scene, ["--scene", arr, "--trace", zero, "--out", nested], ["quaternion of 'gripper' has zero norm"], [os.path.dirname(nested)], 1)
    accepted(render_scene, ["--scene", arr, "--trace", arr_trace, "--out", images])
    if render_scene and not os.path.exists(os.path.join(images, "rgb.png")):
        failures.append("render_scene --scene arr.json --trace arr.csv wrote no rgb.png")
    return aln, huge


def optional_cases(aln, huge):
    run_task, generate_dataset, pick_place_eval = (program(p, required=False) for p in ("run_task", "generate_dataset", "pick_place_eval"))
    refused(run_task, ["--task", "ALN", "--index", "-1"], ["--index must be >= 0 (got -1)"], code=2)
    refused(run_task, ["--task", "ALN", "--seed", "-1"], ["--seed must be >= 0 (got -1)"], code=2)
    refused(run_task, ["--task", "ALN", "--path-speed", "0"], ["--path-speed must be > 0 (got 0)"], code=2)
    if huge:
        refused(run_task, ["--scene", huge, "--quiet"], [huge, "1e400"], code=1)
    dataset = scratch("dataset")
    refused(generate_dataset, ["--tasks", "ALN", "--clean", "1", "--seed", "-1", "--out", dataset], ["--seed must be >= 0 (got -1)"], [dataset], 2)
    refused(generate_dataset, ["--tasks", "ALN", "--clean", "-1", "--out", dataset], ["--clean must be >= 0 (got -1)"], [dataset], 2)
    out = scratch("pick.csv")
    refused(pick_place_eval, ["--episodes", "1", "--seed", "1", "--mass", "nan", "--out", out], ["--mass must be a finite number (got nan)"], [out], 2)
    refused(pick_place_eval, ["--episodes", "1", "--seed", "1", "--mass", "9", "--out", out], ["--mass must be in [0.001, 5] (got 9)"], [out], 2)


def main():
    shutil.rmtree(SCRATCH, ignore_errors=True)
    os.makedirs(SCRATCH)
    rod_sim_cases()
    reach_eval_cases()
    aln, huge = scene_cases()
    optional_cases(aln, huge)
    check_table()
    for f in failures:
        print("FAILED:", f)
    print(f"{len(failures)} failure(s)")
    if not failures:
        shutil.rmtree(SCRATCH, ignore_errors=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
