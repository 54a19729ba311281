// The deferred edge pass, after common.wgsl and scene.wgsl. Several dispatches, so that work
// only some pixels need runs only for them (a software rasterizer runs the arithmetic of
// both sides of every branch, and a loop until its last lane is done; it skips only the
// memory reads of masked lanes):
//
// In order:
//
// `classify_main`, one invocation per 8×8 output tile: the tiles that hold foreground are
// listed, and the background next to foreground is appended to the refine list.
//
// `border_main`, over the output's border pixels: the background there next to foreground
// in the guard band joins that list.
//
// `background_main`, one invocation per output pixel: background and host pixels are
// written, without lines. Only where the background is not one colour that a clear of the
// output lays down instead (DeferredPass::background_clear).
//
// `traced_main`, dispatched indirectly over the tiles the trace pass listed (those its
// lines reach): their background and host pixels get the trace pass's line, if any.
//
// `tile_main`, dispatched indirectly over the listed tiles: the triangle the rasterizer gave
// a pixel is tested exactly at the centre; where it covers the centre with room to spare
// (nearly every pixel), the pixel is finished here: distance to the drawn edges,
// perspective-correct barycentrics, shading, the line. Pixels it cannot decide (the centre
// within COVERAGE_MARGIN of the triangle's boundary or outside it) are appended to the
// refine list instead.
//
// `refine_main`, dispatched indirectly over that list only: the exact coverage search among
// the neighbourhood's triangles and the walks across edges from them.
//
// Flags: TRACED (read what the trace pass left), PATCHES (some instance draws a mesh with
// undrawn edges: a pixel near one searches its patch, `patch_distance`), COLORS (instances differ in line
// colour: the trace pass also left which instance's line a pixel holds), HIDDEN (the trace
// pass left hidden lines, drawn under the visible ones: `hidden_at`), HOST (the host's
// depth seeded the targets: a triangle must also be nearer than it), and the output
// mode: MODE_SHADE, MODE_OVERLAY, MODE_RESULT (with SHADED: surface and lines, else lines
// only), MODE_DIAGNOSTIC.
#if TRACED
// What the trace pass left per target pixel: the greatest `line_key` (and, with COLORS,
// the greatest (level, instance) pair after it); then the tiles its lines reach
// (`traced_tile_marks`).
@group(0) @binding(12) var<storage, read> acc: array<u32>;
#endif

// A list one dispatch appends to and the next is dispatched over: the indirect dispatch
// size (`list_size`), the count, the items, then marks of what is listed (0 until it is).
struct List {
    x: atomic<u32>,
    y: atomic<u32>,
    z: u32,
    count: atomic<u32>,
    items: array<atomic<u32>>,
}

struct ListRead {
    x: u32,
    y: u32,
    z: u32,
    count: u32,
    items: array<u32>,
}

// The pixels `classify_main`, `border_main` and `tile_main` leave to `refine_main`.
@group(0) @binding(15) var<storage, read_write> work_rw: List;
@group(0) @binding(16) var<storage, read> work: ListRead;

// The tiles `classify_main` lists for `tile_main`.
@group(0) @binding(24) var<storage, read_write> tiles_rw: List;
@group(0) @binding(25) var<storage, read> tiles: ListRead;

#if MODE_SHADE
@group(0) @binding(20) var out_color: texture_storage_2d<OUTPUT_FORMAT, write>;
#endif
#if MODE_OVERLAY
@group(0) @binding(20) var out_color: texture_storage_2d<OUTPUT_FORMAT, write>;
@group(0) @binding(21) var host_color: texture_2d<f32>;
#endif
#if MODE_RESULT
// Premultiplied linear RGBA, drawn into the host's render pass by composite.wgsl.
@group(0) @binding(20) var out_color: texture_storage_2d<rgba16float, write>;

// The output tiles composite.wgsl draws (every other tile's result is transparent): the
// indirect draw's arguments (6 vertices a tile, a tile an instance), then the tiles, which
// the draw reads as an instance-rate vertex buffer.
struct CompositeTiles {
    vertices: atomic<u32>,
    tiles: atomic<u32>,
    first_vertex: u32,
    first_instance: u32,
    items: array<atomic<u32>>,
}
@group(0) @binding(36) var<storage, read_write> composite_rw: CompositeTiles;
#endif
#if MODE_DIAGNOSTIC
// Distance in pixels to the line (r) and reverse depth (g); the resolved (instance, triangle).
@group(0) @binding(22) var out_diagnostic: texture_storage_2d<rgba32float, write>;
@group(0) @binding(23) var out_ids: texture_storage_2d<rgba32uint, write>;
#endif

struct Pixel {
    // The visible instance and triangle; inst is BACKGROUND_ID or HOST_ID where none is.
    inst: u32,
    tri: u32,
    // Distance in pixels to the line that colours the pixel most (NO_EDGE for none).
    distance: f32,
    // That line's intensity (profile × depth fade), before the wire alpha, and its colour.
    line: f32,
    wire: vec4<f32>,
    // Linear shaded surface colour.
    surface: vec3<f32>,
    // Reverse depth of the visible point (0 where none).
    depth: f32,
    // The line's class: 0 none, LINE_CLASS_EDGE, LINE_CLASS_OUTLINE.
    kind: u32,
}

// The class of the trace pass's line with owner word `owner` (COLORS; an edge without).
fn owner_kind(owner: u32) -> u32 {
    let kind = owner & OWNER_CLASS;
    var line = select(LINE_CLASS_EDGE, LINE_CLASS_CUT, kind == OWNER_CUT);
    line = select(line, LINE_CLASS_OUTLINE, kind == OWNER_OUTLINE);
    return select(line, LINE_CLASS_INTERSECTION, kind == OWNER_INTERSECTION);
}

