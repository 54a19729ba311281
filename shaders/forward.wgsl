// Forward single-pass wireframe (Bærentzen et al. 2006, "Single-pass wireframe rendering";
// NVIDIA's "Solid Wireframe" white paper, 2007), with vertex pulling in place of their
// geometry shader. Assembled after
// common.wgsl and scene.wgsl; the Rust side appends `encode_output` for the output format.
//
// One non-indexed instanced draw of 3 × triangles vertices per mesh: invocation k reads
// triangle k / 3's three vertices, projects all three, and computes the screen-space altitude
// of its own corner k % 3 exactly as the published geometry shader does, with the corrected
// WIN_SCALE (half the image size, not the whole of it). The three distances are
// interpolated without perspective (`@interpolate(linear)` = GLSL `noperspective`), and the
// fragment's distance to the nearest edge is their minimum.
//
// As published, this DIVIDES BY w. It is the baseline as published, and its failure for
// triangles that cross the near plane (w <= 0 behind the eye: the projected corners jump to
// the other side, the altitudes are wrong, inf or NaN) is part of what the comparison with
// the deferred pass and the ground truth shows. Do not "fix" it here.
//
// Also part of the baseline: it depends on the rasteriser interpolating `noperspective`
// varyings correctly on clipped triangles. Mesa's lavapipe and llvmpipe give NaN for all
// three distances on some triangles their clipper cuts (the same values interpolated with
// perspective are fine), so those triangles lose their lines; tests/forward.rs pins how often.

// The "Solid Wireframe" quad variant's Q ("max edge width", 100 there): the distance a masked edge's component
// carries. Beyond the reach of any line a sane width draws, and small enough that the
// rasteriser interpolates it without precision trouble.
const MASKED: f32 = 1.0e6;

struct Varyings {
    @builtin(position) clip: vec4<f32>,
    // Component j: distance in pixels to the edge opposite corner j, i.e. edge (j + 1) % 3.
    @location(0) @interpolate(linear) dist: vec3<f32>,
    @location(1) local: vec3<f32>,
    @location(2) normal: vec3<f32>,
    @location(3) @interpolate(flat) face_normal: vec3<f32>,
    @location(4) @interpolate(flat) slot: u32,
    @location(5) @interpolate(flat) tri: u32,
}

// The drawn edges of triangle t of instance `inst`.
fn drawn_mask(inst: u32, t: u32) -> u32 {
    if (instances[inst].flags & INSTANCE_EDGES) == 0u {
        return 0u;
    }
    return info[instances[inst].triangle_base + t] & 7u;
}

@vertex
fn vs_main(@builtin(vertex_index) k: u32, @location(7) slot: u32) -> Varyings {
    let t = k / 3u;
    let corner = k - 3u * t;
    let v = corners(instances[slot].triangle_base + t) + instances[slot].vertex_base;
    let a0 = vertex_at(v.x);
    let a1 = vertex_at(v.y);
    let a2 = vertex_at(v.z);
    let clip = instances[slot].clip;

    // The published geometry shader, with WIN_SCALE = half the image size.
    let win_scale = 0.5 * frame.image_size;
    let c0 = clip * vec4<f32>(a0.xyz, 1.0);
    let c1 = clip * vec4<f32>(a1.xyz, 1.0);
    let c2 = clip * vec4<f32>(a2.xyz, 1.0);
    let p0 = win_scale * c0.xy / c0.w;
    let p1 = win_scale * c1.xy / c1.w;
    let p2 = win_scale * c2.xy / c2.w;
    let v0 = p2 - p1;
    let v1 = p2 - p0;
    let v2 = p1 - p0;
    let area = abs(v1.x * v2.y - v1.y * v2.x);

    // Component j belongs to edge (j + 1) % 3: component 0 to edge 1 (mask bit 2), component
    // 1 to edge 2 (bit 4), component 2 to edge 0 (bit 1). So edge i is carried by corner
    // (i + 2) % 3, the corner opposite it.
    let mask = drawn_mask(slot, t);
    let drawn = vec3<bool>((mask & 2u) != 0u, (mask & 4u) != 0u, (mask & 1u) != 0u);
    // A drawn edge's component is the corner's altitude at its own corner and 0 at the two
    // corners on the edge. A masked edge's component is Q at all three corners (the quad variant puts
    // Q at the other two corners and keeps the altitude at the own one; a constant Q keeps
    // the edge out of the minimum everywhere, as the deferred pass's NO_EDGE does).
    var dist = select(vec3<f32>(MASKED), vec3<f32>(0.0), drawn);
    var opposite = v0;
    var own = a0;
    if corner == 1u {
        opposite = v1;
        own = a1;
    } else if corner == 2u {
        opposite = v2;
        own = a2;
    }
    if drawn[corner] {
        dist[corner] = area / length(opposite);
    }
    var out: Varyings;
    // Exactly the visibility pass's expression, so both rasterise the same triangles.
    out.clip = raster_position(frame, clip, instances[slot].depth_row, own.xyz);
    out.dist = dist;
    out.local = own.xyz;
    out.normal = unpack_normal(bitcast<u32>(own.w));
    out.face_normal = cross(a1.xyz - a0.xyz, a2.xyz - a0.xyz);
    out.slot = slot;
    out.tri = t;
    return out;
}

// Distance to the nearest drawn edge; masked components never win.
fn nearest(in: Varyings) -> f32 {
    return min(in.dist.x, min(in.dist.y, in.dist.z));
}

fn shaded(in: Varyings, d: f32) -> vec4<f32> {
    let inst = instances[in.slot];
    let surface = surface_color(frame, inst, in.local, in.normal, in.face_normal);
    let depth = dot(inst.fade_row, vec4<f32>(in.local, 1.0));
    let i = line_intensity(d, inst.line_width) * depth_fade(depth, frame.fade);
    return vec4<f32>(mix(surface, inst.wire_color.rgb, i * inst.wire_color.a), 1.0);
}

@fragment
fn fs_main(in: Varyings) -> @location(0) vec4<f32> {
    return encode_output(shaded(in, nearest(in)));
}

struct MapsOut {
    @location(0) color: vec4<f32>,
    @location(1) id: vec2<u32>,
    // The bits of two f32 (an Rgba32Uint target: float targets are not renderable on every
    // backend): r = distance in pixels (NO_EDGE where no edge is drawn; NaN stays NaN),
    // g = reverse raster depth.
    @location(2) diag: vec4<u32>,
}

@fragment
fn fs_maps(in: Varyings) -> MapsOut {
    var d = nearest(in);
    var out: MapsOut;
    out.color = encode_output(shaded(in, d));
    out.id = vec2<u32>(in.slot, in.tri);
    if d >= 0.5 * MASKED {
        d = NO_EDGE;
    }
    out.diag = vec4<u32>(bitcast<u32>(d), bitcast<u32>(in.clip.z), bitcast<u32>(NO_EDGE), 0u);
    return out;
}
