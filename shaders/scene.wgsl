// The scene as the compute passes see it: the frame, the instances, the mesh store and the
// id target, with the exact test of one triangle at one screen point. Assembled after
// common.wgsl, before the trace and edge passes.
//
// Flags: SPLIT (the store's vertex and per-triangle buffers are bound as two halves each),
// UNIFORM_INSTANCES (the frame's instance records fit a uniform buffer) and ONE_INSTANCE (the
// frame has one instance).

@group(0) @binding(0) var<uniform> frame: Frame;
#if UNIFORM_INSTANCES
// Few instances: a uniform buffer. Software rasterizers read uniform buffers with plain
// gathers, or once for all lanes at a constant index, but storage buffers lane by lane.
@group(0) @binding(18) var<uniform> instances: array<Instance, UNIFORM_INSTANCE_CAPACITY>;
#else
@group(0) @binding(1) var<storage, read> instances: array<Instance>;
#endif

// Indirect dispatches over a list that a pass appends to are LIST_WIDTH workgroups wide and
// as many rows as the list needs, each workgroup taking its own item (or its own `per`
// items). A loop over the list instead costs a software rasterizer far more.
const LIST_WIDTH: u32 = 256u;

// The least dispatch size (x, y) of a list whose item k is there, one workgroup per `per`
// items.
fn list_size(k: u32, per: u32) -> vec2<u32> {
    let group = k / per;
    return vec2<u32>(min(group + 1u, LIST_WIDTH), group / LIST_WIDTH + 1u);
}

// The list index of workgroup `group` of an indirect dispatch sized by `list_size`.
fn list_group(group: vec3<u32>) -> u32 {
    return group.y * LIST_WIDTH + group.x;
}

// The trace buffer (`acc` in the edge pass, `acc_rw` in the trace pass; sized by
// src/gpu/targets.rs): the trace pass's line per target pixel (one word, two with COLORS),
// with HIDDEN its hidden line per target pixel (`hidden_lines`), then a mark per 8×8 output
// tile its lines reach, then the list of those tiles (a list header as `list_size` fills it,
// then one packed tile per item), then the phase tables (`chain_phases`), then its list of
// pieces.
fn traced_tile_count() -> u32 {
    let size = vec2<u32>(frame.output_size);
    return ((size.x + 7u) / 8u) * ((size.y + 7u) / 8u);
}

// The class bits of the trace pass's owner word (COLORS: intensity level << 20 | class
// bits | instance slot): an outline's line (the instance's outline colour, not its line
// colour), a section's cut line (the frame's section line colour), both for an
// intersection line (the frame's intersection line colour; of equal intensity, it wins
// over the others); then the slot's bits (OWNER_*, from src/gpu/shaders.rs).
// The colour of the trace pass's line whose owner word is `owner`: the owning instance's
// outline colour for an outline, the section line colour for a cut line, the intersection
// line colour for an intersection line, its line colour for a drawn edge.
fn owner_color(owner: u32) -> vec4<f32> {
    let i = slot(owner & OWNER_INSTANCE);
    let kind = owner & OWNER_CLASS;
    var line = select(instances[i].wire_color, frame.section_line_color, kind == OWNER_CUT);
    line = select(line, unpack_color(instances[i].outline_color), kind == OWNER_OUTLINE);
    return select(line, frame.intersection_line_color, kind == OWNER_INTERSECTION);
}

// Word offset of the hidden lines (HIDDEN): the greatest `line_key` per target pixel (with
// COLORS, and its owner word, as the lines' are: `hidden_color_of`).
fn hidden_lines() -> u32 {
    let pixels = u32(frame.target_size.x) * u32(frame.target_size.y);
#if COLORS
    return 2u * pixels;
#else
    return pixels;
#endif
}

// The colour of the hidden line whose owner word (COLORS) is `owner`.
fn hidden_color_of(owner: u32) -> vec4<f32> {
    return unpack_color(instances[slot(owner & OWNER_INSTANCE)].hidden_color);
}

// Word offset of the tile marks.
fn traced_tile_marks() -> u32 {
#if HIDDEN
    // The hidden lines take as many words as the lines.
    return 2u * hidden_lines();
#else
    return hidden_lines();
#endif
}

// Word offset of the tile list's header.
fn traced_tile_list() -> u32 {
    return traced_tile_marks() + traced_tile_count();
}

// Where instance slot `i`'s record is read: with ONE_INSTANCE always slot 0, a constant
// index, so every lane reads the same record (background ids fold to it too).
fn slot(i: u32) -> u32 {
#if ONE_INSTANCE
    return 0u;
#else
    return i;
#endif
}