// The line the trace pass left in target pixel `xy`: its key (0 for none) and its owner
// (the instance slot whose line it is, and OWNER_OUTLINE for an outline: `owner_color`).
fn outline_at(xy: vec2<u32>) -> vec2<u32> {
    var key = 0u;
    var owner = 0u;
#if TRACED
    let k = xy.y * u32(frame.target_size.x) + xy.x;
#if COLORS
    key = acc[2u * k];
    owner = acc[2u * k + 1u] & 0xfffffu;
#else
    key = acc[k];
#endif
#endif
    return vec2<u32>(key, owner);
}

// The key of the hidden line the trace pass left in target pixel `xy` (0 for none), and
// its owner word (COLORS: `hidden_color_of`; 0 otherwise).
fn hidden_at(xy: vec2<u32>) -> vec2<u32> {
#if HIDDEN
    let k = xy.y * u32(frame.target_size.x) + xy.x;
#if COLORS
    return vec2<u32>(acc[hidden_lines() + 2u * k], acc[hidden_lines() + 2u * k + 1u]);
#else
    return vec2<u32>(acc[hidden_lines() + k], 0u);
#endif
#else
    return vec2<u32>(0u);
#endif
}

// A pixel whose centre no triangle covers (`inst` is BACKGROUND_ID or HOST_ID): only the
// trace pass's line colours it, `outline` as outline_at gives it (0 for no line).
fn empty_pixel(xy: vec2<u32>, inst: u32, outline: vec2<u32>) -> Pixel {
    var p: Pixel;
    p.inst = inst;
    p.tri = 0u;
    p.depth = 0.0;
    if inst == HOST_ID {
        p.depth = host_at(vec2<i32>(xy));
    }
    if outline.x == 0u {
        p.distance = NO_EDGE;
        p.line = 0.0;
        p.wire = instances[slot(min(inst, frame.instances - 1u))].wire_color;
        p.kind = 0u;
    } else {
        p.distance = key_distance(outline.x);
        p.line = key_intensity(outline.x);
        p.wire = owner_color(outline.y);
        p.kind = owner_kind(outline.y);
    }
    return p;
}

// Bits of `info` (mesh_records.rs, EdgeData; INFO_*): the triangle's patch is larger than
// PATCH_TRIANGLES or crosses another surface (its drawn edges come from the trace pass), or
// is two triangles. Where the patch crosses another surface (INFO_CROSSED) its pixels take
// no lines of their own, which the crossing surface may hide right beside them.
#if PATCHES
// Corner k of a sampled triangle.
fn sample_corner(s: Sample, k: u32) -> vec3<f32> {
    return select(select(s.v2.xyz, s.v1.xyz, k == 1u), s.v0.xyz, k == 0u);
}

// The least distance from `point` to the drawn edges (mask bits) of a triangle with clip-space
// corners c0, c1, c2, as segments.
fn drawn_segments(c0: vec4<f32>, c1: vec4<f32>, c2: vec4<f32>, mask: u32, point: vec2<f32>) -> f32 {
    var best = NO_EDGE;
    if (mask & 1u) != 0u {
        best = min(best, segment_distance(c0, c1, point, frame.image_size));
    }
    if (mask & 2u) != 0u {
        best = min(best, segment_distance(c1, c2, point, frame.image_size));
    }
    if (mask & 4u) != 0u {
        best = min(best, segment_distance(c2, c0, point, frame.image_size));
    }
    return best;
}

// Twin of edge_math::patch_distance: pixels from `point` to the nearest drawn edge (as a
// segment) of the (small) patch around the sampled triangle `s`, the triangles reached from it
// across undrawn edges that are not silhouettes, breadth first. Quads take quad_distance,
// larger polygons patch_search.
fn patch_distance(s: Sample, point: vec2<f32>) -> f32 {
    let bits = info[instances[slot(s.inst)].triangle_base + s.tri];
    if (bits & INFO_QUAD) != 0u {
        return quad_distance(s, bits, point);
    }
    var best = drawn_segments(s.clip0, s.clip1, s.clip2, bits & 7u, point);
    // A loop no lane enters is skipped (and so are the search's arrays), while the body of an
    // `if` runs for every lane.
    for (var polygon = true; polygon; polygon = false) {
        best = min(best, patch_search(s, point));
    }
    return best;
}

// The triangle with corners q0, q1, q2 (in its own order) and drawn edges `mask`, across
// edge a -> b of a patch triangle whose third corner is c: whether it joins the patch (that
// edge is no silhouette), and if so the distance from `point` to its drawn edges (NO_EDGE
// otherwise).
struct Across {
    joins: bool,
    distance: f32,
}

fn across(s: Sample, q0: vec3<f32>, q1: vec3<f32>, q2: vec3<f32>, mask: u32, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, point: vec2<f32>) -> Across {
    let clip = instances[slot(s.inst)].clip;
    var out = Across(!is_silhouette(a, b, c, (q0 + q1 + q2) / 3.0, instances[slot(s.inst)].eye), NO_EDGE);
    if out.joins {
        let c0 = clip * vec4<f32>(q0, 1.0);
        let c1 = clip * vec4<f32>(q1, 1.0);
        let c2 = clip * vec4<f32>(q2, 1.0);
        out.distance = drawn_segments(c0, c1, c2, mask, point);
    }
    return out;
}

