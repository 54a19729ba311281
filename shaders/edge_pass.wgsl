// The deferred edge pass: one invocation per pixel. Prepended with common.wgsl.
//
// id -> three indices -> three clip-space vertices -> homogeneous screen edge lines ->
// distance to each drawn edge + perspective-correct barycentrics -> shade -> line -> store.

@group(0) @binding(0) var<uniform> frame: Frame;
// xyz per vertex, packed, mesh-local.
@group(0) @binding(1) var<storage, read> positions: array<f32>;
@group(0) @binding(2) var<storage, read> normals: array<f32>;
@group(0) @binding(3) var<storage, read> indices: array<u32>;
// A byte per triangle, 4 triangles per word: bits 0-2 the drawn edges, bits 3-7 the outline
// hints (Mesh::outline_hints: bit 3 a boundary edge, bits 4-7 the fold bound).
@group(0) @binding(4) var<storage, read> edge_masks: array<u32>;
@group(0) @binding(5) var ids: texture_2d<u32>;
// The triangle across each edge (3 per triangle, edge i = corner i -> i+1), or
// BACKGROUND_ID for boundary and non-manifold edges.
@group(0) @binding(6) var<storage, read> neighbours: array<u32>;

// The second halves of `indices` and `neighbours`, for meshes split over two bindings.
@group(0) @binding(7) var<storage, read> indices_hi: array<u32>;
@group(0) @binding(8) var<storage, read> neighbours_hi: array<u32>;

const BACKGROUND_ID: u32 = 0xffffffffu;

// What the outline pass wrote (outline.wgsl), read when frame.silhouettes is 1.
@group(2) @binding(0) var<storage, read> outline: array<u32>;

// Vertex indices of triangle t.
fn corners(t: u32) -> vec3<u32> {
    if t < frame.index_split {
        return vec3<u32>(indices[3u * t], indices[3u * t + 1u], indices[3u * t + 2u]);
    }
    let k = 3u * (t - frame.index_split);
    return vec3<u32>(indices_hi[k], indices_hi[k + 1u], indices_hi[k + 2u]);
}

// The triangle across edge i of triangle t.
fn neighbour(t: u32, i: u32) -> u32 {
    if t < frame.index_split {
        return neighbours[3u * t + i];
    }
    return neighbours_hi[3u * (t - frame.index_split) + i];
}