// Per vertex: local position (xyz) and the packed normal's bits (w).
@group(0) @binding(2) var<storage, read> vertices: array<vec4<f32>>;
#if SPLIT
@group(0) @binding(3) var<storage, read> vertices_hi: array<vec4<f32>>;
#endif
// Three vertex indices per triangle, relative to the mesh's first vertex.
@group(0) @binding(4) var<storage, read> indices: array<u32>;
#if SPLIT
@group(0) @binding(5) var<storage, read> indices_hi: array<u32>;
#endif
// Per edge (edge i = corner i -> i+1), the triangle across it (mesh_store::neighbour_word):
// bits 0-28 its index relative to the mesh's first triangle, bits 29-30 its corner off the
// shared edge, bit 31 set where it runs along that edge the same way; BACKGROUND_ID (all
// ones) for boundary and non-manifold edges.
@group(0) @binding(6) var<storage, read> neighbours: array<u32>;
#if SPLIT
@group(0) @binding(7) var<storage, read> neighbours_hi: array<u32>;
#endif
// Per triangle (src/gpu/mesh_store.rs, triangle_info): bits 0-2 the drawn edges, bit 3 a
// boundary edge, bits 4-7 the fold code, bits 8-10 the edges that may be outlines, bits
// 11-23 what the edge pass needs of its patch (mesh_store::EdgeData::info).
@group(0) @binding(8) var<storage, read> info: array<u32>;
// (instance slot, triangle of its mesh) per target pixel; BACKGROUND_ID or HOST_ID in x.
@group(0) @binding(10) var ids: texture_2d<u32>;
#if HOST
// The host's own reverse depth per target pixel, as bits; 0xffffffff where it has no
// geometry (src/gpu/host.rs).
@group(0) @binding(17) var host_depth: texture_2d<u32>;
#endif

fn vertex_at(v: u32) -> vec4<f32> {
#if SPLIT
    if v >= frame.vertex_split {
        return vertices_hi[v - frame.vertex_split];
    }
#endif
    return vertices[v];
}

// Vertex index of corner k of the store's triangle t (relative to its mesh's first vertex).
fn corner(t: u32, k: u32) -> u32 {
#if SPLIT
    if t >= frame.triangle_split {
        return indices_hi[3u * (t - frame.triangle_split) + k];
    }
#endif
    return indices[3u * t + k];
}

// Vertex indices of the store's triangle t (relative to its mesh's first vertex).
fn corners(t: u32) -> vec3<u32> {
    return vec3<u32>(corner(t, 0u), corner(t, 1u), corner(t, 2u));
}

// The neighbour word of edge i of the store's triangle t.
fn neighbour_word(t: u32, i: u32) -> u32 {
#if SPLIT
    if t >= frame.triangle_split {
        return neighbours_hi[3u * (t - frame.triangle_split) + i];
    }
#endif
    return neighbours[3u * t + i];
}

// The triangle a neighbour word names (relative to its mesh), or BACKGROUND_ID.
fn neighbour_of(word: u32) -> u32 {
    return select(word & NEIGHBOUR_INDEX, BACKGROUND_ID, word == BACKGROUND_ID);
}

// The triangle across edge i of the store's triangle t (relative to its mesh), or
// BACKGROUND_ID.
fn neighbour(t: u32, i: u32) -> u32 {
    return neighbour_of(neighbour_word(t, i));
}

// The triangle across an edge a -> b of another one, from the edge's neighbour word and the
// store's corner data: its index (relative to its mesh) and its corners in its own order.
// It shares a and b, so only its corner off the edge is read.
struct Beyond {
    tri: u32,
    q0: vec4<f32>,
    q1: vec4<f32>,
    q2: vec4<f32>,
}

fn beyond_edge(inst: u32, word: u32, a: vec4<f32>, b: vec4<f32>) -> Beyond {
    var out: Beyond;
    out.tri = word & NEIGHBOUR_INDEX;
    let k = (word >> NEIGHBOUR_CORNER_SHIFT) & 3u;
    let base = instances[slot(inst)].triangle_base;
    let d = vertex_at(corner(base + out.tri, k) + instances[slot(inst)].vertex_base);
    // Its corners k + 1 and k + 2: the edge's start and end where it runs the same way.
    let same = (word & NEIGHBOUR_SAME_WAY) != 0u;
    let first = select(b, a, same);
    let second = select(a, b, same);
    out.q0 = select(select(first, second, k == 1u), d, k == 0u);
    out.q1 = select(select(second, first, k == 0u), d, k == 1u);
    out.q2 = select(select(first, second, k == 0u), d, k == 2u);
    return out;
}