// Bits of a quad triangle's `info` (INFO_QUAD; mesh_store::quad_bits) that describe the
// other triangle without reading it: the diagonal (this triangle's undrawn edge, bits
// 16-17), the other triangle's corner off the diagonal (18-19), whether its next corner is
// the diagonal's start (bit 20) or its end, its drawn edges (21-23), and whether it is
// stored right after this one (bit 24) or right before it (bit 25): QUAD_* from
// mesh_records.rs.
// A quad as its sampled triangle `s` sees it, from two reads (three where its halves are
// not stored side by side): the diagonal a -> b (the sample's undrawn edge i) and its third
// corner c, the other triangle's fourth corner d (its corner k) and that triangle's corners
// in its own order and drawn edges.
struct Quad {
    i: u32,
    k: u32,
    a: vec3<f32>,
    b: vec3<f32>,
    c: vec3<f32>,
    d: vec3<f32>,
    q0: vec3<f32>,
    q1: vec3<f32>,
    q2: vec3<f32>,
    // The other triangle's corner after d is a (else b).
    same: bool,
    mask: u32,
}

fn quad_of(s: Sample, bits: u32) -> Quad {
    var q: Quad;
    let base = instances[slot(s.inst)].triangle_base;
    q.i = (bits >> QUAD_EDGE_SHIFT) & 3u;
    q.k = (bits >> QUAD_CORNER_SHIFT) & 3u;
    // The other triangle: next to this one where the store keeps a source quad's halves
    // together (no read, and its corners share a cache line with these); else across the
    // diagonal, read behind a branch so that the lanes of stored pairs skip the read.
    var n = select(s.tri - 1u, s.tri + 1u, (bits & QUAD_NEXT) != 0u);
    if (bits & (QUAD_NEXT | QUAD_PREVIOUS)) == 0u {
        n = neighbour(base + s.tri, q.i);
    }
    q.a = sample_corner(s, q.i);
    q.b = sample_corner(s, (q.i + 1u) % 3u);
    q.c = sample_corner(s, (q.i + 2u) % 3u);
    q.d = vertex_at(corner(base + n, q.k) + instances[slot(s.inst)].vertex_base).xyz;
    // d at k, then the diagonal's ends.
    q.same = (bits & QUAD_SAME) != 0u;
    let x = select(q.b, q.a, q.same);
    let y = select(q.a, q.b, q.same);
    q.q0 = select(select(y, x, q.k == 2u), q.d, q.k == 0u);
    q.q1 = select(select(x, y, q.k == 2u), q.d, q.k == 1u);
    q.q2 = select(select(x, y, q.k == 0u), q.d, q.k == 2u);
    q.mask = (bits >> QUAD_MASK_SHIFT) & 7u;
    return q;
}

// patch_distance for a patch of two triangles (a quad): the drawn edges of the sampled one
// and of the other one, across the diagonal that joins them, unless that is a silhouette.
// What the search finds, without its queue.
fn quad_distance(s: Sample, bits: u32, point: vec2<f32>) -> f32 {
    let best = drawn_segments(s.clip0, s.clip1, s.clip2, bits & 7u, point);
    let q = quad_of(s, bits);
    return min(best, across(s, q.q0, q.q1, q.q2, q.mask, q.a, q.b, q.c, point).distance);
}

// quad_distance for a pixel of tile_main, where the centre lies inside its own triangle, and
// only where the quad's four corners lie in front of the near plane (`front`; elsewhere
// refine_main measures it with quad_distance's clipping): each corner is projected once and
// each drawn edge measured as segment_distance measures it unclipped, the same arithmetic.
struct QuadFront {
    distance: f32,
    front: bool,
}

fn quad_front(s: Sample, bits: u32, point: vec2<f32>) -> QuadFront {
    let q = quad_of(s, bits);
    let cd = instances[slot(s.inst)].clip * vec4<f32>(q.d, 1.0);
    let size = frame.image_size;
    let h0 = pixel_relative(s.clip0, point, size);
    let h1 = pixel_relative(s.clip1, point, size);
    let h2 = pixel_relative(s.clip2, point, size);
    let hd = pixel_relative(cd, point, size);
    let p0 = h0.xy / h0.z;
    let p1 = h1.xy / h1.z;
    let p2 = h2.xy / h2.z;
    let pd = hd.xy / hd.z;
    let own = vec3<f32>(screen_segment_distance(p0, p1), screen_segment_distance(p1, p2), screen_segment_distance(p2, p0));
    let drawn = (vec3<u32>(bits) & vec3<u32>(1u, 2u, 4u)) != vec3<u32>(0u);
    let mine = select(vec3<f32>(NO_EDGE), own, drawn);
    var best = min(mine.x, min(mine.y, mine.z));
    // The other triangle's edges k (d -> x) and k + 2 (y -> d), x and y the diagonal's ends
    // in its order; its edge k + 1, the diagonal, is undrawn on both sides
    // (mesh_store::quad_bits).
    let pa = select(select(p2, p1, q.i == 1u), p0, q.i == 0u);
    let pb = select(select(p0, p2, q.i == 1u), p1, q.i == 0u);
    let px = select(pb, pa, q.same);
    let py = select(pa, pb, q.same);
    let first = select(NO_EDGE, screen_segment_distance(pd, px), (q.mask & (1u << q.k)) != 0u);
    let last = select(NO_EDGE, screen_segment_distance(py, pd), (q.mask & (1u << ((q.k + 2u) % 3u))) != 0u);
    if !is_silhouette(q.a, q.b, q.c, (q.q0 + q.q1 + q.q2) / 3.0, instances[slot(s.inst)].eye) {
        best = min(best, min(first, last));
    }
    let front = min(min(s.clip0.z, s.clip1.z), min(s.clip2.z, cd.z)) >= 0.0;
    return QuadFront(best, front);
}