fn position(v: u32) -> vec3<f32> {
    return vec3<f32>(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

fn normal(v: u32) -> vec3<f32> {
    return vec3<f32>(normals[3u * v], normals[3u * v + 1u], normals[3u * v + 2u]);
}

// Pixels whose centre lies within this many pixels of their triangle's boundary are checked
// against the triangles of their 3×3 neighbourhood. Rasterizers snap vertices to a sub-pixel
// grid (8 bits on lavapipe, llvmpipe and desktop GPUs: errors up to 1/512 px), so such a
// centre may have been given to the wrong side of an edge; the exact test below decides.
const COVERAGE_MARGIN: f32 = 1.0 / 128.0;

// One triangle seen from one pixel centre.
struct Sample {
    id: u32,
    clip0: vec4<f32>,
    clip1: vec4<f32>,
    clip2: vec4<f32>,
    // Screen lines of the three edges, relative to the pixel centre (see `edge_eval`).
    l0: vec3<f32>,
    l1: vec3<f32>,
    l2: vec3<f32>,
    bary: vec3<f32>,
    // The centre's ray hits the triangle between the near and far planes.
    covers: bool,
    // Distances from the centre to the three edge lines, drawn or not.
    lines: vec3<f32>,
    // The smallest of them.
    margin: f32,
    // Clip w of the hit point (the view distance): smaller is nearer.
    w: f32,
}

fn sample(id: u32, pixel: vec2<f32>) -> Sample {
    var s: Sample;
    s.id = id;
    let v = corners(id);
    s.clip0 = frame.view_proj * vec4<f32>(position(v.x), 1.0);
    s.clip1 = frame.view_proj * vec4<f32>(position(v.y), 1.0);
    s.clip2 = frame.view_proj * vec4<f32>(position(v.z), 1.0);
    let p0 = pixel_relative(s.clip0, pixel, frame.size);
    let p1 = pixel_relative(s.clip1, pixel, frame.size);
    let p2 = pixel_relative(s.clip2, pixel, frame.size);
    s.l0 = cross(p0, p1);
    s.l1 = cross(p1, p2);
    s.l2 = cross(p2, p0);
    let e = vec3<f32>(s.l1.z, s.l2.z, s.l0.z);
    let sum = e.x + e.y + e.z;
    s.bary = select(vec3<f32>(-1.0), e / sum, sum != 0.0);
    let hit = s.bary.x * s.clip0 + s.bary.y * s.clip1 + s.bary.z * s.clip2;
    s.covers = all(s.bary >= vec3<f32>(0.0)) && hit.z >= 0.0 && hit.z <= hit.w;
    s.w = hit.w;
    s.lines = vec3<f32>(line_distance(s.l0, true), line_distance(s.l1, true), line_distance(s.l2, true));
    s.margin = min(s.lines.x, min(s.lines.y, s.lines.z));
    return s;
}

// Steps of the walk across edges in `walk`: enough to go round a vertex's fan of small
// triangles from a rasterized neighbour to the one that owns the centre, and, in the
// outline pass, to cross the few pixels' worth of sub-pixel triangles between a rasterized
// triangle and one that hides a point of an outline (6 steps left outlines showing through
// the far bunny's sub-pixel bumps: errors up to 0.45 px against the ground truth).
const WALK_STEPS: u32 = 24u;

// Point location by walking: from `start`, which does not cover the pixel centre, cross the
// edge the centre lies beyond until a triangle covers it. Finds the owner of a centre that
// the rasterizer gave to a neighbour when the owner (a sub-pixel triangle, say) has no
// rasterized pixel of its own.
fn walk(start: Sample, pixel: vec2<f32>) -> Sample {
    var s = start;
    for (var step = 0u; step < WALK_STEPS; step++) {
        let b = s.bary;
        // Corner k's weight is negative beyond the opposite edge k + 1 (mod 3).
        let lowest = min(b.x, min(b.y, b.z));
        if s.covers || lowest >= 0.0 || any(b == vec3<f32>(-1.0)) {
            return s; // covered, or inside but beyond the near or far plane, or degenerate
        }
        let edge = select(select(0u, 2u, b.y == lowest), 1u, b.x == lowest);
        let next = neighbour(s.id, edge);
        if next == BACKGROUND_ID {
            return s;
        }
        s = sample(next, pixel);
    }
    return s;
}

// The triangle whose surface the centre of pixel `xy` sees: the rasterizer's answer unless
// the centre lies within COVERAGE_MARGIN of that triangle's boundary, or the pixel is
// background next to foreground. Then the neighbourhood's triangles (and those a walk from
// them reaches) are tested exactly and the nearest one covering the centre wins; if none
// does, the pixel is background where background is next to it, and keeps the rasterizer's
// triangle otherwise (the true one is out of reach).
fn resolve(xy: vec2<u32>, pixel: vec2<f32>) -> Sample {
    let raster = textureLoad(ids, xy, 0).x;
    var own: Sample;
    own.id = BACKGROUND_ID;
    own.covers = false;
    if raster != BACKGROUND_ID {
        own = sample(raster, pixel);
        if own.covers && own.margin >= COVERAGE_MARGIN {
            return own;
        }
    } else if !foreground_next_to(xy) {
        return own;
    }
    return refine(xy, pixel, own);
}

// True when one of the four edge-adjacent pixels is foreground.
fn foreground_next_to(xy: vec2<u32>) -> bool {
    let last = vec2<u32>(frame.size) - 1u;
    let l = textureLoad(ids, vec2<u32>(max(xy.x, 1u) - 1u, xy.y), 0).x;
    let r = textureLoad(ids, vec2<u32>(min(xy.x + 1u, last.x), xy.y), 0).x;
    let u = textureLoad(ids, vec2<u32>(xy.x, max(xy.y, 1u) - 1u), 0).x;
    let d = textureLoad(ids, vec2<u32>(xy.x, min(xy.y + 1u, last.y)), 0).x;
    return min(min(l, r), min(u, d)) != BACKGROUND_ID;
}

// The slow path of `resolve`, taken by few pixels.
fn refine(xy: vec2<u32>, pixel: vec2<f32>, own: Sample) -> Sample {
    let raster = own.id;
    var best: Sample;
    best.id = BACKGROUND_ID;
    best.w = 3.0e38;
    if own.covers {
        best = own;
    } else if raster != BACKGROUND_ID {
        let found = walk(own, pixel);
        if found.covers {
            best = found;
        }
    }
    var background_near = raster == BACKGROUND_ID;
    let last = vec2<i32>(frame.size) - 1;
    var checked = raster;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = clamp(vec2<i32>(xy) + vec2<i32>(dx, dy), vec2<i32>(0), last);
            let id = textureLoad(ids, vec2<u32>(q), 0).x;
            background_near = background_near || id == BACKGROUND_ID;
            if id == BACKGROUND_ID || id == raster || id == checked {
                continue;
            }
            checked = id;
            var s = sample(id, pixel);
            if !s.covers && raster == BACKGROUND_ID {
                s = walk(s, pixel);
            }
            if s.covers && s.w < best.w {
                best = s;
            }
        }
    }
    if best.id == BACKGROUND_ID && !background_near {
        return own;
    }
    return best;
}

