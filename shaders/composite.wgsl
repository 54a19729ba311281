// Draws a frame's result (premultiplied linear RGBA, written by the edge pass in its result
// mode) into the host's own render pass: quads over the runs of tiles that hold something,
// within the render pass's viewport (the frame's size, anywhere in the attachment), blended
// with (One, OneMinusSrcAlpha). The host's colour attachment decides the encoding: sRGB formats
// store sRGB and blend in linear light, float formats hold linear values. Assembled after
// common.wgsl.
//
// Flags: ENCODE_SRGB (the target is an 8-bit format without sRGB, which holds sRGB-encoded
// values); TESTED (the frame was seeded from the host's depth, and the render pass has the
// host's depth attachment). The result decides per pixel whether an instance or the host
// shows, from the host's farthest sample there; where the host's own geometry in front of an
// instance covers only some of a pixel's samples, the draw then tests each sample against
// the host's depth, so those samples keep the host's colour and the host's antialiased edges
// survive. The fragment's depth is the instance's at the nearest of the pixel's samples,
// moved forward by the margin that lets the pass's surfaces win ties with a host's own copy
// of them (the seeding's rule); pixels where no instance shows (lines over the host or the
// background) pass at every sample, as the result already hides what the host hides.

@group(0) @binding(34) var result: texture_2d<f32>;

// One run of 8×8 output tiles along a row an instance (two triangles), from the runs the
// edge pass listed (`list_composite_runs` in edge_pass.wgsl: tile x | (length - 1) <<
// COMPOSITE_RUN_SHIFT | tile y << 16): the other tiles' result is transparent, and drawing
// them would cost a software rasterizer a fragment each.
// The result texel a fragment shows comes from the quad, not from the fragment's position in
// the attachment, so the host may place the frame anywhere in its render pass with a
// viewport of the frame's size (an editor's panel, egui's paint callback).
struct Quad {
    @builtin(position) position: vec4<f32>,
    // The fragment's pixel in the result texture, interpolated without perspective: exact
    // to rounding at each pixel's centre.
    @location(0) @interpolate(linear) texel: vec2<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) i: u32, @location(0) run: u32) -> Quad {
    let corner = vec2<u32>(select(0u, 1u, i == 1u || i == 4u || i == 5u), select(0u, 1u, i == 2u || i == 3u || i == 5u));
    let size = vec2<f32>(textureDimensions(result));
    let x = run & ((1u << COMPOSITE_RUN_SHIFT) - 1u);
    let extent = vec2<u32>(((run & 0xffffu) >> COMPOSITE_RUN_SHIFT) + 1u, 1u);
    let p = min(vec2<f32>((vec2<u32>(x, run >> 16u) + corner * extent) * 8u), size);
    return Quad(vec4<f32>(p.x / size.x * 2.0 - 1.0, 1.0 - p.y / size.y * 2.0, 0.0, 1.0), p);
}

fn result_at(texel: vec2<f32>) -> vec4<f32> {
    let size = vec2<i32>(textureDimensions(result));
    let xy = clamp(vec2<i32>(floor(texel)), vec2<i32>(0), size - 1);
    let c = textureLoad(result, xy, 0);
#if ENCODE_SRGB
    // An 8-bit target without sRGB holds sRGB-encoded values (as the storage output's
    // Rgba8Unorm and egui's surface do): the colour encoded, still premultiplied, so the
    // blend works on encoded values as the host's own drawing does.
    return vec4<f32>(linear_to_srgb(c.rgb / max(c.a, 1e-6)) * c.a, c.a);
#else
    return c;
#endif
}

#if TESTED
@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(31) var<uniform> host: HostParams;
@group(0) @binding(10) var ids: texture_2d<u32>;
@group(0) @binding(35) var depth: texture_2d<f32>;

struct Tested {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// The reverse depth of the instance that target pixel xy shows, or -1 where none does
// (background, the host, outside the targets).
fn instance_depth(xy: vec2<i32>) -> f32 {
    let p = clamp(xy, vec2<i32>(0), vec2<i32>(frame.target_size) - 1);
    let id = textureLoad(ids, p, 0).x;
    let shows = id != BACKGROUND_ID && id != HOST_ID && all(p == xy);
    return select(-1.0, textureLoad(depth, p, 0).x, shows);
}

// The host's depth of reverse depth r at full-image pixel `pixel`: host_value's mapping
// (host_depth.wgsl) inverted.
fn host_depth_of(r: f32, pixel: vec2<f32>) -> f32 {
    let same = select(1.0 - r, r, host.mode == 1u);
    let ndc = vec2<f32>(pixel.x / frame.image_size.x * 2.0 - 1.0,
                        1.0 - pixel.y / frame.image_size.y * 2.0);
    // r = dot(a, q) / dot(b, q) with q = (ndc, d, 1), solved for d.
    let num = dot(host.a.xy, ndc) + host.a.w - r * (dot(host.b.xy, ndc) + host.b.w);
    let den = r * host.b.z - host.a.z;
    return select(same, num / den, host.mode == 2u && den != 0.0);
}

// The larger change from r to a neighbour that shows an instance (a or b, -1 for none).
fn axis_change(r: f32, a: f32, b: f32) -> f32 {
    return max(select(0.0, abs(r - a), a >= 0.0), select(0.0, abs(b - r), b >= 0.0));
}

@fragment
fn fs_main(quad: Quad) -> Tested {
    let xy = vec2<i32>(floor(quad.texel + frame.output_offset));
    let r = instance_depth(xy);
    // The instance's depth change to its neighbours, per axis the larger (a crease may lie
    // within the pixel), summed: a sample lies within half a pixel per axis, and the change
    // over a whole pixel bounds the surface there on either side of a crease.
    let x = vec2<i32>(1, 0);
    let y = vec2<i32>(0, 1);
    let change = axis_change(r, instance_depth(xy - x), instance_depth(xy + x))
        + axis_change(r, instance_depth(xy - y), instance_depth(xy + y));
    let nearest = min(r + change + host_margin(r, host.quantum), 1.0);
    let pixel = floor(quad.texel + frame.output_offset + frame.target_origin) + 0.5;
    let d = clamp(host_depth_of(nearest, pixel), 0.0, 1.0);
    let everywhere = select(0.0, 1.0, host.reversed == 1u);
    return Tested(result_at(quad.texel), select(everywhere, d, r >= 0.0));
}
#else
@fragment
fn fs_main(quad: Quad) -> @location(0) vec4<f32> {
    return result_at(quad.texel);
}
#endif