// The breadth-first search of patch_distance from the sampled triangle `s`, for patches of
// more than two triangles: the least distance to the drawn edges of the other triangles.
// Each triangle is read once, when it joins the patch; a triangle's neighbours are read only
// across its undrawn edges, and its corners again only when one of them is new.
fn patch_search(s: Sample, point: vec2<f32>) -> f32 {
    let base = instances[slot(s.inst)].triangle_base;
    let vbase = instances[slot(s.inst)].vertex_base;
    var best = NO_EDGE;
    var queue: array<u32, PATCH_TRIANGLES>;
    queue[0] = s.tri;
    var count = 1u;
    for (var k = 0u; k < count; k++) {
        let t = queue[k];
        let mask = info[base + t] & 7u;
        // The triangles across t's undrawn edges not yet in the patch.
        var next = vec3<u32>(BACKGROUND_ID);
        var fresh = false;
        for (var i = 0u; i < 3u; i++) {
            if (mask & (1u << i)) == 0u {
                let n = neighbour(base + t, i);
                var seen = n == BACKGROUND_ID;
                for (var q = 0u; q < count; q++) {
                    seen = seen || queue[q] == n;
                }
                if !seen {
                    next[i] = n;
                    fresh = true;
                }
            }
        }
        if !fresh {
            continue;
        }
        var p = array<vec3<f32>, 3>(s.v0.xyz, s.v1.xyz, s.v2.xyz);
        if k > 0u {
            let v = corners(base + t) + vbase;
            p = array<vec3<f32>, 3>(vertex_at(v.x).xyz, vertex_at(v.y).xyz, vertex_at(v.z).xyz);
        }
        for (var i = 0u; i < 3u; i++) {
            let n = next[i];
            var seen = n == BACKGROUND_ID || count >= PATCH_TRIANGLES;
            for (var q = 0u; q < count; q++) {
                seen = seen || queue[q] == n;
            }
            if seen {
                continue;
            }
            let w = corners(base + n) + vbase;
            let q0 = vertex_at(w.x).xyz;
            let q1 = vertex_at(w.y).xyz;
            let q2 = vertex_at(w.z).xyz;
            let joined = across(s, q0, q1, q2, info[base + n] & 7u, p[i], p[(i + 1u) % 3u], p[(i + 2u) % 3u], point);
            if joined.joins {
                queue[count] = n;
                count++;
                best = min(best, joined.distance);
            }
        }
    }
    return best;
}
#endif

// The distance from the sample's point to its triangle's drawn edges (their lines), and
// whether the pixel's patch must be searched instead (PATCHES): where an undrawn edge is
// nearer than the line's reach and the drawn edges, the nearest line may lie beyond it (and
// the line of a drawn edge pass closer than the edge). A large patch's pixels there take
// their lines from the trace pass, which draws its drawn edges.
struct Own {
    distance: f32,
    search: bool,
    // The patch is a quad, measured without a search (quad_front, quad_distance).
    quad: bool,
    // The triangle's `info`.
    info: u32,
}

fn own_lines(s: Sample, point: vec2<f32>) -> Own {
    let flags = instances[slot(s.inst)].flags;
    let bits = info[instances[slot(s.inst)].triangle_base + s.tri];
    // Patterned edges, those of crossed patches and those near where another instance
    // crosses this one are drawn by the trace pass.
    var crossed = false;
#if CROSSINGS
    // A loop, not an `if` (see `finish`).
    for (var near = (flags & INSTANCE_CROSSED) != 0u; near; near = false) {
        crossed = in_box(instances[slot(s.inst)].cross_box, point);
    }
#endif
    let edges = (flags & (INSTANCE_EDGES | INSTANCE_LISTED_EDGES)) == INSTANCE_EDGES && (bits & INFO_CROSSED) == 0u && !crossed;
    let mask = select(0u, bits & 7u, edges);
    let near = vec3<f32>(s.clip0.z, s.clip1.z, s.clip2.z);
    let d = drawn_distances(s.lines, near, mask);
    var own = Own(min(d.x, min(d.y, d.z)), false, false, bits);
    let u = drawn_distances(s.lines, near, ~mask & 7u);
    let reach = line_reach(instances[slot(s.inst)].line_width);
    let beyond = edges && min(u.x, min(u.y, u.z)) < min(own.distance, reach);
    let large = (bits & INFO_LARGE_PATCH) != 0u;
    if beyond && large {
        own.distance = NO_EDGE;
    }
#if PATCHES
    own.search = beyond && !large;
    own.quad = (bits & INFO_QUAD) != 0u;
#endif
    return own;
}

