// Seeds the targets from the host's depth buffer, before the visibility pass draws the
// instances over it. `resolve_main` (compute) writes, per target pixel, the host's farthest
// depth sample in the pass's reverse depth, moved back by host_margin, into `host_out` (its
// bits; 0xffffffff where the host has no geometry) for the compute passes; the draw
// `vs_main`/`fs_main` then writes the seed depth and the id HOST_ID (BACKGROUND_ID where the
// host has no geometry) into the depth and id targets. Reading a multisampled texture in a
// compute pass rather than a fragment shader keeps lavapipe from growing its memory with
// every frame. Assembled after common.wgsl.
//
// Flags: MULTISAMPLED (the host's depth texture has several samples per pixel; the farthest
// counts, so a line is hidden only where the host covers the whole pixel). A multisampled
// host also gets its seed depth, written into `seed_out`: the farthest sample moved back
// further by the spread of the pixel's samples. The seed decides whether a pixel shows the
// host, comparing the host with an instance at the pixel's centre, where none of the samples
// lies: so a host's own copy of an instance, seen at samples off the centre, does not hide
// the instance, and a pixel that the host's other geometry covers only in part shows the
// instance (the composite then tests each sample: composite.wgsl). A single-sampled host's
// seed is its depth. The ground truth's twin is `HostOccluders::depth_map`
// (src/truth/rays.rs).

@group(0) @binding(0) var<uniform> frame: Frame;
// Bound as unfilterable float (its depth in x), which every backend can load from; GLSL
// has no texel fetch from depth textures.
#if MULTISAMPLED
@group(0) @binding(30) var host_source: texture_multisampled_2d<f32>;
#else
@group(0) @binding(30) var host_source: texture_2d<f32>;
#endif

@group(0) @binding(31) var<uniform> host: HostParams;

@group(0) @binding(32) var host_out: texture_storage_2d<r32uint, write>;
#if MULTISAMPLED
@group(0) @binding(33) var seed_out: texture_storage_2d<r32uint, write>;
#endif

@compute @workgroup_size(8, 8)
fn resolve_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !all(vec2<f32>(gid.xy) < frame.target_size) {
        return;
    }
    let v = host_value(gid.xy);
    textureStore(host_out, gid.xy, vec4<u32>(v.x, 0u, 0u, 0u));
#if MULTISAMPLED
    textureStore(seed_out, gid.xy, vec4<u32>(v.y, 0u, 0u, 0u));
#endif
}

// The host's depth of convention `d` at full-image pixel centre `pixel`, in the pass's
// reverse depth.
fn host_reverse(d: f32, pixel: vec2<f32>, size: vec2<f32>) -> f32 {
    let ndc = vec2<f32>(pixel.x / size.x * 2.0 - 1.0, 1.0 - pixel.y / size.y * 2.0);
    let q = vec4<f32>(ndc, d, 1.0);
    // Selects, not branches on the uniform mode (see common.wgsl).
    let same = select(1.0 - d, d, host.mode == 1u);
    return select(same, dot(host.a, q) / dot(host.b, q), host.mode == 2u);
}

// The bits of the host's reverse depth at target pixel xy and of its seed depth, or
// 0xffffffff for both.
fn host_value(xy: vec2<u32>) -> vec2<u32> {
    // The image pixel this target pixel is; the host's depth covers the image only.
    let image = vec2<i32>(xy) + vec2<i32>(frame.target_origin);
    let size = vec2<i32>(textureDimensions(host_source));
    if any(image < vec2<i32>(0)) || any(image >= size) {
        return vec2<u32>(0xffffffffu);
    }
    let far = select(1.0, 0.0, host.reversed == 1u);
    // The farthest sample (towards `far`), and the nearest.
    var d = 1.0 - far;
    var near = far;
#if MULTISAMPLED
    // The texture's own count, not a uniform: a loop bound by uniform values alone is
    // re-specialised by lavapipe at every dispatch (see common.wgsl).
    for (var s = 0u; s < textureNumSamples(host_source); s++) {
        let x = textureLoad(host_source, image, i32(s)).x;
        d = select(max(d, x), min(d, x), host.reversed == 1u);
        near = select(min(near, x), max(near, x), host.reversed == 1u);
    }
#else
    d = textureLoad(host_source, image, 0).x;
    near = d;
#endif
    if d == far {
        return vec2<u32>(0xffffffffu);
    }
    let pixel = vec2<f32>(image) + 0.5;
    let reverse = host_reverse(d, pixel, vec2<f32>(size));
    // Moved back by the margin, so the pass's own surfaces win ties with the host's copy.
    let line = clamp(reverse - host_margin(reverse, host.quantum), 0.0, 1.0);
    let spread = max(host_reverse(near, pixel, vec2<f32>(size)) - reverse, 0.0);
    return vec2<u32>(bitcast<u32>(line), bitcast<u32>(max(line - spread, 0.0)));
}

// The seed depth: the host target itself for a single-sampled host, the seed target for a
// multisampled one.
@group(0) @binding(17) var host_depth: texture_2d<u32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // One triangle over the whole target.
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

struct Seed {
    @builtin(frag_depth) depth: f32,
    @location(0) id: vec2<u32>,
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> Seed {
    let v = textureLoad(host_depth, vec2<u32>(position.xy), 0).x;
    if v == 0xffffffffu {
        return Seed(0.0, vec2<u32>(BACKGROUND_ID, 0u));
    }
    return Seed(bitcast<f32>(v), vec2<u32>(HOST_ID, 0u));
}