// The id target at a target pixel, clamped to the targets.
fn id_at(q: vec2<i32>) -> vec2<u32> {
    let last = vec2<i32>(frame.target_size) - 1;
    return textureLoad(ids, vec2<u32>(clamp(q, vec2<i32>(0), last)), 0).xy;
}

// The host's reverse depth at target pixel q, or -1 where the host has no geometry there
// (or gave no depth).
fn host_at(q: vec2<i32>) -> f32 {
#if HOST
    let last = vec2<i32>(frame.target_size) - 1;
    let v = textureLoad(host_depth, vec2<u32>(clamp(q, vec2<i32>(0), last)), 0).x;
    if v != 0xffffffffu {
        return bitcast<f32>(v);
    }
#endif
    return -1.0;
}

// The host's reverse depth at target pixel q and its slope there (host_slope); x < 0 where the
// host has no geometry.
fn host_pixel(q: vec2<i32>) -> vec2<f32> {
    let h = host_at(q);
    let x = vec2<i32>(1, 0);
    let y = vec2<i32>(0, 1);
    return vec2<f32>(h, host_slope(h, host_at(q - x), host_at(q + x), host_at(q - y), host_at(q + y)));
}

// host_pixel where q shows the host (its surface nearer there than every instance's); x < 0
// elsewhere. Where an instance shows, the host hides nothing drawn there: not even the host's
// own copy of that instance, just behind its surface.
fn host_shown(q: vec2<i32>) -> vec2<f32> {
#if HOST
    if id_at(q).x == HOST_ID {
        return host_pixel(q);
    }
#endif
    return vec2<f32>(-1.0, 0.0);
}

// Whether the host hides a point of an edge at target-space point x, of reverse depth
// `point`: the pixel containing x shows the host, and the host there is clearly nearer
// (host_hides).
fn host_hides_point(x: vec2<f32>, point: f32) -> bool {
    return host_hides_line(vec2<i32>(floor(x)), point, 0.0);
}

// Whether the host hides, in target pixel q, the line of a point of reverse depth `point`
// that lies `distance` pixels from q's centre: q shows the host, and the host there is
// clearly nearer than the point (host_hides).
fn host_hides_line(q: vec2<i32>, point: f32, distance: f32) -> bool {
#if HOST
    let shown = host_shown(q);
    return shown.x >= 0.0 && host_hides(shown.x, point, distance, shown.y);
#else
    return false;
#endif
}

// Full-image coordinates of a target pixel's centre.
fn pixel_centre(xy: vec2<u32>) -> vec2<f32> {
    return vec2<f32>(xy) + frame.target_origin + 0.5;
}

// Pixels whose centre lies within this many pixels of their triangle's boundary are checked
// against the triangles of their 3×3 neighbourhood. Rasterizers snap vertices to a sub-pixel
// grid (8 bits on lavapipe, llvmpipe and desktop GPUs: each coordinate off by up to 1/512
// px, so an edge's line by up to √2/512 ≈ 0.0028 px), so such a centre may have been given
// to the wrong side of an edge; the exact test decides. The margin leaves 40 % on top of
// that for the f32 rounding of both tests.
const COVERAGE_MARGIN: f32 = 1.0 / 256.0;

// One triangle of one instance seen from one screen point.
struct Sample {
    inst: u32,
    // The triangle, relative to its mesh.
    tri: u32,
    // Corners: local position and packed normal.
    v0: vec4<f32>,
    v1: vec4<f32>,
    v2: vec4<f32>,
    // Corners in clip space (rows x, y, near, w).
    clip0: vec4<f32>,
    clip1: vec4<f32>,
    clip2: vec4<f32>,
    // Screen lines of the three edges, relative to the point (see `edge_eval`).
    l0: vec3<f32>,
    l1: vec3<f32>,
    l2: vec3<f32>,
    bary: vec3<f32>,
    // The point's ray hits the triangle between the near and far planes, where no section
    // plane cuts it away.
    covers: bool,
    // Distances from the point to the three edge lines, drawn or not.
    lines: vec3<f32>,
    // The smallest of them.
    margin: f32,
    // Near row and w of the hit point: along one ray, a smaller near row is nearer.
    near: f32,
    w: f32,
    // Reverse depth of the hit point (1 at the near plane, 0 at the far plane).
    depth: f32,
}

