#!/usr/bin/env bash
# Stages a build for the GPU machine (docs/performance.md 1.3): builds here for compute capability 9.0, then
# copies into .gpu-stage/ (git-ignored) the gem binary, the test binaries, the project's shared
# libraries and every non-system, non-CUDA shared library they need, the scenarios, and a driver
# script. On the GPU machine:  bash .gpu-stage/run.sh [OUT]   (OUT defaults to $OUT, else ./gpu-out)
# It runs `gem info`, the CUDA tests (a plugin's event on the device among them), compute-sanitizer
# on them, the timings and a cuda run of scenarios/thesis/random_50.toml, with every log under OUT.
# GEM_SKIP_SANITIZER=1 skips the sanitizer; GEM_BENCH_TABLE=NAME runs that bench table only and
# stops there; GEM_PROFILE=1 adds an nsys kernel summary of the 824-floe timing (where nsys exists).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${GEM_STAGE_BUILD:-$root/build-cuda}"
stage="$root/.gpu-stage"

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CUDA_ARCHITECTURES=90 \
  -DCMAKE_CUDA_COMPILER="${CUDACXX:-/usr/local/cuda/bin/nvcc}" -DGEM_BUILD_CGAL_TESTS=OFF >/dev/null
cmake --build "$build" --target gem gem_tests gem_cuda_tests  # gem_cuda_tests builds the CUDA test plugin too

rm -rf "$stage"
mkdir -p "$stage/lib"
cp "$build/gem" "$build/tests/gem_cuda_tests" "$build/tests/gem_tests" "$stage/"
cp "$build/libgem_core.so" "$build/libgem_cuda.so" "$stage/lib/"
# Every library ldd resolves, except glibc's own, the C++ runtime the target has, and CUDA's.
for bin in "$stage/gem" "$stage/gem_cuda_tests" "$stage/gem_tests" "$stage/lib/libgem_cuda.so"; do
  ldd "$bin" | awk '/=> \//{print $3}' | while read -r lib; do
    case "$(basename "$lib")" in
      libc.so*|libm.so*|libdl.so*|librt.so*|libpthread.so*|ld-linux*|libgcc_s.so*|libstdc++.so*|libcuda.so*|libcudart.so*|libz.so*|libudev.so*) ;;
      libgem_*) ;;
      *) cp -nL "$lib" "$stage/lib/" ;;
    esac
  done
done
# The CUDA runtime of the build (13.0, as on the GPU machine) travels too: a match is then certain.
cp -L "$(ldd "$stage/lib/libgem_cuda.so" | awk '/libcudart/{print $3}')" "$stage/lib/"
cp -r "$root/scenarios" "$stage/scenarios"
mkdir -p "$stage/tests" && cp -r "$root/tests/golden" "$stage/tests/golden"  # the CUDA golden hashes
# The shear_current, rafting_onset and sweep_and_prune plugins with their CUDA parts
# (tests/cuda/plugin_cuda_test.cpp and broadphase_cuda_test.cpp run them on the device).
mkdir -p "$stage/cuda_plugins"
cp "$build/tests/cuda_plugins/libshear_current.so" "$build/tests/cuda_plugins/librafting_onset.so" \
  "$build/tests/cuda_plugins/libsweep_and_prune.so" "$stage/cuda_plugins/"

cat > "$stage/run.sh" <<'RUN'
#!/usr/bin/env bash
# Driver on the GPU machine: every result goes under OUT.
stage="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="${1:-${OUT:-$PWD/gpu-out}}"
mkdir -p "$out"
export LD_LIBRARY_PATH="$stage/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
# The tests find the gem binary and the scenarios here, not at the build's paths.
export GEM_BINARY_DIR="$stage" GEM_SOURCE_DIR="$stage" GEM_TEST_CUDA_PLUGIN_DIR="$stage/cuda_plugins"
status=0
cd "$stage"
{ date -u; nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv; } 2>&1 | tee "$out/device.txt"
./gem info 2>&1 | tee "$out/gem-info.txt" | head -3
echo "== CUDA tests"
./gem_cuda_tests --gtest_color=no 2>&1 | tee "$out/cuda-tests.txt" | grep -E "^\[ +(OK|FAILED|SKIPPED|PASSED) |busy channel|CUDA device|Failure|Expected|Which|error" || true
[ "${PIPESTATUS[0]}" = 0 ] || status=1
if [ "${GEM_SKIP_SANITIZER:-0}" != 1 ]; then
  echo "== compute-sanitizer (memcheck) on the CUDA tests (fast ones), with the step graph and without"
  sanitizer="$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)"
  # GEM_CUDA_GRAPH=0: the same kernels launched one by one, a sync per step.
  # The device-wide driver (GEM_CUDA_DRIVER=device), with its step graph and without.
  for graph in 1 0; do
    GEM_CUDA_DRIVER=device GEM_CUDA_GRAPH=$graph "$sanitizer" --tool memcheck --error-exitcode 9 --show-backtrace yes ./gem_cuda_tests --gtest_color=no \
      --gtest_filter='CudaBackend.TwoFloes*:CudaBackend.BusyChannelMatchesTheCpuAfter50Steps:CudaBackend.CandidateOverflow*:CudaPlugin.Rafting*:CudaBroadphase.Candidate*:*CasesTogether*' > "$out/sanitizer-graph$graph.txt" 2>&1
    rc=$?
    tail -3 "$out/sanitizer-graph$graph.txt"; echo "compute-sanitizer (GEM_CUDA_GRAPH=$graph) exit $rc"; [ $rc = 0 ] || status=1
  done
  # The resident driver: memcheck, and racecheck for its shared memory (one world, and three together).
  for tool in memcheck racecheck; do
    GEM_CUDA_DRIVER=resident "$sanitizer" --tool $tool --error-exitcode 9 --show-backtrace yes ./gem_cuda_tests --gtest_color=no \
      --gtest_filter='CudaBackend.TwoFloes*:CudaBackend.BusyChannelMatchesTheCpuAfter50Steps:CudaBackend.CandidateOverflow*:*CasesTogether*resident_variable*' > "$out/sanitizer-resident-$tool.txt" 2>&1
    rc=$?
    tail -3 "$out/sanitizer-resident-$tool.txt"; echo "compute-sanitizer $tool (resident driver) exit $rc"; [ $rc = 0 ] || status=1
  done
