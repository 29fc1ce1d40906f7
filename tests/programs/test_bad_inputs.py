"""Bad inputs to the command-line programs, run as a user types them: each is refused with a
non-zero exit status and a message that names the flag and the value, the key and the file, or
the file that could not be written, and leaves no output that looks complete.

    test_bad_inputs.py BIN_DIR SCRATCH_DIR

BIN_DIR holds the example programs. rod_sim, reach_eval, world_demo, asset_gallery, scene_sample
and render_scene are required (the tests build them); run_task, generate_dataset and pick_place_eval are checked when
they are there (builds that only check them for warnings do not make them). Every case is listed
as it runs: program, input, exit status and the message's first line, and is a row of
docs/bad-inputs.md (tests/bad_input_table.py): the sections of flags, scene files, traces and
weight files.
"""
import json
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from bad_input_table import Section, cell  # noqa: E402

BIN, SCRATCH = sys.argv[1], sys.argv[2]
failures = []
OPTIONAL = ("run_task", "generate_dataset", "pick_place_eval")


def not_built_here(row):
    """A documented row of an optional program this build does not make: kept, not checked."""
    name = row.split("`")[1]
    return name in OPTIONAL and not os.path.exists(os.path.join(BIN, name))


FLAGS = Section("Program flags and output files", """
Each program refuses a bad flag with exit status 2 and one line naming the flag, the value and
the limit; an output it cannot write (a full disk: `/dev/full`) or a run that fails is exit status
1, and the partial output is removed. Test `bad_inputs` (`tests/programs/test_bad_inputs.py`).
""", ["program", "input", "exit", "message"], not_built_here)
SCENES = Section("Scene files", """
A scene file is read as strictly as JSON allows and then validated as a sampled scene is: a
number out of range, a duplicate or unknown key, an object off the table, inside another or
floating, and a goal that already holds or cannot be reached are refused before any step, naming
the file, the key or the object and the reason. The files are scenes written by `scene_sample`,
edited as the second column says. Test `bad_inputs` (`tests/programs/test_bad_inputs.py`).
""", ["program", "scene file (edited)", "exit", "message"], not_built_here)
TRACES = Section("Traces", """
A trace (the per-step CSV that `run_task --trace` writes and `render_scene --trace` draws) must
have the columns of its scene's objects and finite cells. Test `bad_inputs`
(`tests/programs/test_bad_inputs.py`).
""", ["program", "input", "exit", "message"], not_built_here)


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


def refused(prog, args, expected, absent=(), code=None, section=FLAGS, shown=None):
    """`prog args` exits non-zero (`code` if given), prints every string of `expected` and leaves
    none of the paths `absent` (nor their temporary .tmp files). The row shows `shown` for the
    input when given (what was edited into a file), else the arguments."""
    if prog is None:
        return
    rc, out = run(prog, args)
    first = next((line for line in out.splitlines() if line.strip()), "")
    print(f"{os.path.basename(prog)} {' '.join(args)}\n    exit {rc}: {first}")
    section.add(f"`{os.path.basename(prog)}`", f"`{cell(shown or ' '.join(args), SCRATCH)}`", str(rc), cell(first, SCRATCH))
    problems = []
    if rc == 0 or (code is not None and rc != code):
        problems.append(f"exit status {rc}, expected {code if code is not None else 'non-zero'}")
    problems += [f"the message lacks {e!r}" for e in expected if e not in out]
    problems += [f"{p} was left behind" for p in absent for p in (p, p + ".tmp") if os.path.exists(p)]
    if problems:
        failures.append(f"{os.path.basename(prog)} {' '.join(args)}: " + "; ".join(problems) + "\n" + out)


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
    refused(reach_eval, ["--seed", "1", "--hold-steps", "0", "--out", out], ["--hold-steps must be in [1, 1500] (got 0)"], [out], 2)
    refused(reach_eval, ["--seed", "1", "--targets", "1", "--out", "/dev/full"], ["writing '/dev/full' failed"], code=1)
    if reach_eval and "--load-kg" not in accepted(reach_eval, ["--help"]):
        failures.append("reach_eval --help does not list --load-kg")