struct Pixel {
    // The visible triangle, BACKGROUND_ID on background.
    id: u32,
    // Distance in pixels to the nearest line: a drawn edge of the visible triangle, or an
    // outline within reach (see outline.wgsl).
    distance: f32,
    // The line's intensity at this pixel (profile × depth fade), before the wire alpha.
    line: f32,
    // Linear shaded surface colour.
    surface: vec3<f32>,
    // Reverse-Z depth of the visible point (0 on background).
    depth: f32,
}

// Distances are kept in 1/4096 px steps in the high 20 bits (complemented, so the atomic max
// keeps the least), the line's depth fade in the low 12 bits. 0 means no outline.
const OUTLINE_STEPS: f32 = 4096.0;
const OUTLINE_MAX: u32 = 0xfffffu;

fn pack_outline(d: f32, fade: f32) -> u32 {
    let q = u32(clamp(d * OUTLINE_STEPS, 0.0, f32(OUTLINE_MAX)));
    return ((OUTLINE_MAX - q) << 12u) | u32(round(clamp(fade, 0.0, 1.0) * 4095.0));
}

// What the outline pass left for this pixel: (distance, depth fade), or (NO_EDGE, 0).
fn outline_at(xy: vec2<u32>) -> vec2<f32> {
    if frame.silhouettes == 0u {
        return vec2<f32>(NO_EDGE, 0.0);
    }
    let v = outline[xy.y * u32(frame.size.x) + xy.x];
    if v == 0u {
        return vec2<f32>(NO_EDGE, 0.0);
    }
    let steps = OUTLINE_MAX - (v >> 12u);
    return vec2<f32>((f32(steps) + 0.5) / OUTLINE_STEPS, f32(v & 0xfffu) / 4095.0);
}

