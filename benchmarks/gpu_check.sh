#!/usr/bin/env bash
# Issue 46's device check, in one run of under 10 minutes (the device tool's limit per command) on a
# machine with an NVIDIA GPU and numba-cuda (no package registry needed).  Writes everything under the
# folder given (default gpu-check-<date>): the tests marked gpu, then bench_gpu.py's timings and agreement.
#
#     bash benchmarks/gpu_check.sh [OUT]
set -u
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-gpu-check-$(date -u +%Y%m%dT%H%M%SZ)}"
mkdir -p "$out"
cd "$here"
export PYTHONPATH="$here/src:$here${PYTHONPATH:+:$PYTHONPATH}"
python="${PYTHON:-python}"
{ nvidia-smi || true; "$python" -c "import numba, numba.cuda as c; print('numba', numba.__version__, c.__file__); c.detect()"; } \
    >"$out/device.txt" 2>&1
# the kernel against the CPU lanes on the device (three short sweeps; the kernels compile here)
timeout 200 "$python" -m pytest -q -p no:cacheprovider --gpu tests/gpu/test_device.py >"$out/test_device.txt" 2>&1
echo "test_device rc=$?" >>"$out/status.txt"
# the equal-work map of 10^6 points and a 1000 x 1000 basin: GPU against the CPU lanes
timeout 360 "$python" benchmarks/bench_gpu.py --repeats 3 --json "$out/bench_gpu.json" --markdown \
    >"$out/bench_gpu.txt" 2>&1
echo "bench_gpu rc=$?" >>"$out/status.txt"
cat "$out/status.txt"
