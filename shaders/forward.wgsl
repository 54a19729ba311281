// Forward single-pass wireframe (Bærentzen et al. 2006, NVIDIA "Solid Wireframe" 2007; seeds
// 000-004), with vertex pulling in place of the seeds' geometry shader. Prepended with
// common.wgsl; the Rust side appends `encode_output` for the output format.
//
// A non-indexed draw of 3 × triangles vertices: invocation k reads triangle k / 3's three
// vertices, projects all three, and computes the screen-space altitude of its own corner
// k % 3 exactly as the seeds' geometry shader does, with the corrected WIN_SCALE (half the
// image size; seed 000's reader comment). The three distances are interpolated without
// perspective (`@interpolate(linear)` = GLSL `noperspective`), and the fragment's distance to
// the nearest edge is their minimum.
//
// Like the seeds, this DIVIDES BY w. It is the baseline as published, and its failure for
// triangles that cross the near plane (w <= 0 behind the eye: the projected corners jump to
// the other side, the altitudes are wrong, inf or NaN) is part of what the comparison with
// the deferred pass and the ground truth shows. Do not "fix" it here.
//
// Also part of the baseline: it depends on the rasteriser interpolating `noperspective`
// varyings correctly on clipped triangles. Mesa's lavapipe and llvmpipe give NaN for all
// three distances on some triangles their clipper cuts (the same values interpolated with
// perspective are fine), so those triangles lose their lines; tests/forward.rs pins how often.

struct Draw {
    first_id: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> draw: Draw;
// xyz per vertex, packed, mesh-local.
@group(0) @binding(2) var<storage, read> positions: array<f32>;
@group(0) @binding(3) var<storage, read> normals: array<f32>;
@group(0) @binding(4) var<storage, read> indices: array<u32>;
// Edge masks, 8 bits per triangle, 4 triangles per word; bit i = edge i (corner i -> i+1).
@group(0) @binding(5) var<storage, read> edge_masks: array<u32>;
// The second half of `indices`, for meshes split over two bindings (src/gpu/mesh.rs).
@group(0) @binding(6) var<storage, read> indices_hi: array<u32>;

// Vertex indices of triangle t.
fn corners(t: u32) -> vec3<u32> {
    if t < frame.index_split {
        return vec3<u32>(indices[3u * t], indices[3u * t + 1u], indices[3u * t + 2u]);
    }
    let k = 3u * (t - frame.index_split);
    return vec3<u32>(indices_hi[k], indices_hi[k + 1u], indices_hi[k + 2u]);
}

// Seed 004's Q ("max edge width", 100 there): the distance a masked edge's component
// carries. Beyond the reach of any line a sane width draws, and small enough that the
// rasteriser interpolates it without precision trouble.
const MASKED: f32 = 1.0e6;

fn position(v: u32) -> vec3<f32> {
    return vec3<f32>(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

fn normal(v: u32) -> vec3<f32> {
    return vec3<f32>(normals[3u * v], normals[3u * v + 1u], normals[3u * v + 2u]);
}

fn triangle_mask(t: u32) -> u32 {
    return (edge_masks[t >> 2u] >> ((t & 3u) * 8u)) & 7u;
}


struct Varyings {
    @builtin(position) clip: vec4<f32>,
    // Component j: distance in pixels to the edge opposite corner j, i.e. edge (j + 1) % 3.
    @location(0) @interpolate(linear) dist: vec3<f32>,
    @location(1) world: vec3<f32>,
    @location(2) normal: vec3<f32>,
    @location(3) @interpolate(flat) face_normal: vec3<f32>,
    @location(4) @interpolate(flat) id: u32,
}

@vertex
fn vs_main(@builtin(vertex_index) k: u32) -> Varyings {
    let t = k / 3u;
    let corner = k - 3u * t;
    let v = corners(t);
    let w0 = position(v.x);
    let w1 = position(v.y);
    let w2 = position(v.z);

    // The seeds' geometry shader, with WIN_SCALE = half the image size.
    let win_scale = 0.5 * frame.size;
    let c0 = frame.view_proj * vec4<f32>(w0, 1.0);
    let c1 = frame.view_proj * vec4<f32>(w1, 1.0);
    let c2 = frame.view_proj * vec4<f32>(w2, 1.0);
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
    let mask = triangle_mask(t);
    let drawn = vec3<bool>((mask & 2u) != 0u, (mask & 4u) != 0u, (mask & 1u) != 0u);
    // A drawn edge's component is the corner's altitude at its own corner and 0 at the two
    // corners on the edge. A masked edge's component is Q at all three corners (seed 004 puts
    // Q at the other two corners and keeps the altitude at the own one; a constant Q keeps
    // the edge out of the minimum everywhere, as the deferred pass's NO_EDGE does).
    var dist = select(vec3<f32>(MASKED), vec3<f32>(0.0), drawn);
    var opposite = v0;
    if corner == 1u {
        opposite = v1;
    } else if corner == 2u {
        opposite = v2;
    }
    if drawn[corner] {
        dist[corner] = area / length(opposite);
    }

    var own = w0;
    var own_normal = normal(v.x);
    if corner == 1u {
        own = w1;
        own_normal = normal(v.y);
    } else if corner == 2u {
        own = w2;
        own_normal = normal(v.z);
    }
    var out: Varyings;
    // Exactly the visibility pass's expression, so both rasterise the same triangles.
    out.clip = reverse_z(frame.view_proj, frame.depth_row, own);
    out.dist = dist;
    out.world = own;
    out.normal = own_normal;
    out.face_normal = cross(w1 - w0, w2 - w0);
    out.id = draw.first_id + t;
    return out;
}

// Distance to the nearest drawn edge; masked components never win.
fn nearest(in: Varyings) -> f32 {
    return min(in.dist.x, min(in.dist.y, in.dist.z));
}

fn shaded(in: Varyings, d: f32) -> vec4<f32> {
    let surface = surface_color(frame, in.world, in.normal, in.face_normal);
    let w = (frame.view_proj * vec4<f32>(in.world, 1.0)).w;
    let i = line_intensity(d, frame.line_width) * depth_fade(w, frame.fade);
    return vec4<f32>(mix(surface, frame.wire_color.rgb, i * frame.wire_color.a), 1.0);
}

@fragment
fn fs_main(in: Varyings) -> @location(0) vec4<f32> {
    return encode_output(shaded(in, nearest(in)));
}

struct MapsOut {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
    // The bits of two f32 (an Rgba32Uint target: float targets are not renderable on every
    // backend): r = distance in pixels (NO_EDGE where no edge is drawn; NaN stays NaN),
    // g = reverse-Z raster depth.
    @location(2) diag: vec4<u32>,
}

@fragment
fn fs_maps(in: Varyings) -> MapsOut {
    var d = nearest(in);
    var out: MapsOut;
    out.color = encode_output(shaded(in, d));
    out.id = in.id;
    if d >= 0.5 * MASKED {
        d = NO_EDGE;
    }
    out.diag = vec4<u32>(bitcast<u32>(d), bitcast<u32>(in.clip.z), 0u, 0u);
    return out;
}