// A pixel whose centre triangle `s` covers, `own` pixels from a line of its own triangle or
// patch: the stronger of that line and the trace pass's colours it, equal ones going to the
// nearer.
fn surface_pixel(xy: vec2<u32>, s: Sample, own: f32) -> Pixel {
    var p: Pixel;
    p.inst = s.inst;
    p.tri = s.tri;
    let outline = outline_at(xy);
    let inst = s.inst;
    let b = s.bary;
    let local = b.x * s.v0.xyz + b.y * s.v1.xyz + b.z * s.v2.xyz;
    let view_depth = dot(instances[slot(inst)].fade_row, vec4<f32>(local, 1.0));
    let own_line = line_intensity(own, instances[slot(inst)].line_width) * depth_fade(view_depth, frame.fade);
    var own_key = 0u;
    if own < NO_EDGE {
        own_key = line_key(own_line, own);
    }
    let n = b.x * unpack_normal(bitcast<u32>(s.v0.w)) + b.y * unpack_normal(bitcast<u32>(s.v1.w)) + b.z * unpack_normal(bitcast<u32>(s.v2.w));
    let face = cross(s.v1.xyz - s.v0.xyz, s.v2.xyz - s.v0.xyz);
    p.surface = surface_color(frame, instances[slot(inst)], local, n, face);
    // A back face seen through a section's cut is the section face: its outward normal
    // against the eye, in the instance's own space, where the winding is the mesh's whatever
    // the transform mirrors.
    let eye = instances[slot(inst)].eye;
    let back = dot(face, eye.xyz - local * eye.w) < 0.0;
    p.surface = select(p.surface, frame.section_color.rgb, back && frame.sections_on != 0u);
    p.depth = s.depth;
    if own_key >= outline.x {
        p.distance = own;
        p.line = own_line;
        p.wire = instances[slot(inst)].wire_color;
        p.kind = LINE_CLASS_EDGE;
    } else {
        p.distance = key_distance(outline.x);
        p.line = key_intensity(outline.x);
        p.wire = owner_color(outline.y);
        p.kind = owner_kind(outline.y);
    }
    return p;
}

// Writes pixel `p` of target pixel `xy` into the output: the visible line over the hidden
// line, over the surface at its opacity, over what is below.
fn store_pixel(xy: vec2<u32>, p: Pixel) {
    let out = xy - vec2<u32>(frame.output_offset);
    let i = p.line * p.wire.a;
    let hidden_key = hidden_at(xy);
#if HIDDEN
#if COLORS
    let hidden_color = hidden_color_of(hidden_key.y);
#else
    let hidden_color = frame.hidden_color;
#endif
    let h = key_intensity(hidden_key.x) * hidden_color.a;
    let hidden = hidden_color.rgb;
#endif
#if MODE_SHADE
    var base = frame.background;
    if p.inst < HOST_ID {
        // The background's colour, premultiplied, under a see-through surface.
        base = see_through(p.surface, vec4<f32>(base.rgb * base.a, base.a), frame.fill_opacity);
        base = vec4<f32>(base.rgb / max(base.a, 1e-30), base.a);
    }
#if HIDDEN
    base = vec4<f32>(mix(base.rgb, hidden, h), max(base.a, h));
#endif
    textureStore(out_color, out, encode_output(vec4<f32>(mix(base.rgb, p.wire.rgb, i), max(base.a, i))));
#endif
#if MODE_OVERLAY
    var host = textureLoad(host_color, out, 0);
#if HOST_ENCODED
    host = vec4<f32>(srgb_to_linear(host.rgb), host.a);
#endif
#if HIDDEN
    host = vec4<f32>(mix(host.rgb, hidden, h), max(host.a, h));
#endif
    textureStore(out_color, out, encode_output(vec4<f32>(mix(host.rgb, p.wire.rgb, i), max(host.a, i))));
#endif
#if MODE_RESULT
    var color = vec4<f32>(p.wire.rgb * i, i);
#if HIDDEN
    color += vec4<f32>(hidden * h, h) * (1.0 - i);
#endif
#if SHADED
    if p.inst < HOST_ID {
        var surface = p.surface;
#if HIDDEN
        surface = mix(surface, hidden, h);
#endif
        // Premultiplied where the surface is see-through: the surface at its opacity, the
        // hidden line over it, the line over both; the host's image shows through what is
        // left. (A select, not an if on the uniform: lavapipe specialises a pipeline again
        // at every dispatch for a branch on uniform values alone.)
        var under = see_through(p.surface, vec4<f32>(0.0), frame.fill_opacity);
#if HIDDEN
        under = under * (1.0 - h) + vec4<f32>(hidden * h, h);
#endif
        let opaque = vec4<f32>(mix(surface, p.wire.rgb, i), 1.0);
        color = select(under * (1.0 - i) + vec4<f32>(p.wire.rgb * i, i), opaque, frame.fill_opacity >= 1.0);
    }
#endif
    textureStore(out_color, out, color);
#endif
#if MODE_DIAGNOSTIC
    // b: the distance to the hidden line that colours the pixel (NO_EDGE for none); a: the
    // class of the line that colours it most (the visible one where they tie).
    var kind = select(0u, p.kind, i > 0.0);
#if HIDDEN
    kind = select(kind, LINE_CLASS_HIDDEN, h > i);
#endif
    textureStore(out_diagnostic, out, vec4<f32>(p.distance, p.depth, key_distance(hidden_key.x), f32(kind)));
    textureStore(out_ids, out, vec4<u32>(p.inst, p.tri, 0u, 0u));
#endif
}

fn no_sample(inst: u32) -> Sample {
    var s: Sample;
    s.inst = inst;
    s.tri = 0u;
    s.covers = false;
    return s;
}

// Pixels without a triangle, without lines (those over the background are traced_main's).
// Background next to foreground is written here too; classify_main listed it for
// refine_main, which decides it.
@compute @workgroup_size(8, 8)
fn background_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let xy = gid.xy + vec2<u32>(frame.output_offset);
    let raster = textureLoad(ids, xy, 0).x;
    if all(vec2<f32>(gid.xy) < frame.output_size) && raster >= HOST_ID {
        store_pixel(xy, empty_pixel(xy, raster, vec2<u32>(0u)));
    }
}

