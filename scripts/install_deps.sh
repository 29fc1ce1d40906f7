#!/usr/bin/env bash
# Installs the Debian packages ManiSoft needs, only those that are missing (needs root or sudo).
set -euo pipefail
packages=(cmake make g++ clang libclang-rt-14-dev libeigen3-dev libfcl-dev libccd-dev catch2 libbenchmark-dev)
# render component: OpenGL through EGL (Mesa llvmpipe), libpng, CLI11; blender and ffmpeg for the Blender adapter and videos
packages+=(libegl-dev libgl-dev libegl1-mesa-dev libgl1-mesa-dri libegl-mesa0 libpng-dev libcli11-dev blender ffmpeg)
# import component: users' meshes through assimp, JSON sidecars through nlohmann-json
packages+=(libassimp-dev nlohmann-json3-dev)
# dataset component: HDF5 files; h5py and numpy for the Python reader (Debian's /usr/bin/python3)
packages+=(libhdf5-dev python3-h5py python3-numpy)
# sharded dataset generation on one machine (and its test); the dataset's plots and zarr export
packages+=(parallel python3-matplotlib python3-zarr)
# the Python module (pybind11, for Debian's /usr/bin/python3)
packages+=(pybind11-dev python3-dev)
# installing it as a Python package: pip install --no-build-isolation . (setup.py), offline
packages+=(python3-pip python3-setuptools python3-wheel python3-venv)
# the evaluation harness's policy-server client (openpi's websocket + msgpack protocol)
packages+=(python3-websockets python3-msgpack python3-msgpack-numpy)
# the learned reference policies (PyTorch on CPU; OpenBLAS so its matrix products use a tuned BLAS)
packages+=(python3-torch libopenblas0-pthread)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  sudo_cmd=()
  [[ $(id -u) -eq 0 ]] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