fn sample(inst: u32, tri: u32, point: vec2<f32>) -> Sample {
    let v = corners(instances[slot(inst)].triangle_base + tri) + instances[slot(inst)].vertex_base;
    return sample_corners(inst, tri, vertex_at(v.x), vertex_at(v.y), vertex_at(v.z), point);
}

// `sample` of a triangle whose corners (v0, v1, v2, in its own order) are already read.
fn sample_corners(inst: u32, tri: u32, v0: vec4<f32>, v1: vec4<f32>, v2: vec4<f32>, point: vec2<f32>) -> Sample {
    var s: Sample;
    s.inst = inst;
    s.tri = tri;
    let clip = instances[slot(inst)].clip;
    let depth_row = instances[slot(inst)].depth_row;
    s.v0 = v0;
    s.v1 = v1;
    s.v2 = v2;
    let h0 = vec4<f32>(s.v0.xyz, 1.0);
    let h1 = vec4<f32>(s.v1.xyz, 1.0);
    let h2 = vec4<f32>(s.v2.xyz, 1.0);
    s.clip0 = clip * h0;
    s.clip1 = clip * h1;
    s.clip2 = clip * h2;
    let p0 = pixel_relative(s.clip0, point, frame.image_size);
    let p1 = pixel_relative(s.clip1, point, frame.image_size);
    let p2 = pixel_relative(s.clip2, point, frame.image_size);
    s.l0 = cross(p0, p1);
    s.l1 = cross(p1, p2);
    s.l2 = cross(p2, p0);
    let e = vec3<f32>(s.l1.z, s.l2.z, s.l0.z);
    let sum = e.x + e.y + e.z;
    s.bary = select(vec3<f32>(-1.0), e / sum, sum != 0.0);
    let b = s.bary;
    let hit = b.x * s.clip0 + b.y * s.clip1 + b.z * s.clip2;
    let r = b.x * dot(depth_row, h0) + b.y * dot(depth_row, h1) + b.z * dot(depth_row, h2);
    // Not cut away by a section plane (the visibility pass's test, at this point).
    let sides = section_sides(frame, hit);
    let kept = all(sides.a >= vec4<f32>(0.0)) && all(sides.b >= vec2<f32>(0.0));
    s.covers = all(b >= vec3<f32>(0.0)) && hit.z >= 0.0 && r >= 0.0 && kept;
    s.near = hit.z;
    s.w = hit.w;
    s.depth = r / hit.w;
    s.lines = vec3<f32>(line_distance(s.l0), line_distance(s.l1), line_distance(s.l2));
    s.margin = min(s.lines.x, min(s.lines.y, s.lines.z));
    return s;
}

// True when `a` is nearer than `b` at the same screen point by more than f32 rounding:
// triangles that meet at an edge or a vertex agree there only to rounding (HIDDEN_MARGIN).
fn nearer(a_near: f32, b_near: f32, b_w: f32) -> bool {
    return a_near < b_near - HIDDEN_MARGIN * (abs(b_near) + b_w);
}

// How much nearer than a line's point a surface within HIDDEN_MARGIN of it must be to tell
// how the eye's ray reaches that point (`class_at`, in a frame with section planes): from
// the section face of a cut solid, through a back face, or through a front face.
fn nearer_than_cap(a_near: f32, b_near: f32, b_w: f32) -> bool {
    return a_near < b_near - CAP_MARGIN * (abs(b_near) + b_w);
}

// WALK_STEPS, the steps of a walk across edges (`locate`), is declared from
// src/gpu/loop_budget.rs.

