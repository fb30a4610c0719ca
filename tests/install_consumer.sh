#!/usr/bin/env bash
# Installs the built rigcal into a temporary prefix, builds tests/consumer against it with
# find_package(rigcal), runs it on the sample rig, and runs the installed CLI.
set -euo pipefail
build=$1 source=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
cmake -S "$source/tests/consumer" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" \
      -DCMAKE_BUILD_TYPE=Release > "$work/configure.log" || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" > "$work/build.log" || { cat "$work/build.log"; exit 1; }
out=$("$work/build/consumer" "$work/prefix/share/rigcal/sample_rig.yaml")
echo "consumer: $out"
[[ "$out" == "sensors 6 t "* ]] || { echo "unexpected consumer output"; exit 1; }
"$work/prefix/bin/rigcal" rig validate "$work/prefix/share/rigcal/sample_rig.yaml"
echo "installed rigcal and find_package(rigcal) work"