def other_program_cases():
    world_demo, asset_gallery = program("world_demo"), program("asset_gallery")
    out = scratch("world.csv")
    refused(world_demo, ["--samples", "abc", "--map", "--out", out], ["--samples expects a number (got 'abc')"], [out], 2)
    refused(world_demo, ["--samples", "0", "--map", "--out", out], ["--samples must be in [1, 1000000] (got 0)"], [out], 2)
    refused(world_demo, ["--mount", "1", "--out", out], ["--mount"], [out], 2)
    sheet = scratch("sheet.png")
    refused(asset_gallery, ["--contact-sheet", sheet, "--columns", "0"], ["--columns must be in [1, 100] (got 0)"], [sheet], 2)


WEIGHTS = Section("Weight files", """
An MLP executor's weight file (`control/mlp_executor.hpp`: a plain-text header, then each layer's
weight rows and bias) is read whole before any episode: a missing file, a layer that does not fit
what follows, a number that is not finite and a network whose sizes do not match the arm are
refused naming the file and the line. `reach_eval --executor mlp --weights FILE --targets 1
--seed 1 --out DIR/reach.csv`; no CSV is left. Test `bad_inputs` (`tests/programs/test_bad_inputs.py`).
""", ["program", "weight file", "exit", "message"])


def weight_cases():
    reach_eval = program("reach_eval")
    out = scratch("reach.csv")
    head = "manisoft-mlp 1\nlayers 1\ninput 2\n"
    for name, text, words in [("missing.txt", None, "cannot open the MLP weight file"),
                              ("huge_layer.txt", "manisoft-mlp 1\nlayers 1\ninput 1000000\nlayer 1000000 linear\n", "huge_layer.txt:5: unexpected end of file"),
                              ("nan_weight.txt", head + "layer 1 linear\n1 nan\n0\n", "nan_weight.txt:5: 'nan' is not finite"),
                              ("no_bias.txt", head + "layer 1 linear\n1 2\n", "no_bias.txt:6: unexpected end of file, expected a bias row"),
                              ("too_small.txt", head + "layer 1 linear\n1 2\n0\n", "too_small.txt: the network outputs 1 values, the action needs 3 x 20 = 60")]:
        path = scratch(name)
        if text is not None:
            with open(path, "w") as f:
                f.write(text)
        refused(reach_eval, ["--executor", "mlp", "--weights", path, "--targets", "1", "--seed", "1", "--out", out], [words], [out], 1,
                section=WEIGHTS, shown=name + ("" if text is None else ": " + text.replace("\n", " / ").strip(" /")))


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


def sampled(scene_sample, task):
    """A clean scene of `task` (index 0, seed 0) written by scene_sample, or None."""
    path = scratch(task.lower() + ".json")
    accepted(scene_sample, ["--task", task, "--setting", "clean", "--index", "0", "--seed", "0", "--out", path, "--quiet"])
    if not os.path.exists(path):
        failures.append(f"scene_sample wrote no {task} scene: its scene file cases are skipped")
        return None
    return path


def scene_edit(source, name, edit):
    """`source` (a scene file) with `edit(scene)` applied, written as `name` in the scratch folder."""
    scene = json.load(open(source))
    edit(scene)
    path = scratch(name)
    json.dump(scene, open(path, "w"), indent=1)
    return path


def position(scene, i):
    return scene["objects"][i]["pose"]["position"]