// Point location by walking: from triangle `tri` of instance `inst`, cross the edge `point`
// lies beyond, for at most `steps` steps, until a triangle covers it; returns the last
// triangle's sample. Finds the owner of a point that the rasterizer gave to a neighbour when
// the owner (a sub-pixel triangle, say) has no rasterized pixel of its own. The walk stays
// within the instance. With 0 steps it is the sample of `tri` itself. With `stop_at_fold`
// it also ends where it would cross a silhouette (the next triangle faces the eye the other
// way than the last one that faced it either way): the triangle beyond a silhouette edge
// lies on screen on this side of the edge, so it cannot cover a point beyond it, and the
// walk would only wander over the surface's far side (a walk from the mesh towards a
// background point does that for all its steps). In the trace pass of a frame with hidden
// lines (TURNS) it first turns about the silhouette edge's end nearer the point, up to
// FOLD_TURNS times a walk: where a surface folds back and forth within a pixel (the rim of a
// scanned or noisy mesh), the sheet past the fold goes on beyond the edge, hiding the line
// there, and it is reached round that end's fan of triangles (the ones facing away, then the
// first facing the eye again, from which the walk goes on). One
// `sample_corners` in one loop, so a shader holds one copy of it; a step reads only the next
// triangle's corner off the crossed edge (`beyond_edge`), so the corners of the returned
// sample that it shares with the triangle before it carry that one's normal bits (w) where a
// seam splits their vertices.
fn locate(inst: u32, tri: u32, point: vec2<f32>, steps: u32, stop_at_fold: bool) -> Sample {
    var t = tri;
    var s: Sample;
    let eye = instances[slot(inst)].eye;
    let v = corners(instances[slot(inst)].triangle_base + tri) + instances[slot(inst)].vertex_base;
    var q0 = vertex_at(v.x);
    var q1 = vertex_at(v.y);
    var q2 = vertex_at(v.z);
    var facing = 0.0;
#if TURNS
    // Turning about `pivot` (a corner's position) through triangles that face away; `off`,
    // the corner of the current triangle off the edge it was entered by.
    var turning = false;
    var turns_left = FOLD_TURNS;
    var pivot = vec4<f32>(0.0);
    var off = 0u;
    // The end of the last crossed edge nearer the point, and how far beyond that edge the
    // point lies (px).
    var nearer_end = vec4<f32>(0.0);
    var crossed_by = 0.0;
#endif
    for (var step = 0u; step <= steps; step++) {
        let next_s = sample_corners(inst, t, q0, q1, q2, point);
        let side = dot(towards_eye(next_s.v0.xyz, eye), cross(next_s.v1.xyz - next_s.v0.xyz, next_s.v2.xyz - next_s.v0.xyz));
#if TURNS
        let folds = side * facing < 0.0;
        if stop_at_fold && folds && !turning {
            // A point on the fold's edge (a point of an outline there) lies on no sheet
            // beyond it.
            if turns_left == 0u || crossed_by < COVERAGE_MARGIN {
                break;
            }
            turns_left -= 1u;
            turning = true;
            pivot = nearer_end;
        }
        // Back on the side the walk faced: it goes on from here.
        turning = turning && folds;
        s = next_s;
        // Edge-on and degenerate triangles (side 0) face neither way.
        if side != 0.0 && !turning {
            facing = side;
        }
#else
        if stop_at_fold && side * facing < 0.0 {
            break;
        }
        s = next_s;
        // Edge-on and degenerate triangles (side 0) face neither way.
        if side != 0.0 {
            facing = side;
        }
#endif
        let b = s.bary;
        let lowest = min(b.x, min(b.y, b.z));
        // Covered, or inside but beyond the near or far plane, or degenerate: stop.
        if s.covers || lowest >= 0.0 || any(b == vec3<f32>(-1.0)) || step == steps {
            break;
        }
        // Corner k's weight is negative beyond the opposite edge k + 1 (mod 3).
        var edge = select(select(0u, 2u, b.y == lowest), 1u, b.x == lowest);
#if TURNS
        // Turning, the walk crosses the edge from the pivot to the corner off the edge it
        // entered by (edge `off` where the pivot is corner off + 1, else edge off + 2).
        let after = select(select(q0, q2, off == 1u), q1, off == 0u);
        edge = select(edge, select((off + 2u) % 3u, off, all(after == pivot)), turning);
#endif
        let word = neighbour_word(instances[slot(inst)].triangle_base + t, edge);
        if word == BACKGROUND_ID {
            break;
        }
        let start = select(select(q2, q1, edge == 1u), q0, edge == 0u);
        let end = select(select(q0, q2, edge == 1u), q1, edge == 0u);
#if TURNS
        // The edge's ends are corners edge and edge + 1: the greater weight is the nearer.
        let w_start = select(select(b.z, b.y, edge == 1u), b.x, edge == 0u);
        let w_end = select(select(b.x, b.z, edge == 1u), b.y, edge == 0u);
        nearer_end = select(end, start, w_start >= w_end);
        crossed_by = select(select(s.lines.z, s.lines.y, edge == 1u), s.lines.x, edge == 0u);
        off = (word >> NEIGHBOUR_CORNER_SHIFT) & 3u;
#endif
        let next = beyond_edge(inst, word, start, end);
        t = next.tri;
        q0 = next.q0;
        q1 = next.q1;
        q2 = next.q2;
    }
    return s;
}
