#!/usr/bin/env bash
# short_runs.sh SOURCE_DIR BUILD_DIR: builds the fuzz targets with clang-14, libFuzzer, ASan and
# UBSan in BUILD_DIR (libraries only, no tests or benchmarks), then runs each on its corpus and
# reproducers for its fixed number of inputs (fuzz/CMakeLists.txt; ctest label fuzz there).
set -euo pipefail
src=$1 build=$2
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
CC=clang-14 CXX=clang++-14 cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS="-O1 -gline-tables-only" \
  -DKINOGRAPH_FUZZ=ON -DKINOGRAPH_BUILD_TESTS=OFF -DKINOGRAPH_BUILD_BENCH=OFF "${launcher[@]}"
cmake --build "$build" -j "$(nproc)" --target kinograph_fuzzers
ctest --test-dir "$build" -L fuzz --output-on-failure --no-tests=error
