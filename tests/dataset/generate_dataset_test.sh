#!/usr/bin/env bash
# generate_dataset end to end: a small dataset (ALN and ARR, 3 clean + 3 randomized
# episodes; a second one, COLL and STK, 2 + 2, is generated, verified and read too, so every task
# and setting is covered) made as 1 shard and as 3 shards run by GNU parallel with --index-only as the merge
# step must be identical file for file, bit for bit; a run killed mid-way and resumed must give the
# same files; verify_dataset accepts it, and names a truncated episode file; the h5py reader
# (examples/python/read_dataset.py) reads it; dataset_stats.py draws its plots and export_zarr.py
# writes Diffusion Policy's zarr layout with the same actions.
# render_dataset renders the images of a states-only dataset equal to those generated with it, and
# (where Blender is installed) the same frames with Blender.
# Usage: generate_dataset_test.sh GENERATE VERIFY READ_DATASET_PY PYTHON RENDER_DATASET
set -euo pipefail
gen=$1 verify=$2 reader=$3 python=$4 render=$5
examples=$(dirname "$reader")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
args=(--tasks ALN,ARR --clean 3 --randomized 3 --seed 7)

"$gen" "${args[@]}" --out "$work/one" --jobs 2 > /dev/null
"$verify" "$work/one"

# three shards as independent processes through GNU parallel, then the merge step
parallel --halt now,fail=1 "$gen" "${args[@]}" --out "$work/three" --shard {}/3 ::: 0 1 2 > /dev/null
"$gen" "${args[@]}" --out "$work/three" --index-only > /dev/null
for f in $(cd "$work/one" && find . -type f | sort); do
  cmp "$work/one/$f" "$work/three/$f" || { echo "FAIL: $f differs between 1 and 3 shards"; exit 1; }
done
[[ $(cd "$work/one" && find . -type f | wc -l) == $(cd "$work/three" && find . -type f | wc -l) ]] || { echo "FAIL: file counts differ"; exit 1; }

# killed after its first episode, then resumed: the same files, no partial file left
"$gen" "${args[@]}" --out "$work/killed" > /dev/null 2>&1 &
pid=$!
for _ in $(seq 600); do
  [[ -e $work/killed/episodes/demo_0.hdf5 ]] && break
  sleep 0.1
