#!/usr/bin/env bash
# Writes every speed table and plot of the docs from one benchmark run on this machine, and
# the baseline of record that `wirepass bench --against` and CI compare with:
#
#   docs/speed.md                  the tables (summary, ratios, every pass), with the
#                                  adapter, the commit and the date
#   docs/bench-triangles.png       GPU time against triangles
#   bench/baseline.json            the run's ratios, which `wirepass bench --against`
#                                  (and CI, in a smaller run) compares with
#
#   bench/tables.sh               FRAMES (default 9) narrows the run; WGPU_BACKEND picks
#                                  the adapter (default vulkan: lavapipe where no GPU is)
#
# It measures the commit checked out, so the tree must be clean; commit its output on its
# own. On a software adapter (2 cores) it takes about 10 minutes.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -n "$(git status --porcelain --untracked-files=no)" ]; then
    echo "bench/tables.sh measures a commit: commit or stash the changes first" >&2
    exit 1
fi
commit="$(git rev-parse --short HEAD)"
date="$(date -u +%F)"
frames="${FRAMES:-9}"
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
cargo build --release --locked -p wirepass-cli
bin="${CARGO_TARGET_DIR:-target}/release/wirepass"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

# The scenes of the docs: UV spheres from few to many triangles per pixel, a scanned mesh,
# depth complexity without triangles (layers:16), and two instances whose bounds meet, side
# by side and passing through each other (bench/scenes); every method, outlines on and off.
scenes="sphere:20000 sphere:200000 sphere:2000000 tests/data/meshes/stanford-bunny.obj layers:16
    bench/scenes/side-by-side.json bench/scenes/through-each-other.json"
# shellcheck disable=SC2086 # the scenes are separate arguments
"$bin" bench $scenes --size 1280x720 --frames "$frames" --warmup 3 --outlines on,off \
    --out "$out" --record bench/baseline.json --commit "$commit" --date "$date" \
    >"$out/report.md"
cp "$out/time_vs_triangles.png" docs/bench-triangles.png

{
    cat <<EOF
# Speed

Written by \`bench/tables.sh\` from one run of \`wirepass bench\` at commit \`$commit\`, on
$date, $frames timed frames after 3 of warm-up, 1280×720, polygon edges, every method
interleaved frame by frame (so ratios within the run compare alike on a busy machine);
medians of GPU timestamp spans in ms. The same run is the baseline of record,
\`bench/baseline.json\`: \`wirepass bench … --against bench/baseline.json\` prints any
run's ratios against it and flags those that worsened by more than 15 %.

- \`floor\`: the visibility pass and a compute pass that reads each pixel's id and writes a
  flat colour, the least a deferred pass can cost.
- \`deferred\`: the visibility, trace and edge passes into a storage texture;
  \`render-pass\`: the same into the frame's result, composited into a host's render pass
  (\`OutputTarget::RenderPass\`, \`Composite::Shaded\`), the path hosts take.
- \`forward\`, \`two-pass\`: the forward baselines on wgpu; \`gs\`: the published
  geometry-shader method itself on the machine's OpenGL, timed from issuing the frame to
  \`glFinish\` on a software renderer (its GL timestamps miss the vertex and geometry
  stages there), by its timestamps on a GPU.
- \`bench/scenes/side-by-side.json\`: Spot, and Suzanne beside it, their bounds meeting but
  not their surfaces; \`through-each-other.json\`: Suzanne passing through Spot, whose
  lines near the crossings the trace pass draws where visible, in one-pixel pieces tested
  over 9×9 windows.
- Ratios: \`deferred ÷ gs\` and \`÷ forward\`, the whole frame; \`edge ÷ floor\`, the edge
  pass's dispatches against the floor's one compute pass; \`edge ÷ edge at sphere:20000\`,
  the edge pass against its time on the sphere of fewest triangles (flat is 1).

Adapter:
EOF
    # The report: the adapter and gs's renderer, the summary, the ratios, every pass.
    sed -e 's/^| scene | triangles | size | floor/\n&/' "$out/report.md"
    cat <<EOF

![GPU time against triangle count: every method, the deferred one with outlines on and off, the spheres joined, the bunny and layers:16 as points](bench-triangles.png)

## On a GPU

The figures from an NVIDIA H200 are in [speed-h200.md](speed-h200.md), measured at an
earlier commit, as it says: \`bench/gpu.sh\` writes them where a GPU is lent.
EOF
} >docs/speed.md
echo "wrote docs/speed.md, docs/bench-triangles.png and bench/baseline.json ($commit, $date)" >&2