// Whether output pixel `at` (in output coordinates, clamped to the output) shows a triangle.
fn foreground_at(at: vec2<i32>) -> bool {
    let q = clamp(at, vec2<i32>(0), vec2<i32>(frame.output_size) - 1) + vec2<i32>(frame.output_offset);
    return textureLoad(ids, vec2<u32>(q), 0).x < HOST_ID;
}

// Half of a tile as bits: bit 8 × row + column of rows 0-3 (x) and 4-7 (y).
// `bits` (bit i for row i) placed in column `column`.
fn tile_column(bits: u32, column: u32) -> vec2<u32> {
    var out = vec2<u32>(0u);
    for (var row = 0u; row < 4u; row++) {
        out.x |= ((bits >> row) & 1u) << (8u * row + column);
        out.y |= ((bits >> (row + 4u)) & 1u) << (8u * row + column);
    }
    return out;
}

// One invocation per 8×8 output tile, from its ids and those of the ring of pixels
// edge-adjacent to it (bit masks, so each pixel's four neighbours cost no reads): lists the
// tile for tile_main if it holds foreground, and lists for refine_main its background
// pixels next to foreground, which may hold a triangle the rasterizer missed (border_main
// lists the background next to foreground in the guard band). Reads cost a lane per tile
// less than a lane per pixel, and the lists' atomics are paid once a tile.
// In the result mode it also lists the composite's runs of drawn tiles
// (`list_composite_runs`), a workgroup's rows of tiles at a time.
@compute @workgroup_size(CLASSIFY_COLUMNS, CLASSIFY_ROWS)
fn classify_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_id) local: vec3<u32>) {
    var drawn = false;
    if all(vec2<f32>(8u * gid.xy) < frame.output_size) {
        drawn = classify_tile(gid.xy);
    }
#if MODE_RESULT
    list_composite_runs(gid.xy, local.xy, drawn);
#endif
}

#if MODE_RESULT
// Whether each tile of the workgroup's is drawn by the composite.
var<workgroup> drawn_tiles: array<u32, CLASSIFY_COLUMNS * CLASSIFY_ROWS>;

// Lists for composite.wgsl the runs of drawn tiles along each row of the workgroup's tiles,
// a run an instance (tile x | (length - 1) << COMPOSITE_RUN_SHIFT | tile y << 16): a
// software rasterizer sets up every triangle it draws, and a run of up to CLASSIFY_COLUMNS
// tiles costs it what one tile does.
fn list_composite_runs(tile: vec2<u32>, local: vec2<u32>, drawn: bool) {
    let row = CLASSIFY_COLUMNS * local.y;
    drawn_tiles[row + local.x] = select(0u, 1u, drawn);
    workgroupBarrier();
    if all(tile == vec2<u32>(0u)) {
        atomicStore(&composite_rw.vertices, 6u);
    }
    if drawn && (local.x == 0u || drawn_tiles[row + local.x - 1u] == 0u) {
        var length = 1u;
        for (var k = local.x + 1u; k < CLASSIFY_COLUMNS; k++) {
            if drawn_tiles[row + k] == 0u {
                break;
            }
            length++;
        }
        let k = atomicAdd(&composite_rw.tiles, 1u);
        atomicStore(&composite_rw.items[k], tile.x | ((length - 1u) << COMPOSITE_RUN_SHIFT) | (tile.y << 16u));
    }
}
#endif