done
kill -TERM $pid 2> /dev/null || true
wait $pid 2> /dev/null || true
[[ ! -e $work/killed/dataset.hdf5 ]] || { echo "FAIL: the killed run wrote its index (was it killed in time?)"; exit 1; }
"$gen" "${args[@]}" --out "$work/killed" --resume > /dev/null
! ls "$work"/killed/episodes/*.partial > /dev/null 2>&1 || { echo "FAIL: partial files left after --resume"; exit 1; }
for f in $(cd "$work/one" && find . -type f | sort); do
  cmp "$work/one/$f" "$work/killed/$f" || { echo "FAIL: $f differs after kill + resume"; exit 1; }
done

# a truncated episode file is named by verify_dataset
cp -r "$work/one" "$work/cut"
truncate -s 5000 "$work/cut/episodes/demo_4.hdf5"
if out=$("$verify" "$work/cut" 2>&1); then echo "FAIL: verify_dataset accepted a truncated file"; exit 1; fi
grep -q "demo_4.hdf5" <<< "$out" || { echo "FAIL: verify_dataset did not name the file: $out"; exit 1; }

# physics first, images later: the same dataset generated with images equals render_dataset's
# images of the states-only one, bit for bit
"$gen" "${args[@]}" --out "$work/images" --images every:50 --image-size 48 40 > /dev/null
"$render" "$work/one" --out "$work/rendered" --every 50 --image-size 48 40 > /dev/null 2>&1
"$python" - "$work/images" "$work/rendered" <<'PY'
import sys, h5py, numpy as np
for k in range(6):
    with h5py.File(f"{sys.argv[1]}/episodes/demo_{k}.hdf5", "r") as a, h5py.File(f"{sys.argv[2]}/demo_{k}.hdf5", "r") as b:
        x, y = a[f"data/demo_{k}/images/agentview_image"][()], b[f"data/demo_{k}/images/agentview_image"][()]
        assert x.shape[1:] == (40, 48, 3) and x.shape[0] >= 10, x.shape
        assert np.array_equal(x, y), f"demo_{k}: rendered images differ"
        assert np.array_equal(a[f"data/demo_{k}/images/agentview_image_steps"][()], np.arange(0, 50 * len(x), 50))
PY

# the same frames through Blender (Workbench), where Debian's blender is installed: same steps and
# sizes as the OpenGL images, a picture in each frame (not one flat colour), and the arm moves
if command -v "${MANISOFT_BLENDER:-blender}" > /dev/null; then
  "$render" "$work/one" --out "$work/blender" --every 250 --image-size 48 40 --episodes 1 --renderer blender > /dev/null 2>&1
  [[ ! -e $work/blender/blender.partial ]] || { echo "FAIL: render_dataset left its Blender scratch folder"; exit 1; }
  "$python" - "$work/rendered" "$work/blender" <<'PY'
import sys, h5py, numpy as np
with h5py.File(f"{sys.argv[1]}/demo_1.hdf5", "r") as a, h5py.File(f"{sys.argv[2]}/demo_1.hdf5", "r") as b:
    g, x = a["data/demo_1/images"], b["data/demo_1/images"]
    steps = x["agentview_image_steps"][()]
    assert np.array_equal(steps, g["agentview_image_steps"][()][::5]), steps
    img = x["agentview_image"][()]
    assert img.shape == (len(steps), 40, 48, 3), img.shape
    assert all(f.std() > 10 for f in img), [f.std() for f in img]
    assert np.abs(img[0].astype(int) - img[-1].astype(int)).sum() > 0, "first and last Blender frames are identical"
PY
fi

# robomimic-style reading with h5py alone
summary=$("$python" "$reader" "$work/one")  # not piped into grep -q: an early exit would break the reader's pipe
grep -q "demos 6 " <<< "$summary" || { echo "FAIL: read_dataset.py: $summary"; exit 1; }

# the other two tasks, clean and randomized: one episode of each pair, verified and read back
"$gen" --tasks COLL,STK --clean 2 --randomized 2 --seed 7 --out "$work/coll_stk" --jobs 2 > /dev/null
"$verify" "$work/coll_stk"
summary=$("$python" "$reader" "$work/coll_stk")
for pair in COLL/clean COLL/randomized STK/clean STK/randomized; do
  grep -q "^  $pair: 1$" <<< "$summary" || { echo "FAIL: no $pair episode in the COLL + STK dataset: $summary"; exit 1; }
done

# the paper's figure 4 plots and table, and Diffusion Policy's zarr layout
"$python" "$examples/dataset_stats.py" "$work/one" --out "$work/stats" > /dev/null
for f in lengths categories heatmap instructions; do [[ -s $work/stats/$f.png ]] || { echo "FAIL: no $f.png"; exit 1; }; done
grep -q "| all | all | 6 |" "$work/stats/stats.md" || { echo "FAIL: stats.md lacks the 6-episode total"; exit 1; }
"$python" "$examples/export_zarr.py" "$work/one" "$work/one.zarr" --split all > /dev/null
"$python" - "$work/one" "$work/one.zarr" <<'PY'
import sys, h5py, numpy as np, zarr
with h5py.File(sys.argv[1] + "/dataset.hdf5", "r") as f:
    demos = [f["data"][f"demo_{k}"] for k in range(6)]
    actions = np.concatenate([d["actions"][()] for d in demos])
    ends = np.cumsum([d["actions"].shape[0] for d in demos])
z = zarr.open_group(sys.argv[2], mode="r")
assert np.array_equal(z["meta/episode_ends"][:], ends), "episode_ends"
assert np.array_equal(z["data/action"][:], actions), "actions"
assert z["data/rod_centerline"].shape == (ends[-1], 63), z["data/rod_centerline"].shape
assert z["data/rod_directors"].shape == (ends[-1], 180), z["data/rod_directors"].shape
targets = np.concatenate([d["obs/ee_target"][()] for d in demos])
assert np.array_equal(z["data/ee_target"][:], targets), "ee_target"
assert np.array_equal(targets[:, 6], actions[:, -1]), "the ee target's S is the action's"
assert z["data/ee_waypoint"].shape == (ends[-1], 1), z["data/ee_waypoint"].shape
PY
echo "generate_dataset: 1 shard == 3 shards == killed + resumed; verify, h5py read (all four tasks), stats and zarr export OK"
