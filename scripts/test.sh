#!/usr/bin/env bash
# Installs what is missing, then builds and runs every test twice:
#   1. g++, Release at -O1 (a heavy translation unit compiles in about 2/3 of the time it takes at
#      -O2, and faster than at -O0; BENCHMARKS.md numbers come from a default -O3 build), -Wall
#      -Wextra -Wpedantic -Werror: the tests and the programs they run.
#   2. clang++ with AddressSanitizer + UndefinedBehaviorSanitizer (-O1, line tables only: stack
#      traces name file and line, and the build is faster than with full -g): the tests and the
#      programs they run; what no test runs (the other examples, the benchmarks, every header on
#      its own) is only checked for warnings (MANISOFT_CHECK_ONLY: -fsyntax-only, not built; the
#      programs in one translation unit, manisoft_add_unrun_check in CMakeLists.txt), and the
#      installed package is built against by a consumer project. clang, not g++, does these checks:
#      it parses this code in a quarter of g++'s time.
#      The libFuzzer targets of the file readers (tests/fuzz, MANISOFT_FUZZ) run 8 s each on their
#      corpora (label fuzz).
# Tests that instantiate the same templates share an executable built as one unity translation
# unit (tests/CMakeLists.txt): every test of the world, the executor, the assets, the scenes, the
# tasks and the recorded expert is one unit, so the world is compiled once, not once per group.
# For the same reason the programs the tests run are one executable (MANISOFT_ONE_PROGRAM_BINARY:
# build/*/examples/manisoft_programs, each program's name a link to it).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
jobs=${JOBS:-2}
bash "$root/scripts/install_deps.sh"

echo "== g++ Release build"
cmake -S "$root" -B "$root/build/gcc-release" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" \
  -DCMAKE_CXX_COMPILER=g++ -DMANISOFT_HEADER_CHECK=OFF -DMANISOFT_CHECK_ONLY=ON -DMANISOFT_UNRUN_CHECK=OFF -DMANISOFT_PACKAGE_TEST=OFF \
  -DMANISOFT_ONE_PROGRAM_BINARY=ON
cmake --build "$root/build/gcc-release" -j"$jobs"
(cd "$root/build/gcc-release" && ctest --output-on-failure -j"$jobs")

echo "== clang++ ASan+UBSan build"
cmake -S "$root" -B "$root/build/clang-asan" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DMANISOFT_SANITIZE=ON -DMANISOFT_FUZZ=ON -DMANISOFT_BUILD_EXAMPLES=ON -DMANISOFT_BUILD_BENCHMARKS=ON -DMANISOFT_HEADER_CHECK=ON -DMANISOFT_CHECK_ONLY=ON -DMANISOFT_ONE_PROGRAM_BINARY=ON
cmake --build "$root/build/clang-asan" -j"$jobs"
# The longest tests under the sanitizers (30-160 s each there, 25 times their g++ time: the
# nested bowls' contact, the scene-validity samples, the placement band, the instruction matchers
# over many sampled scenes, the PyElastica reference trajectories, three expert episodes replayed
# through the end-effector track, the shipped MLP executor's 200 reach episodes) run in the g++
# build only; the same code runs under the sanitizers in shorter tests.
asan_long="four nested bowls rest in each other|(COLL|ARR|STK|OVR): .* scenes valid|clean placements cover the reachable band"
asan_long+="|STK: with items within|stored instructions name each goal object uniquely|random tables of catalogue assets"
asan_long+="|canonical and seen instructions say no unseen|every PyElastica reference trajectory is reproduced"
asan_long+="|the end-effector track fed the expert's recorded targets|the shipped MLP executor reaches"
(cd "$root/build/clang-asan" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j"$jobs" -E "$asan_long")