// classify_main's work for one output tile inside the output; whether the composite draws
// it (foreground, background the refine dispatch decides, the trace pass's lines).
fn classify_tile(tile: vec2<u32>) -> bool {
    let first = vec2<i32>(8u * tile);
    // The tile's columns and rows inside the output, a bit each.
    let room = vec2<i32>(frame.output_size) - first;
    let columns = select(0xffu, (1u << u32(room.x)) - 1u, room.x < 8);
    let rows = select(0xffu, (1u << u32(room.y)) - 1u, room.y < 8);
    // Pixels inside the output (tile_column's layout), and the foreground among them.
    var inside = vec2<u32>(0u);
    for (var row = 0u; row < 4u; row++) {
        inside.x |= select(0u, columns << (8u * row), (rows & (1u << row)) != 0u);
        inside.y |= select(0u, columns << (8u * row), (rows & (16u << row)) != 0u);
    }
    var fg = vec2<u32>(0u);
    for (var k = 0u; k < 32u; k++) {
        let at = first + vec2<i32>(vec2<u32>(k % 8u, k / 8u));
        fg |= select(vec2<u32>(0u), vec2<u32>(1u << k), vec2<bool>(foreground_at(at), foreground_at(at + vec2<i32>(0, 4))));
    }
    fg &= inside;
    // The ring: bit i of each side is its pixel in row or column i, where inside the output.
    var top = 0u;
    var bottom = 0u;
    var left = 0u;
    var right = 0u;
    for (var i = 0; i < 8; i++) {
        let bit = 1u << u32(i);
        top |= select(0u, bit, foreground_at(first + vec2<i32>(i, -1)));
        bottom |= select(0u, bit, foreground_at(first + vec2<i32>(i, 8)));
        left |= select(0u, bit, foreground_at(first + vec2<i32>(-1, i)));
        right |= select(0u, bit, foreground_at(first + vec2<i32>(8, i)));
    }
    top &= select(0u, columns, first.y > 0);
    bottom &= select(0u, columns, room.y > 8);
    left &= select(0u, rows, first.x > 0);
    right &= select(0u, rows, room.x > 8);
    // Pixels whose left, right, upper or lower neighbour is foreground.
    let from_left = ((fg << vec2<u32>(1u)) & vec2<u32>(0xfefefefeu)) | tile_column(left, 0u);
    let from_right = ((fg >> vec2<u32>(1u)) & vec2<u32>(0x7f7f7f7fu)) | tile_column(right, 7u);
    let from_above = vec2<u32>((fg.x << 8u) | (top & 0xffu), (fg.y << 8u) | (fg.x >> 24u));
    let from_below = vec2<u32>((fg.x >> 8u) | (fg.y << 24u), (fg.y >> 8u) | (bottom << 24u));
    var listed = (from_left | from_right | from_above | from_below) & inside & ~fg;
    // Whether the tile's result may be other than transparent (only the result mode asks).
    var drawn = any((fg | listed) != vec2<u32>(0u));
#if MODE_RESULT
#if TRACED
    let columns_out = (u32(frame.output_size.x) + 7u) / 8u;
    drawn = drawn || acc[traced_tile_marks() + tile.y * columns_out + tile.x] != 0u;
#endif
#endif
    if any(fg != vec2<u32>(0u)) {
        let k = atomicAdd(&tiles_rw.count, 1u);
        atomicStore(&tiles_rw.items[k], tile.x | (tile.y << 16u));
        let size = list_size(k, 1u);
        atomicMax(&tiles_rw.x, size.x);
        atomicMax(&tiles_rw.y, size.y);
    }
    let n = countOneBits(listed.x) + countOneBits(listed.y);
    if n != 0u {
        var k = atomicAdd(&work_rw.count, n);
        let size = list_size(k + n - 1u, 64u);
        atomicMax(&work_rw.x, size.x);
        atomicMax(&work_rw.y, size.y);
        let origin = vec2<u32>(first) + vec2<u32>(frame.output_offset);
        // A loop ends once no lane has pixels left, so tiles without any cost nearly nothing.
        while any(listed != vec2<u32>(0u)) {
            let half = select(1u, 0u, listed.x != 0u);
            let bits = listed[half];
            let b = firstTrailingBit(bits);
            listed[half] = bits & (bits - 1u);
            let xy = origin + vec2<u32>(b % 8u, b / 8u + 4u * half);
            atomicStore(&work_rw.items[k], xy.x | (xy.y << 16u));
            k++;
        }
    }
    return drawn;
}

#if TRACED
// The trace pass's lines over the background and host pixels of the tiles they reach.
@compute @workgroup_size(8, 8)
fn traced_main(@builtin(local_invocation_id) local: vec3<u32>, @builtin(workgroup_id) group: vec3<u32>) {
    let list = traced_tile_list();
    let t = list_group(group);
    if t < acc[list + 3u] {
        let tile = acc[list + 4u + t];
        let at = vec2<u32>(tile & 0xffffu, tile >> 16u) * 8u + local.xy;
        let xy = at + vec2<u32>(frame.output_offset);
        let raster = textureLoad(ids, xy, 0).x;
        if all(vec2<f32>(at) < frame.output_size) && raster >= HOST_ID {
            store_pixel(xy, empty_pixel(xy, raster, outline_at(xy)));
        }
    }
}
#endif

// Edge-adjacent pixel i (left, right, up, down) of a pixel, as an offset.
fn neighbour_offset(i: u32) -> vec2<i32> {
    let d = select(-1, 1, (i & 1u) != 0u);
    return select(vec2<i32>(0, d), vec2<i32>(d, 0), i < 2u);
}

// Appends target pixel xy to the refine list (each pixel is listed by one invocation only).
fn refine_later(xy: vec2<u32>) {
    let k = atomicAdd(&work_rw.count, 1u);
    atomicStore(&work_rw.items[k], xy.x | (xy.y << 16u));
    let size = list_size(k, 64u);
    atomicMax(&work_rw.x, size.x);
    atomicMax(&work_rw.y, size.y);
}

// The background on the output's border next to foreground in the guard band, which no
// listed tile lists (tile_main lists the background beside its own foreground): one
// invocation per border pixel (top row, bottom row, left column, right column) lists it for
// refine_main.
@compute @workgroup_size(64)
fn border_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = vec2<u32>(frame.output_size);
    let k = gid.x;
    var at = vec2<u32>(k, 0u);
    if k >= 2u * (size.x + size.y) {
        return;
    } else if k >= 2u * size.x + size.y {
        at = vec2<u32>(size.x - 1u, k - 2u * size.x - size.y);
    } else if k >= 2u * size.x {
        at = vec2<u32>(0u, k - 2u * size.x);
    } else if k >= size.x {
        at = vec2<u32>(k - size.x, size.y - 1u);
    }
    let q = vec2<i32>(at + vec2<u32>(frame.output_offset));
    if id_at(q).x < HOST_ID {
        return;
    }
    let first = vec2<i32>(frame.output_offset);
    let last = vec2<i32>(frame.output_offset + frame.output_size) - 1;
    var beyond = false;
    for (var i = 0u; i < 4u; i++) {
        let n = q + neighbour_offset(i);
        let outside = any(n < first) || any(n > last);
        if id_at(n).x < HOST_ID {
            // Foreground inside the output: classify_main lists this pixel.
            if !outside {
                return;
            }
            beyond = true;
        }
    }
    if beyond {
        refine_later(vec2<u32>(q));
    }
}

