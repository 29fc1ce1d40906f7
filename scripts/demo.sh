#!/usr/bin/env bash
# Installs what is missing, builds the examples in Release and runs the main demo.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/install_deps.sh"
cmake -S "$root" -B "$root/build/release" -DCMAKE_BUILD_TYPE=Release -DMANISOFT_BUILD_TESTS=OFF -DMANISOFT_BUILD_BENCHMARKS=OFF
cmake --build "$root/build/release" --target rod_demo -j2
"$root/build/release/examples/rod_demo"
