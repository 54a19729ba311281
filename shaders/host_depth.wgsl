// Seeds the targets from the host's depth buffer, before the visibility pass draws the
// instances over it: per target pixel, the host's nearest depth sample in the pass's reverse
// depth (moved back by HOST_MARGIN), the id HOST_ID where the host has geometry
// (BACKGROUND_ID where it has none), and
// the host depth alone in `host_out` for the compute passes. Assembled after common.wgsl.
//
// Flags: MULTISAMPLED (the host's depth texture has several samples per pixel; the nearest
// counts, so a line is hidden in every pixel a nearer host surface touches).

@group(0) @binding(0) var<uniform> frame: Frame;
#if MULTISAMPLED
@group(0) @binding(30) var host_depth: texture_depth_multisampled_2d;
#else
@group(0) @binding(30) var host_depth: texture_depth_2d;
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
    // Samples per pixel of the host's depth texture.
    samples: u32,
    // The smallest step of the host's depth format near its far end: 2^-bits for unorm
    // formats, the f32 step at 1 for float ones (relative for a reversed float format).
    quantum: f32,
}
@group(0) @binding(31) var<uniform> host: HostParams;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // One triangle over the whole target.
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

struct Seed {
    @builtin(frag_depth) depth: f32,
    @location(0) id: vec2<u32>,
    // The bits of the host's reverse depth; 0xffffffff where the host has no geometry.
    @location(1) host: u32,
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> Seed {
    var out: Seed;
    out.depth = 0.0;
    out.id = vec2<u32>(BACKGROUND_ID, 0u);
    out.host = 0xffffffffu;
    // The image pixel this target pixel is; the host's depth covers the image only.
    let image = vec2<i32>(floor(position.xy + frame.target_origin));
    let size = vec2<i32>(textureDimensions(host_depth));
    if any(image < vec2<i32>(0)) || any(image >= size) {
        return out;
    }
    let far = select(1.0, 0.0, host.reversed == 1u);
    // The farthest sample: towards `far`.
    let near_end = 1.0 - far;
    var d = near_end;
#if MULTISAMPLED
    for (var s = 0u; s < host.samples; s++) {
        let x = textureLoad(host_depth, image, i32(s));
        d = select(max(d, x), min(d, x), host.reversed == 1u);
    }
#else
    d = textureLoad(host_depth, image, 0);
#endif
    if d == far {
        return out;
    }
    var reverse = 1.0 - d;
    if host.mode == 1u {
        reverse = d;
    } else if host.mode == 2u {
        let pixel = vec2<f32>(image) + 0.5;
        let ndc = vec2<f32>(pixel.x / f32(size.x) * 2.0 - 1.0, 1.0 - pixel.y / f32(size.y) * 2.0);
        let q = vec4<f32>(ndc, d, 1.0);
        reverse = dot(host.a, q) / dot(host.b, q);
    }
    // Moved back by the margin, so the pass's own surfaces win ties with the host's copy.
    out.depth = clamp(reverse - host_margin(reverse, host.quantum), 0.0, 1.0);
    out.id = vec2<u32>(HOST_ID, 0u);
    out.host = bitcast<u32>(out.depth);
    return out;
}
