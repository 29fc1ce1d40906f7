#!/usr/bin/env bash
# The expert's success table: run_task on train scenes FIRST..LAST of every task and
# setting (seed 0), JOBS at a time, one JSON line an episode into OUT, then a summary by task and
# setting: successes, mean steps of the successes, failure reasons; the successes' lengths; COLL's
# and ARR's successes by the category of the object moved, ARR's by relation.
#   [TASKS="COLL ALN STK ARR OVR"] [SETTINGS="clean randomized"] [JOBS=2] \
#   scripts/expert_sweep.sh RUN_TASK OUT [LAST=199] [FIRST=0] [extra run_task flags...]
set -euo pipefail
run_task=$1 out=$2 last=${3:-199} first=${4:-0}
shift $(( $# < 4 ? $# : 4 ))
jobs=${JOBS:-2}
for task in ${TASKS:-COLL ALN STK ARR OVR}; do for setting in ${SETTINGS:-clean randomized}; do for i in $(seq "$first" "$last"); do
  echo "$task $setting $i"
done; done; done | xargs -P"$jobs" -L1 bash -c 'echo "$0 $1 $2 $("'"$run_task"'" --task $0 --setting $1 --index $2 --seed 0 --quiet '"$*"' | tail -1)"' > "$out"
/usr/bin/python3 - "$out" <<'PY'
import json, sys, collections
rows = collections.defaultdict(list)
for line in open(sys.argv[1]):
    task, setting, index, js = line.split(" ", 3)
    rows[(task, setting)].append(json.loads(js))
total = collections.Counter()
for (task, setting), eps in sorted(rows.items()):
    ok = [e for e in eps if e["success"]]
    fails = collections.Counter(e.get("failure") for e in eps if not e["success"])
    mean = sum(e["steps"] for e in ok) / max(1, len(ok))
    print(f"{task:4} {setting:10} {len(ok):3}/{len(eps)} ({100*len(ok)/len(eps):5.1f}%) mean steps {mean:6.0f}  {dict(fails)}")
    total[setting + "_ok"] += len(ok); total[setting] += len(eps)
for s in ("clean", "randomized"):
    if total[s]: print(f"{s}: {total[s+'_ok']}/{total[s]} ({100*total[s+'_ok']/total[s]:.1f}%)")
# Lengths of the successes, and successes by category (COLL, ARR: the object moved; ARR: relation).
for (task, setting), eps in sorted(rows.items()):
    steps = sorted(e["steps"] for e in eps if e["success"])
    if steps:
        print(f"{task:4} {setting:10} steps of successes: median {steps[len(steps) // 2]}, "
              f"90th percentile {steps[min(len(steps) - 1, (9 * len(steps)) // 10)]}, longest {steps[-1]}")
    for key in ("object", "relation"):
        if task not in ("COLL", "ARR") or (key == "relation" and task != "ARR"): continue
        by = collections.defaultdict(lambda: [0, 0])
        for e in eps:
            k = (e.get(key) or "?").split("/")[0]
            by[k][0] += e["success"]; by[k][1] += 1
        print(f"{task:4} {setting:10} by {key}: " + ", ".join(f"{k} {a}/{b}" for k, (a, b) in sorted(by.items())))
PY
