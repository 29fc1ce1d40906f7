#!/usr/bin/env bash
# Installs what is missing, builds the examples in Release and runs the benchmark's main job: one
# expert episode of a ManiSoft task (run_task: the scene sampled, its instruction, each waypoint
# as the expert reaches it, success and steps, one JSON line), then its pictures through the
# in-process OpenGL renderer (render_scene: the first and the last frame, an image strip of the
# episode). Choose another episode with TASK, SETTING, INDEX, SEED. Output in build/demo/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
task=${TASK:-ALN} setting=${SETTING:-clean} index=${INDEX:-1} seed=${SEED:-0}
bash "$root/scripts/install_deps.sh"
cmake -S "$root" -B "$root/build/release" -DCMAKE_BUILD_TYPE=Release -DMANISOFT_BUILD_TESTS=OFF -DMANISOFT_BUILD_BENCHMARKS=OFF
cmake --build "$root/build/release" --target run_task render_scene -j2
out="$root/build/demo"
rm -rf "$out"
mkdir -p "$out"
bin="$root/build/release/examples"
"$bin/run_task" --task "$task" --setting "$setting" --index "$index" --seed "$seed" --save-scene "$out/scene.json" --trace "$out/trace.csv"
"$bin/render_scene" --scene "$out/scene.json" --trace "$out/trace.csv" --frame 0 --out "$out/first"
"$bin/render_scene" --scene "$out/scene.json" --trace "$out/trace.csv" --frame -1 --out "$out/last"
"$bin/render_scene" --scene "$out/scene.json" --trace "$out/trace.csv" --episode --every 50 --out "$out/episode"
echo "pictures: $out/first/rgb.png, $out/last/rgb.png (depth.png, mask.png, camera.json beside each), $out/episode/strip.png"
