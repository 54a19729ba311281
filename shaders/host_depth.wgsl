// Seeds the targets from the host's depth buffer, before the visibility pass draws the
// instances over it. `resolve_main` (compute) writes, per target pixel, the host's farthest
// depth sample in the pass's reverse depth, moved back by host_margin, into `host_out` (its
// bits; 0xffffffff where the host has no geometry) for the compute passes; the draw
// `vs_main`/`fs_main` then writes that depth and the id HOST_ID (BACKGROUND_ID where the
// host has no geometry) into the depth and id targets. Reading a multisampled texture in a
// compute pass rather than a fragment shader keeps lavapipe from growing its memory with
// every frame. Assembled after common.wgsl.
//
// Flags: MULTISAMPLED (the host's depth texture has several samples per pixel; the farthest
// counts, so a line is hidden only where the host covers the whole pixel).

@group(0) @binding(0) var<uniform> frame: Frame;
// Bound as unfilterable float (its depth in x), which every backend can load from; GLSL
// has no texel fetch from depth textures.
#if MULTISAMPLED
@group(0) @binding(30) var host_source: texture_multisampled_2d<f32>;
#else
@group(0) @binding(30) var host_source: texture_2d<f32>;
#endif

// How host depth maps to the pass's reverse depth (src/gpu/host.rs, HostParams).
struct HostParams {
    // Host NDC (u, v, depth, 1) of a point -> its reverse depth, as dot(a, q) / dot(b, q);
    // used when the host rendered with other matrices than the scene's.
    a: vec4<f32>,
    b: vec4<f32>,
    // 0: same matrices, standard depth (reverse = 1 - host); 1: same, reversed
    // (reverse = host); 2: other matrices (a, b).
    mode: u32,
    // Whether greater host depth is nearer (a reversed host convention).
    reversed: u32,
    _pad: u32,
    // The smallest step of the host's depth format near its far end: 2^-bits for unorm
    // formats, the f32 step at 1 for float ones (relative for a reversed float format).
    quantum: f32,
}
@group(0) @binding(31) var<uniform> host: HostParams;

@group(0) @binding(32) var host_out: texture_storage_2d<r32uint, write>;

@compute @workgroup_size(8, 8)
fn resolve_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !all(vec2<f32>(gid.xy) < frame.target_size) {
        return;
    }
    textureStore(host_out, gid.xy, vec4<u32>(host_value(gid.xy), 0u, 0u, 0u));
}

// The bits of the host's reverse depth at target pixel xy, or 0xffffffff.
fn host_value(xy: vec2<u32>) -> u32 {
    // The image pixel this target pixel is; the host's depth covers the image only.
    let image = vec2<i32>(xy) + vec2<i32>(frame.target_origin);
    let size = vec2<i32>(textureDimensions(host_source));
    if any(image < vec2<i32>(0)) || any(image >= size) {
        return 0xffffffffu;
    }
    let far = select(1.0, 0.0, host.reversed == 1u);
    // The farthest sample: towards `far`.
    var d = 1.0 - far;
#if MULTISAMPLED
    // The texture's own count, not a uniform: a loop bound by uniform values alone is
    // re-specialised by lavapipe at every dispatch (see common.wgsl).
    for (var s = 0u; s < textureNumSamples(host_source); s++) {
        let x = textureLoad(host_source, image, i32(s)).x;
        d = select(max(d, x), min(d, x), host.reversed == 1u);
    }
#else
    d = textureLoad(host_source, image, 0).x;
#endif
    if d == far {
        return 0xffffffffu;
    }
    let pixel = vec2<f32>(image) + 0.5;
    let ndc = vec2<f32>(pixel.x / f32(size.x) * 2.0 - 1.0, 1.0 - pixel.y / f32(size.y) * 2.0);
    let q = vec4<f32>(ndc, d, 1.0);
    // Selects, not branches on the uniform mode (see common.wgsl).
    let same = select(1.0 - d, d, host.mode == 1u);
    let reverse = select(same, dot(host.a, q) / dot(host.b, q), host.mode == 2u);
    // Moved back by the margin, so the pass's own surfaces win ties with the host's copy.
    return bitcast<u32>(clamp(reverse - host_margin(reverse, host.quantum), 0.0, 1.0));
}

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