fn evaluate(xy: vec2<u32>) -> Pixel {
    var out: Pixel;
    let pixel = vec2<f32>(xy) + 0.5;
    let s = resolve(xy, pixel);
    let outline = outline_at(xy);
    out.id = s.id;
    out.distance = outline.x;
    out.line = line_intensity(outline.x, frame.line_width) * outline.y;
    out.depth = 0.0;
    if s.id == BACKGROUND_ID {
        return out;
    }
    let id = s.id;
    let mask = (edge_masks[id >> 2u] >> ((id & 3u) * 8u)) & 7u;
    let d = drawn_distances(s.lines, vec3<f32>(s.clip0.z, s.clip1.z, s.clip2.z), mask);
    let own = min(d.x, min(d.y, d.z));
    out.distance = min(own, out.distance);
    // Nothing is drawn twice: the stronger of the own edge and the outline wins.
    out.line = max(out.line, line_intensity(own, frame.line_width) * depth_fade(s.w, frame.fade));

    let v = corners(id);
    let w0 = position(v.x);
    let w1 = position(v.y);
    let w2 = position(v.z);
    let b = s.bary;
    let world = b.x * w0 + b.y * w1 + b.z * w2;
    out.depth = dot(frame.depth_row, vec4<f32>(world, 1.0)) / s.w;
    let n = b.x * normal(v.x) + b.y * normal(v.y) + b.z * normal(v.z);
    out.surface = surface_color(frame, world, n, cross(w1 - w0, w2 - w0));
    return out;
}

fn inside(xy: vec2<u32>) -> bool {
    return all(vec2<f32>(xy) < frame.size);
}

// Shaded mode: the pass draws the surface itself.
@group(1) @binding(0) var shaded_out: texture_storage_2d<OUTPUT_FORMAT, write>;

@compute @workgroup_size(8, 8)
fn shade_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !inside(gid.xy) {
        return;
    }
    let p = evaluate(gid.xy);
    var base = frame.background;
    if p.id != BACKGROUND_ID {
        base = vec4<f32>(p.surface, 1.0);
    }
    let i = p.line * frame.wire_color.a;
    let color = vec4<f32>(mix(base.rgb, frame.wire_color.rgb, i), max(base.a, i));
    textureStore(shaded_out, gid.xy, encode_output(color));
}

// Overlay mode: blend the line over the host's own colour image.
@group(1) @binding(1) var overlay_out: texture_storage_2d<OUTPUT_FORMAT, write>;
@group(1) @binding(2) var host_color: texture_2d<f32>;

@compute @workgroup_size(8, 8)
fn overlay_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !inside(gid.xy) {
        return;
    }
    let p = evaluate(gid.xy);
    let host = textureLoad(host_color, gid.xy, 0);
    let i = p.line * frame.wire_color.a;
    let color = vec4<f32>(mix(host.rgb, frame.wire_color.rgb, i), max(host.a, i));
    textureStore(overlay_out, gid.xy, encode_output(color));
}

// Diagnostic mode, for tools and tests: the raw edge distance (pixels; NO_EDGE on
// background) and the reverse-Z depth of the visible point, and the resolved triangle id.
@group(1) @binding(3) var diagnostic_out: texture_storage_2d<rgba32float, write>;
@group(1) @binding(4) var resolved_ids: texture_storage_2d<r32uint, write>;

@compute @workgroup_size(8, 8)
fn diagnostic_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !inside(gid.xy) {
        return;
    }
    let p = evaluate(gid.xy);
    textureStore(diagnostic_out, gid.xy, vec4<f32>(p.distance, p.depth, 0.0, 0.0));
    textureStore(resolved_ids, gid.xy, vec4<u32>(p.id, 0u, 0u, 0u));
}

// Floor mode, for benchmarks: the least any deferred pass can cost. It reads the id and
// writes a flat colour, with no geometry, shading or line work.
@group(1) @binding(5) var floor_out: texture_storage_2d<OUTPUT_FORMAT, write>;

@compute @workgroup_size(8, 8)
fn floor_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !inside(gid.xy) {
        return;
    }
    let id = textureLoad(ids, gid.xy, 0).x;
    let color = select(frame.fill_color, frame.background, id == BACKGROUND_ID);
    textureStore(floor_out, gid.xy, encode_output(color));
}
