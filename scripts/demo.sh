#!/usr/bin/env bash
# Installs what is missing, builds the examples in Release and runs the main demo: the tabletop
# world (world_demo: the soft arm grasps the cube, carries it and puts it down within the
# actuation limits) and its pictures (render_scene: the first frame and an image strip of the
# episode through the in-process OpenGL renderer). Output in build/demo/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/install_deps.sh"
cmake -S "$root" -B "$root/build/release" -DCMAKE_BUILD_TYPE=Release -DMANISOFT_BUILD_TESTS=OFF -DMANISOFT_BUILD_BENCHMARKS=OFF
cmake --build "$root/build/release" --target world_demo render_scene -j2
out="$root/build/demo"
mkdir -p "$out"
"$root/build/release/examples/world_demo" --out "$out/world_trace.csv"
"$root/build/release/examples/render_scene" --trace "$out/world_trace.csv" --frame 2900 --out "$out"
"$root/build/release/examples/render_scene" --trace "$out/world_trace.csv" --episode --every 700 --out "$out"
echo "pictures: $out/rgb.png (the cube held and carried; depth.png, mask.png, camera.json beside it), $out/strip.png (the episode), $out/frames/"
