#!/usr/bin/env bash
# Installs the C++ package into a scratch prefix, builds examples/ against the INSTALLED
# package (find_package(lugrip)), runs the 500 Hz loop example and checks with nm that the
# binary linked to lugrip::core alone holds no simulator and no thread code:
#   * no symbol of the plants or the closed loop (GraspPlant, PatchContact, NormalRng, ClosedLoop)
#   * no symbol of the identification (IdentificationProblem) and no pthread_* / std::thread.
# Usage: tests/install/check_core_install.sh [BUILD_DIR]   (default build/install-check)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-build/install-check}
jobs=${JOBS:-2}
rm -rf "$out/prefix" "$out/examples"
cmake -S . -B "$out/lib" -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$PWD/$out/prefix" > /dev/null
cmake --build "$out/lib" -j "$jobs" > /dev/null
cmake --install "$out/lib" > /dev/null
for t in core sim identification; do
  grep -q "lugrip::$t" "$out"/prefix/lib*/cmake/lugrip/lugripTargets.cmake || { echo "FAIL: lugrip::$t not exported"; exit 1; }
done
cmake -S examples -B "$out/examples" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PWD/$out/prefix" > /dev/null
cmake --build "$out/examples" -j "$jobs" > /dev/null
bin="$out/examples/example_04_robot_loop"
"$bin" > "$out/robot_loop.txt"
tail -2 "$out/robot_loop.txt"
syms=$(nm -C "$bin")
bad=$(grep -E "GraspPlant|PatchContact|NormalRng|ClosedLoop|IdentificationProblem|pthread_|std::thread" <<< "$syms" || true)
if [ -n "$bad" ]; then
  echo "FAIL: example_04_robot_loop links simulator/identification/thread symbols:"
  echo "$bad" | head -20
  exit 1
fi
grep -q "lugrip::SlipControl::step" <<< "$syms" || { echo "FAIL: SlipControl::step not in the binary"; exit 1; }
# control: the same patterns do find the simulator in the installed lugrip::sim archive
sim_syms=$(nm -C "$out"/prefix/lib*/liblugrip_sim.a 2>/dev/null)
grep -q "GraspPlant::step" <<< "$sim_syms" || { echo "FAIL: control pattern"; exit 1; }
echo "OK: installed lugrip::core, lugrip::sim, lugrip::identification exported; example_04_robot_loop links the core only ($(grep -c 'lugrip::' <<< "$syms") lugrip symbols, none of the simulator, identification or threads)"