@compute @workgroup_size(8, 8)
fn tile_main(@builtin(local_invocation_id) local: vec3<u32>, @builtin(workgroup_id) group: vec3<u32>) {
    let t = list_group(group);
    if t < tiles.count {
        let tile = tiles.items[t];
        let at = vec2<u32>(tile & 0xffffu, tile >> 16u) * 8u + local.xy;
        let xy = at + vec2<u32>(frame.output_offset);
        let raster = textureLoad(ids, xy, 0).xy;
        // Background pixels were finished by background_main or the clear.
        let foreground = all(vec2<f32>(at) < frame.output_size) && raster.x < HOST_ID;
        // Memory reads are skipped for masked lanes, so background lanes do not sample.
        var s = no_sample(raster.x);
        if foreground {
            s = sample(raster.x, raster.y, pixel_centre(xy));
        }
        let certain = foreground && s.covers && s.margin >= COVERAGE_MARGIN;
        var own = Own(NO_EDGE, false, false, 0u);
        if certain {
            own = own_lines(s, pixel_centre(xy));
#if PATCHES
            // Near a quad's diagonal the other triangle's edges count too; larger polygons
            // (rarer, and the search's queue would slow every quad) are searched by
            // refine_main.
            if own.search && own.quad {
                let quad = quad_front(s, own.info, pixel_centre(xy));
                own.distance = quad.distance;
                // Cut by the near plane: refine_main clips.
                own.quad = quad.front;
            }
#endif
            if !own.search || own.quad {
                store_pixel(xy, surface_pixel(xy, s, own.distance));
            }
        }
        // The pixel goes to refine_main where the exact test could not decide it or its patch
        // must be searched (classify_main lists the background next to it).
        if foreground && (!certain || (own.search && !own.quad)) {
            refine_later(xy);
        }
    }
}

// The pixel's line and surface, given the triangle that covers its centre (`s.inst` is
// BACKGROUND_ID or HOST_ID for none).
fn finish(xy: vec2<u32>, s: Sample) -> Pixel {
    if s.inst < HOST_ID {
        var own = own_lines(s, pixel_centre(xy));
#if PATCHES
        // A loop, not an `if`: a software rasterizer skips a loop no lane enters, but runs
        // the body of an `if` for every lane.
        for (var search = own.search; search; search = false) {
            own.distance = patch_distance(s, pixel_centre(xy));
        }
#endif
        return surface_pixel(xy, s, own.distance);
    }
    return empty_pixel(xy, s.inst, outline_at(xy));
}

// Steps of the walks from the neighbourhood's triangles towards a background pixel's centre.
// The rasterizer covered none of them there, so a triangle that covers the centre exactly
// does so within its snapping error of its boundary (COVERAGE_MARGIN), on the rim of the
// mesh's image next to a neighbour's triangle. Wherever measured (meshes of 2 k to 20 M
// triangles, near, far and grazing cameras) every such owner lay within two steps. Twice
// that bounds the walks, which at millions of sub-pixel triangles would otherwise wander up
// to WALK_STEPS each over the surface towards its silhouette, the slowest lane holding up
// its batch.
const BACKGROUND_WALK_STEPS: u32 = 4u;

// The triangle whose surface the centre of target pixel `xy` sees, for a pixel `tile_main`
// could not decide: the nearest of the triangles covering the centre among the rasterizer's
// triangle, the 3×3 neighbourhood's, and those a walk from them reaches (the walk from the
// neighbours only when the pixel itself is background). If none covers it, the pixel is
// background where background is next to it, and keeps the rasterizer's triangle otherwise
// (the true one is out of reach). Where the host gave its depth, a triangle must also be
// nearer than the host's surface at the centre.
fn resolve(xy: vec2<u32>) -> Sample {
    let point = pixel_centre(xy);
    let host = host_at(vec2<i32>(xy));
    let raster = textureLoad(ids, xy, 0).xy;
    let raster_empty = raster.x >= HOST_ID;
    // The nearest covering triangle so far (its full sample is taken once, at the end, so
    // that the candidates' line distances are never computed).
    var best = vec2<u32>(raster.x, 0u);
    var best_near = 0.0;
    var found = false;
    var background_near = raster_empty;
    var checked = raster;
    for (var k = 0; k < 10; k++) {
        var id = raster;
        var steps = WALK_STEPS;
        if k > 0 {
            let q = vec2<i32>(xy) + vec2<i32>((k - 1) % 3 - 1, (k - 1) / 3 - 1);
            id = id_at(q);
            background_near = background_near || id.x >= HOST_ID;
            if all(id == raster) || all(id == checked) {
                continue;
            }
            checked = id;
            steps = select(0u, BACKGROUND_WALK_STEPS, raster_empty);
        }
        if id.x >= HOST_ID {
            continue;
        }
        let s = locate(id.x, id.y, point, steps, true);
        if s.covers && s.depth > host && (!found || s.near < best_near) {
            best = vec2<u32>(s.inst, s.tri);
            best_near = s.near;
            found = true;
        }
    }
    if !found && !background_near {
        return sample(raster.x, raster.y, point);
    }
    if !found {
        return no_sample(raster.x);
    }
    return sample(best.x, best.y, point);
}

@compute @workgroup_size(64)
fn refine_main(@builtin(local_invocation_index) lane: u32, @builtin(workgroup_id) group: vec3<u32>) {
    let k = list_group(group) * 64u + lane;
    if k < work.count {
        let item = work.items[k];
        let xy = vec2<u32>(item & 0xffffu, item >> 16u);
        store_pixel(xy, finish(xy, resolve(xy)));
    }
}