def flag_cases():
    scene_sample = program("scene_sample")
    aln = scratch("aln.json")
    refused(scene_sample, ["--task", "ALN", "--setting", "clean", "--index", "-1", "--seed", "0", "--out", aln], ["--index must be >= 0 (got -1)"], [aln], 2)
    refused(scene_sample, ["--task", "ALN", "--setting", "clean", "--index", "0", "--seed", "-1", "--out", aln], ["--seed must be >= 0 (got -1)"], [aln], 2)
    refused(scene_sample, ["--task", "ALN", "--setting", "clean", "--index", "0", "--seed", "0", "--out", "/dev/full"],
            ["writing the scene file '/dev/full' failed"], code=1)
    run_task, generate_dataset, pick_place_eval = (program(p, required=False) for p in OPTIONAL)
    refused(run_task, ["--task", "ALN", "--index", "-1"], ["--index must be >= 0 (got -1)"], code=2)
    refused(run_task, ["--task", "ALN", "--seed", "-1"], ["--seed must be >= 0 (got -1)"], code=2)
    refused(run_task, ["--task", "ALN", "--path-speed", "0"], ["--path-speed must be > 0 (got 0)"], code=2)
    # an expert configuration file (task/expert_config_json.hpp): refused naming the file and the key
    for name, text, words in [("unknown_key.json", '{"carry": {"speed": 1.2}}', "carry.speed is not a setting of the expert"),
                              ("wrong_type.json", '{"settle": {"max_steps": 1.5}}', "settle.max_steps = 1.5 is invalid: it must be an integer"),
                              ("negative_speed.json", '{"carry": {"peak_speed": -1}}', "ExpertConfig carry.peak_speed = -1 is invalid")]:
        path = scratch(name)
        with open(path, "w") as f:
            f.write(text)
        refused(run_task, ["--task", "ALN", "--expert-config", path, "--quiet"], [path + ": ", words], code=1,
                shown=f"--task ALN --expert-config {name}: {text}")
    dataset = scratch("dataset")
    refused(generate_dataset, ["--tasks", "ALN", "--clean", "1", "--seed", "-1", "--out", dataset], ["--seed must be >= 0 (got -1)"], [dataset], 2)
    refused(generate_dataset, ["--tasks", "ALN", "--clean", "-1", "--out", dataset], ["--clean must be >= 0 (got -1)"], [dataset], 2)
    out = scratch("pick.csv")
    refused(pick_place_eval, ["--episodes", "1", "--seed", "1", "--mass", "nan", "--out", out], ["--mass must be a finite number (got nan)"], [out], 2)
    refused(pick_place_eval, ["--episodes", "1", "--seed", "1", "--mass", "9", "--out", out], ["--mass must be in [0.001, 5] (got 9)"], [out], 2)


def scene_file_cases():
    scene_sample, render_scene, run_task = program("scene_sample"), program("render_scene"), program("run_task", required=False)
    aln, arr, coll, stk, ovr = (sampled(scene_sample, t) for t in ("ALN", "ARR", "COLL", "STK", "OVR"))
    if None in (aln, arr, coll, stk, ovr):
        return
    images = scratch("images")
    huge = edited(aln, scratch("huge.json"), r'"half_x": [-+0-9.e]+', '"half_x": 1e400')
    refused(render_scene, ["--scene", huge, "--out", images], [huge, "1e400"], [images], section=SCENES, shown="huge.json: table.half_x 1e400")
    refused(run_task, ["--scene", huge, "--quiet"], [huge, "1e400"], code=1, section=SCENES, shown="huge.json: table.half_x 1e400")
    duplicate = edited(aln, scratch("duplicate.json"), '"friction": ', '"friction": 0.1, "friction": ')
    refused(render_scene, ["--scene", duplicate, "--out", images], [duplicate + ": table.friction: duplicate key"], [images],
            section=SCENES, shown="duplicate.json: table.friction given twice")
    misspelled = edited(aln, scratch("misspelled.json"), '"rolling_resistance"', '"rolling_resistence"')
    refused(render_scene, ["--scene", misspelled, "--out", images], [misspelled + ": table.rolling_resistence: unknown field"], [images],
            section=SCENES, shown="misspelled.json: table.rolling_resistence")
    # scenes that run_task must not run: each (file, what was edited, words the refusal must say)
    for name, source, shown, edit, words in [
            ("in_container.json", coll, "COLL: the object already in the basket (z + 0.005 over the basket's origin)",
             lambda s: s["objects"][1]["pose"].update(position=[*position(s, 0)[:2], position(s, 0)[2] + 0.005]),
             ["the goal already holds before any step (inside"]),
            ("stacked.json", stk, "STK: the plates already stacked",
             lambda s: s["objects"][1]["pose"].update(position=[*position(s, 0)[:2], position(s, 0)[2] + 0.005]),
             ["the goal already holds before any step (above_below, centred_on_below"]),
            ("smallest_first.json", stk, "STK: goal.items listed narrowest first",
             lambda s: s["goal"].update(items=s["goal"]["items"][::-1]), ["items go from the widest (bottom) to the narrowest (top)"]),
            ("container_without_receptacle.json", coll, "COLL: goal.container names the sand clock",
             lambda s: s["goal"].update(container=1, object=0), ["goal.container = 1 ('sand_clock/03') has no receptacle"]),
            ("goal_object_5.json", coll, "COLL: goal.object 5 of 2 objects", lambda s: s["goal"].update(object=5),
             ["goal.object = 5 is out of range: the scene has 2 objects"]),
            ("below_table.json", coll, "COLL: objects[1] at z 0.5, below the table top", lambda s: position(s, 1).__setitem__(2, 0.5),
             ["objects[1].pose position z = 0.5 is not on the table"]),
            ("far_away.json", coll, "COLL: objects[1] at z 1e308", lambda s: position(s, 1).__setitem__(2, 1e308),
             ["objects[1].pose position z = 1e+308 is not on the table"]),
            ("floating.json", coll, "COLL: objects[1] 0.15 m above the table", lambda s: position(s, 1).__setitem__(2, 0.9),
             ["unstable placement: object 1 (sand_clock/03) drifted"]),
            ("twice.json", coll, "COLL: objects[1] listed twice (one pose)", lambda s: s["objects"].append(dict(s["objects"][1])),
             ["interpenetration: object 1 (sand_clock/03) and object 2 (sand_clock/03) overlap"]),
            ("in_obstacle.json", ovr, "OVR: the bottle inside the vase (the obstacle)",
             lambda s: s["objects"][0]["pose"].update(position=list(s["obstacles"][0]["pose"]["position"])), ["not a valid scene"])]:
        path = scene_edit(source, name, edit)
        refused(run_task, ["--scene", path, "--quiet"], [path] + words, code=1, section=SCENES, shown=f"{name}: {shown}")
    return aln, arr


