#!/usr/bin/env bash
# The `manisoft` package installed as a user installs it, then used from outside the source tree:
#   1. cmake --install BUILD --component python --prefix SCRATCH/prefix
#   2. pip install --no-build-isolation --no-index --no-deps --target SCRATCH/pip SOURCE
#      (setup.py, reusing BUILD through MANISOFT_CMAKE_BUILD_DIR: nothing is compiled again)
# Each: the package is imported from where it was installed (not from BUILD), an episode steps,
# and the scripts run as modules (python3 -m manisoft.evaluate --help).
# Usage: install_package.sh PYTHON BUILD SOURCE SCRATCH
set -euo pipefail
python=$1 build=$2 source=$3 scratch=$4
rm -rf "$scratch" && mkdir -p "$scratch"
cd "$scratch"  # not the source tree: nothing there is importable by accident

check() {  # check SITE: the package in SITE works
  PYTHONPATH=$1 "$python" - "$1" <<'PY'
import os, sys
import numpy as np
import manisoft
site = os.path.realpath(sys.argv[1])
assert os.path.realpath(manisoft.__file__).startswith(site + os.sep), (manisoft.__file__, site)
assert os.path.realpath(manisoft._manisoft.__file__).startswith(site + os.sep), manisoft._manisoft.__file__
env = manisoft.make_env("ALN", "clean", seed=0)
obs, info = env.reset(options={"index": 0})
obs, reward, terminated, truncated, info = env.step(np.zeros(env.action_space.shape))
assert info["steps"] == 1 and not terminated, info
vec = manisoft.make_vec_env("reach", 2)
vec.reset(seed=0)
assert vec.step(np.zeros(vec.action_space.shape))[0]["node_positions"].shape[0] == 2
print("manisoft from", os.path.dirname(manisoft.__file__), ": an ALN step and a reach batch step")
PY
  for script in evaluate read_dataset export_zarr dataset_stats bc_baseline reference_policy image_policy sac_executor; do
    PYTHONPATH=$1 "$python" -m manisoft.$script --help > /dev/null || { echo "python3 -m manisoft.$script --help failed"; exit 1; }
  done
  echo "python3 -m manisoft.{evaluate,read_dataset,export_zarr,dataset_stats,bc_baseline,reference_policy,image_policy,sac_executor} --help: OK"
}

cmake --install "$build" --component python --prefix "$scratch/prefix" > /dev/null
site=$(cd "$scratch/prefix" && ls -d lib/python3*/dist-packages)
check "$scratch/prefix/$site"

MANISOFT_CMAKE_BUILD_DIR=$build "$python" -m pip install --quiet --root-user-action=ignore --no-build-isolation --no-index --no-deps --target "$scratch/pip" "$source"
check "$scratch/pip"
