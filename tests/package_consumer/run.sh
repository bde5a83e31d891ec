#!/usr/bin/env bash
# Install impinge from BUILD into a fresh prefix, then configure, build and run an outside project
# that finds it with find_package(impinge).   usage: run.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src="$1"; build="$2"
work="$build/package-consumer-test"
rm -rf "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
cmake -S "$src/tests/package_consumer" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/build" >/dev/null
"$work/build/consumer"
# The installed tree holds the headers, the library and the package files, nothing else.
test -f "$work/prefix/include/impinge/detection/joint.hpp"
test -f "$work/prefix/include/impinge/session/session.hpp"
test -f "$work/prefix/lib/cmake/impinge/impingeConfig.cmake"
echo "package consumer ok"