def trace_cases(aln, arr):
    render_scene = program("render_scene")
    images = scratch("images")
    # one scene drawn at another scene's trace: ARR's objects are not ALN's
    arr_trace = trace_of(arr, scratch("arr.csv"))
    refused(render_scene, ["--scene", aln, "--trace", arr_trace, "--out", images], [arr_trace, "recorded in another scene"], [images], section=TRACES)
    # a frame that fails to draw (a zero quaternion) after the output folder was made: the new folders go again
    zero = edited(arr_trace, scratch("zero_quaternion.csv"), r"(\n(?:[^,]*,){9})0,1,0,0,", r"\g<1>0,0,0,0,")  # gripper_qw..qz
    nested = os.path.join(SCRATCH, "new", "images")
    refused(render_scene, ["--scene", arr, "--trace", zero, "--out", nested], [zero, "row 0: quaternion of 'gripper' has zero norm"], [os.path.dirname(nested)], 1, section=TRACES)
    nan = edited(arr_trace, scratch("nan_cell.csv"), r"(\n(?:[^,]*,){6})[^,]*,", r"\g<1>nan,")  # gripper_px
    refused(render_scene, ["--scene", arr, "--trace", nan, "--out", images], [nan, "gripper_px"], [images], 1, section=TRACES)
    no_column = edited(arr_trace, scratch("no_node3_y.csv"), r",node3_y,", ",node3_w,")
    refused(render_scene, ["--scene", arr, "--trace", no_column, "--out", images], [no_column, "no column 'node3_y'"], [images], 1, section=TRACES)
    short = edited(arr_trace, scratch("short_row.csv"), r",[^,\n]*\n$", "\n")
    refused(render_scene, ["--scene", arr, "--trace", short, "--out", images], [short], [images], 1, section=TRACES)
    accepted(render_scene, ["--scene", arr, "--trace", arr_trace, "--out", images])
    if render_scene and not os.path.exists(os.path.join(images, "rgb.png")):
        failures.append("render_scene --scene arr.json --trace arr.csv wrote no rgb.png")


def main():
    shutil.rmtree(SCRATCH, ignore_errors=True)
    os.makedirs(SCRATCH)
    rod_sim_cases()
    reach_eval_cases()
    other_program_cases()
    weight_cases()
    flag_cases()
    scenes = scene_file_cases()
    if scenes:
        trace_cases(*scenes)
    for section in (FLAGS, SCENES, TRACES, WEIGHTS):
        section.finish(failures)
    for f in failures:
        print("FAILED:", f)
    print(f"{len(failures)} failure(s)")
    if not failures:
        shutil.rmtree(SCRATCH, ignore_errors=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
