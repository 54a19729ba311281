#!/usr/bin/env bash
# The full benchmark comparison on a GPU, unattended: builds the release binary, then times
# floor, deferred (outlines on and off), forward, two-pass and gs (the published
# geometry-shader method, on the machine's OpenGL through EGL) on UV spheres of 20 k to 20 M
# triangles, the Stanford bunny and `layers:16`, at 1920x1080 and 3840x2160, all methods
# interleaved frame by frame in one run. Prints the summary table (one row per scene and size)
# and keeps bench.md, bench.json, bench.csv and the plots in OUT.
#
#   bench/gpu.sh [OUT]        OUT defaults to bench-gpu/
#
# Needs: Rust (rustup.rs), a C++ compiler (FLIP's), and the GPU's Vulkan and EGL drivers (on
# NVIDIA: the driver's libnvidia-gl / its Vulkan ICD and libEGL_nvidia through libglvnd).
# WGPU_ADAPTER_NAME picks the wgpu adapter by name, WIREPASS_EGL_LIBRARY the libEGL. SCENES,
# SIZES and FRAMES narrow the run (CI runs a small one on lavapipe to keep this script
# working). Written for a 16-core machine: within 8 minutes from a clone without target/.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-bench-gpu}"
scenes="${SCENES:-sphere:20000 sphere:200000 sphere:2000000 sphere:20000000 tests/data/meshes/stanford-bunny.obj layers:16}"
sizes="${SIZES:-1920x1080,3840x2160}"
frames="${FRAMES:-20}"
start=$SECONDS

for tool in cargo c++; do
    if ! command -v "$tool" >/dev/null; then
        echo "bench/gpu.sh needs $tool" >&2
        exit 1
    fi
done
if command -v nvidia-smi >/dev/null; then
    nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
fi

cargo build --release --locked -p wirepass-cli
echo "built in $((SECONDS - start)) s" >&2

# Vulkan for the wgpu methods (the GL backend is for machines without it).
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
mkdir -p "$out"
# shellcheck disable=SC2086 # the scenes are separate arguments
"${CARGO_TARGET_DIR:-target}/release/wirepass" bench $scenes --size "$sizes" --frames "$frames" \
    --outlines on,off --out "$out" >"$out/bench.log"

# The adapter, the GL renderer gs ran on, and the summary: bench.md up to its second table.
awk '/^\| scene /{tables++} tables < 2 {print}' "$out/bench.md"
echo "bench/gpu.sh: $((SECONDS - start)) s; the full report is $out/bench.md" >&2