fi
if [ -n "${GEM_BENCH_TABLE:-}" ]; then
  echo "== gem bench --table $GEM_BENCH_TABLE"
  mkdir -p "$out/bench"
  ./gem bench --table "$GEM_BENCH_TABLE" --csv "$out/bench" 2>&1 | tee "$out/bench.txt"
  [ "${PIPESTATUS[0]}" = 0 ] || status=1
  exit $status
fi
echo "== timings (gem bench --table all: the thesis's Chapter 5 tables, one CSV per table under bench/)"
mkdir -p "$out/bench"
./gem bench --table all --csv "$out/bench" 2>&1 | tee "$out/bench.txt"
[ "${PIPESTATUS[0]}" = 0 ] || status=1
if command -v nsys >/dev/null && [ "${GEM_PROFILE:-0}" = 1 ]; then
  echo "== nsys: kernel times of the 824-floe timing"
  nsys profile -o "$out/profile" --force-overwrite true --stats=false ./gem_cuda_tests \
    --gtest_filter='CudaBackend.BusyChannelSummary*' > "$out/nsys.txt" 2>&1
  nsys stats --report cuda_gpu_kern_sum,cuda_api_sum --format csv "$out/profile.nsys-rep" > "$out/nsys-stats.txt" 2>&1
  head -30 "$out/nsys-stats.txt" | cut -c1-200
fi
if [ "${GEM_LOAD_STUDY:-0}" = 1 ]; then
  # The 70-run load study on the device: one CUDA run per sweep job, each on its own stream.
  echo "== load study, backend cuda, --jobs ${GEM_LOAD_JOBS:-8}"
  sed 's/^name = "load_study"/name = "load_study"\nset = { "simulation.backend" = "cuda" }/' scenarios/thesis/load_study.toml > scenarios/thesis/load_study_cuda.toml
  start=$(date +%s.%N)
  ./gem sweep scenarios/thesis/load_study_cuda.toml --out "$out/load_cuda" --jobs "${GEM_LOAD_JOBS:-8}" --quiet > "$out/load-cuda.txt" 2>&1
  rc=$?
  awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN{printf "load study on the device: %.1f s wall\n", b - a}' | tee -a "$out/load-cuda.txt"
  tail -3 "$out/load-cuda.txt"; [ $rc = 0 ] || status=1
  start=$(date +%s.%N)
  ./gem sweep scenarios/thesis/load_study.toml --out "$out/load_cpu" --jobs "$(nproc)" --quiet > "$out/load-cpu.txt" 2>&1
  awk -v a="$start" -v b="$(date +%s.%N)" -v j="$(nproc)" 'BEGIN{printf "load study on the CPU (%d jobs): %.1f s wall\n", j, b - a}' | tee -a "$out/load-cpu.txt"
fi
echo "== gem run --backend cuda scenarios/thesis/random_50.toml"
./gem run scenarios/thesis/random_50.toml --backend cuda --out "$out/random_50" --set output.frame_every=0 > "$out/run-random_50.txt" 2>&1
rc=$?; tail -4 "$out/run-random_50.txt"; [ $rc = 0 ] || status=1
grep -E '"backend"|"device"|"impacts"|"steps"|"wall_time_s"' "$out/random_50/summary.json" || true
exit $status
RUN
chmod +x "$stage/run.sh"
cp "$root/scripts/gpu-record.sh" "$stage/record.sh"  # the README's record run (bench tables, ncu, host timing)
cp "$root/scripts/gpu-load-study.sh" "$stage/load_study.sh"  # the README's load-study timing (batched and not)
du -sh "$stage"
