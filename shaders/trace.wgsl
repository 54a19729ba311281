// The trace pass, after common.wgsl and scene.wgsl. It runs between the visibility pass
// and the edge pass, which reads what it leaves in `acc`: every line the edge pass cannot
// find from the ids around a pixel is traced here along the geometry (outlines, edges of
// large patches, hidden lines, listed edges, cut and intersection lines).
//
// A triangle only colours its own pixels, so the edge pass alone draws an outline edge (a
// boundary, or a silhouette: see `is_silhouette`) at half width. Outline triangles are nearly
// edge-on and often own no pixel centre at all, so they cannot be found from the ids around a
// pixel; instead one invocation per triangle finds its outline edges and lists their pieces
// (`piece_px`), and then one invocation per piece finds its visible runs (points every
// 1/4 px tested, changes bisected) and writes into every pixel within the line's reach the
// key (`line_key`) of the nearest visible run. Only triangles of the clusters that
// `trace_cull` lists are visited, so the pass reads few triangles beyond those near an
// outline. Definition (src/truth/traced.rs implements it in f64 for the ground truth):
// pixel p is at distance d from an outline when d is the distance from p's centre to the
// visible part of the edge's projection (in front of the near plane, not beyond the far
// plane, within the line's reach of the image, not hidden by another surface; the targets'
// guard band holds the ids of that reach). No depth test at p is needed: a nearer surface
// between p and a farther edge has its own outline between them, which is nearer to p and
// wins. Each pixel keeps the line that colours it most (the greatest key) by an atomic max,
// so nothing is drawn twice.
//
// The drawn edges of large patches (the triangles joined across undrawn edges: see
// src/mesh/patches.rs) are drawn here the same way, as the only lines their pixels get beyond
// their own triangle's edges.
//
// Hidden lines (HIDDEN): every drawn edge in view (the selected edges and the outlines) is
// listed too, and the pixels within reach of the hidden runs of each (where the same test
// finds a surface in front) get the key of the nearest point of a dash of the hidden-line
// pattern (`dash_nearest`) in their own word (`hidden_lines`). The pattern's phase runs
// along the edge's projection from its end that comes first in (x, y, z) order, or on
// along its chain of drawn edges (`chain_phases`), or, an outline's, on along the frame's
// outline chains (`outline_chain_ends`).
//
// Listed edges (INSTANCE_LISTED_EDGES): an instance whose drawn edges are dashed or dotted,
// or cut by section planes, has all of them in view listed here too, their visible runs
// drawn (in dashes); the edge pass then leaves its own triangles' edges. Every line ends
// where a section plane cuts it (`edge_span`). So are, where another instance passes
// through one (INSTANCE_CROSSED), the drawn edges of its triangles that reach the box round
// the crossings' image (`crossing_reach_box`), whose lines are tested over a wider window.
//
// Intersection lines (`frame.intersections` > 0): where two triangles of an instance's mesh
// cross (src/mesh/crossings.rs found the pairs and their segments at upload), one invocation
// per segment draws its visible runs, hidden by any surface but the two it lies on.
//
// Flags: COLORS (instances differ in line colour, or an outline's colour differs from the
// edges': each pixel also keeps the greatest (intensity level, class, instance) word,
// `OWNER_OUTLINE`, so the edge pass knows whose line it holds and of which class), HIDDEN
// (with TURNS: the walks of the visibility test turn at folds, `locate` in scene.wgsl),
// PATTERNS (a line is dashed or dotted: phase tables, and dashes in `splat_runs`).

@group(0) @binding(9) var<storage, read> clusters: array<Cluster>;
// The trace buffer (`traced_tile_marks` in scene.wgsl): the lines, and the output tiles
// they reach, which the edge pass visits for their background.
@group(0) @binding(11) var<storage, read_write> acc_rw: array<atomic<u32>>;

// The (instance, cluster) pairs that `trace_cull` finds may hold an outline edge, and the
// indirect dispatch size for visiting them; starts as (0, 1, 1, 0).
struct TraceList {
    x: atomic<u32>,
    y: atomic<u32>,
    z: u32,
    count: atomic<u32>,
    items: array<vec2<u32>>,
}
@group(0) @binding(13) var<storage, read_write> cull_rw: TraceList;

struct TraceListRead {
    x: u32,
    y: u32,
    z: u32,
    count: u32,
    items: array<vec2<u32>>,
}
@group(0) @binding(14) var<storage, read> cull: TraceListRead;

// After the lines and the tiles in `acc_rw`, the phase tables, then the overflow list, then
// the pieces of outline edges that `trace_list_main` lists for `trace_pieces_main`: a header
// (indirect dispatch size x, y, z, then the count; the encoder copies it to where the piece
// dispatch reads its size) and PIECE_WORDS words per piece. A lane of the piece dispatch
// draws one piece, where a lane of `trace_list_main` would draw every piece of its triangle's
// outline edges while the other lanes of its cluster, most of them without any, wait for it.
//
// Where the piece list has no room for all of a cluster's pieces (or all of a group of 64
// intersection segments'), its entry goes to the overflow list (a header, whose first word
// counts the lines listed, the second from 1 the pieces found settled (`hidden_settled`)
// and the last the entries, then up to `frame.overflow_room` entries), and the piece
// dispatch grows by 64 lanes for it, each drawing every piece of one of its triangles
// (`lane_work`): the listing dispatch itself holds no drawing code, which a software
// rasterizer would run for every lane.
fn overflow_list() -> u32 {
    return phase_tables() + frame.chain_work.x;
}

fn piece_list() -> u32 {
    return overflow_list() + 4u + frame.overflow_room;
}

// An overflow entry of intersection segments: their group's index, with this bit.
const OVERFLOW_SEGMENTS: u32 = 0x80000000u;

// Word offset of the phase tables (`chain_phases`), after the tile list.
fn phase_tables() -> u32 {
    return traced_tile_list() + 4u + traced_tile_count();
}

// A listed piece's words (PIECE_WORDS, from targets.rs): instance slot, triangle, edge, and
// piece | pieces << 16. How many pieces the list has room for, after its header at word `list`.
fn piece_room(list: u32) -> u32 {
    return (arrayLength(&acc_rw) - list - 4u) / PIECE_WORDS;
}

// The instance whose clusters hold the cull's flat cluster index f: the last with
// cluster_first <= f (instances are in the order of their cluster_first).
fn instance_of_cluster(f: u32) -> u32 {
    var lo = 0u;
    var hi = frame.instances;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if instances[slot(mid)].cluster_first <= f {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// Lists the clusters that may hold an outline edge from their instance's eye
// (`cluster_may_fold`), so that the triangles of the others, usually nearly all, are never
// read.
@compute @workgroup_size(64)
fn trace_cull(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Dispatched as a 2D grid: huge scenes have more clusters than one dimension allows.
    let f = gid.x + gid.y * groups.x * CLUSTER_TRIANGLES;
    if f >= frame.clusters {
        return;
    }
    let inst = instance_of_cluster(f);
    let flags = instances[slot(inst)].flags;
    let c = f - instances[slot(inst)].cluster_first;
    let cluster = clusters[instances[slot(inst)].cluster_base + c];
    let outlines = (flags & INSTANCE_OUTLINES) != 0u && cluster_may_fold(cluster, instances[slot(inst)].eye);
    let splats = (flags & INSTANCE_EDGES) != 0u && cluster_splats(cluster);
    // Every drawn edge in view has a hidden part to find (HIDDEN), or a pattern to draw;
    // another instance passes through this one near it (`crossing_reach_box`).
    var listed = (flags & INSTANCE_LISTED_EDGES) != 0u;
#if CROSSINGS
    let crossed = INSTANCE_CROSSED | INSTANCE_EDGES;
    for (var near = (flags & crossed) == crossed; near; near = false) {
        listed = listed || cluster_meets(instances[slot(inst)].clip, cluster, crossing_reach_box(inst));
    }
#endif
#if HIDDEN
    let hidden_edges = INSTANCE_EDGES | INSTANCE_HIDDEN | INSTANCE_HIDDEN_EDGES;
    listed = listed || (flags & hidden_edges) == hidden_edges;
#endif
    let in_view = cluster_in_view(instances[slot(inst)].clip, cluster);
    let drawn = listed && cluster_draws(cluster) && in_view;
    // A section plane cuts it: it has cut lines to draw.
#if SECTIONS
    let cut = cluster_cut(instances[slot(inst)].clip, cluster) && in_view;
#else
    let cut = false;
#endif
    if !outlines && !splats && !drawn && !cut {
        return;
    }
    let k = atomicAdd(&cull_rw.count, 1u);
    cull_rw.items[k] = vec2<u32>(inst, c);
    let size = list_size(k, 1u);
    atomicMax(&cull_rw.x, size.x);
    atomicMax(&cull_rw.y, size.y);
}

// Whether a cluster's bounding sphere reaches the view volume (local -> clip rows x, y,
// near, w: `clip`), widened by the targets' guard band.
fn cluster_in_view(clip: mat4x4<f32>, c: Cluster) -> bool {
    return cluster_meets(clip, c, vec4<f32>(-frame.output_offset, frame.image_size + frame.output_offset));
}

// Whether a cluster's bounding sphere reaches what projects into the box `b` of image
// pixels (min x, min y, max x, max y), in front of the near plane.
fn cluster_meets(clip: mat4x4<f32>, c: Cluster, b: vec4<f32>) -> bool {
    let planes = box_planes(b.xy, b.zw);
    var inside = b.x <= b.z && b.y <= b.w;
    for (var k = 0u; k < 5u; k++) {
        // The plane's function of a local point, dot(plane, clip * (p, 1)).
        let r = planes[k] * clip;
        inside = inside && dot(r.xyz, c.center) + r.w >= -cluster_radius(c) * length(r.xyz);
    }
    return inside;
}

// Whether a section plane passes through a cluster's bounding sphere (local -> clip rows
// `clip`; unused planes are 0 and pass through nothing).
fn cluster_cut(clip: mat4x4<f32>, c: Cluster) -> bool {
    var cut = false;
    for (var k = 0u; k < MAX_SECTIONS; k++) {
        let r = frame.sections[k] * clip;
        let reach = cluster_radius(c) * length(r.xyz);
        cut = cut || (reach > 0.0 && abs(dot(r.xyz, c.center) + r.w) <= reach);
    }
    return cut;
}

// The section planes a triangle (local corners p) crosses, a bit each: those with corners
// on both sides (cut away, and kept).
fn cut_planes(inst: u32, p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>) -> u32 {
    let clip = instances[slot(inst)].clip;
    let c0 = clip * vec4<f32>(p0, 1.0);
    let c1 = clip * vec4<f32>(p1, 1.0);
    let c2 = clip * vec4<f32>(p2, 1.0);
    var cuts = 0u;
    for (var k = 0u; k < MAX_SECTIONS; k++) {
        let s = vec3<f32>(dot(frame.sections[k], c0), dot(frame.sections[k], c1), dot(frame.sections[k], c2));
        let away = s < vec3<f32>(0.0);
        cuts |= select(0u, 1u << k, any(away) && !all(away));
    }
    return cuts;
}

// Where section plane k meets a triangle that crosses it (local corners p): the points
// where its side changes sign on the two edges it crosses (twin of `cut_segment` in
// src/truth/traced.rs).
fn cut_segment(inst: u32, p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>, k: u32) -> array<vec3<f32>, 2> {
    let clip = instances[slot(inst)].clip;
    let p = array<vec3<f32>, 3>(p0, p1, p2);
    var s: array<f32, 3>;
    for (var j = 0u; j < 3u; j++) {
        s[j] = dot(frame.sections[k], clip * vec4<f32>(p[j], 1.0));
    }
    var ends = array<vec3<f32>, 2>(p0, p0);
    var found = 0u;
    for (var j = 0u; j < 3u; j++) {
        let a = s[j];
        let b = s[(j + 1u) % 3u];
        if (a < 0.0) != (b < 0.0) && found < 2u {
            ends[found] = mix(p[j], p[(j + 1u) % 3u], a / (a - b));
            found++;
        }
    }
    return ends;
}

// Whether triangle (local corners p) of `inst` faces away from the eye: its outward normal,
// in the instance's own space, where the winding is the mesh's whatever the transform
// mirrors.
fn faces_away(inst: u32, p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>) -> bool {
    return dot(cross(p1 - p0, p2 - p0), towards_eye(p0, instances[slot(inst)].eye)) < 0.0;
}

// In a frame with section planes, back faces stand for the section face of a cut solid, and
// a line point that the eye's ray reaches from inside the solid lies behind that face (see
// `class_at`). Where no other surface lies just in front of the point, its own triangles
// tell: the ray reaches from inside a line between two back faces (edge i of triangle t, its
// neighbour's too), a back face's boundary, and a silhouette where the surface folds inwards
// (concave). Returns the line's CAP_ value (twin of `capped` in src/truth/traced.rs); cut
// lines are on the face.
const CAP_NONE: u32 = 0u;
const CAP_OUTSIDE: u32 = 1u;
const CAP_INSIDE: u32 = 2u;

fn capped(inst: u32, t: u32, i: u32, mode: u32) -> u32 {
#if !SECTIONS
    return CAP_NONE;
#else
    let base = instances[slot(inst)].triangle_base;
    let v = corners(base + t) + instances[slot(inst)].vertex_base;
    let p0 = vertex_at(v.x);
    let p1 = vertex_at(v.y);
    let p2 = vertex_at(v.z);
    let word = neighbour_word(base + t, i);
    var edge = array<vec4<f32>, 3>(p0, p1, p2);
    let q = beyond_edge(inst, select(word, 0u, word == BACKGROUND_ID), edge[i], edge[(i + 1u) % 3u]);
    let away = faces_away(inst, p0.xyz, p1.xyz, p2.xyz);
    let beyond = word == BACKGROUND_ID || faces_away(inst, q.q0.xyz, q.q1.xyz, q.q2.xyz);
    let centroid = (q.q0.xyz + q.q1.xyz + q.q2.xyz) / 3.0;
    let concave = dot(cross(p1.xyz - p0.xyz, p2.xyz - p0.xyz), centroid - p0.xyz) > 0.0;
    let inside = select(away && beyond, concave && word != BACKGROUND_ID, away != beyond);
    let cap = select(CAP_OUTSIDE, CAP_INSIDE, inside);
    return select(CAP_NONE, cap, (mode & DRAW_CUT) == 0u);
#endif
}

// The plane of a cut line's `mode` (DRAW_CUT), else NO_PLANE.
fn cut_plane(mode: u32) -> u32 {
    return select(NO_PLANE, (mode >> CUT_PLANE_SHIFT) & 7u, (mode & DRAW_CUT) != 0u);
}

// Whether a lane of this workgroup found more pieces than the piece list had room for.
var<workgroup> overflowed: atomic<u32>;

// One invocation per triangle of each listed cluster: lists the pieces of its outline edges.
@compute @workgroup_size(64)
fn trace_list_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let k = list_group(group);
    if k < cull.count {
        let item = cull.items[k];
        let t = item.y * CLUSTER_TRIANGLES + lane;
        if t < instances[slot(item.x)].triangles && !list_triangle(item.x, t) {
            atomicStore(&overflowed, 1u);
        }
    }
    workgroupBarrier();
    if lane == 0u && atomicLoad(&overflowed) != 0u {
        push_overflow(k);
    }
}

// Appends `entry` (a cluster list index, or a group of intersection segments) to the
// overflow list, and grows the piece dispatch by 64 lanes for it.
fn push_overflow(entry: u32) {
    let o = overflow_list();
    let j = atomicAdd(&acc_rw[o + 3u], 1u);
    if j < frame.overflow_room {
        atomicStore(&acc_rw[o + 4u + j], entry);
    }
    let list = piece_list();
    let size = list_size(piece_room(list) + 64u * j + 63u, 64u);
    atomicMax(&acc_rw[list], size.x);
    atomicMax(&acc_rw[list + 1u], size.y);
}

// A listed piece (`list_piece`): its instance, its triangle (or, DRAW_INTERSECTION in
// `mode`, its intersection segment), its edge, how it is drawn, and which of how many pieces
// of the edge it is.
struct Listed {
    inst: u32,
    t: u32,
    i: u32,
    mode: u32,
    piece: u32,
    pieces: u32,
}

// Lists pieces range.x..range.y of an edge (`item` names the edge, its mode and its piece
// count) for trace_pieces_main to draw, with one reservation in
// the list for all of them; returns how many it listed, fewer where the list is full (the
// caller draws the rest itself, `draw_unlisted`).
fn list_pieces(item: Listed, range: vec2<u32>) -> u32 {
    if range.x >= range.y {
        return 0u;
    }
    // Counted for the work counters (PreparedFrame::edge_work): the overflow list's
    // header keeps the lines listed in its first word.
    atomicAdd(&acc_rw[overflow_list()], 1u);
    let n = range.y - range.x;
    let list = piece_list();
    let room = piece_room(list);
    let k = atomicAdd(&acc_rw[list + 3u], n);
    let listed = min(n, room - min(k, room));
    let at = list + 4u + PIECE_WORDS * k;
    let word = item.i | (item.mode << 2u);
    for (var j = 0u; j < listed; j++) {
        let w = at + PIECE_WORDS * j;
        atomicStore(&acc_rw[w], item.inst);
        atomicStore(&acc_rw[w + 1u], item.t);
        atomicStore(&acc_rw[w + 2u], word);
        atomicStore(&acc_rw[w + 3u], (range.x + j) | (item.pieces << 16u));
    }
    if listed > 0u {
        let size = list_size(k + listed - 1u, 64u);
        atomicMax(&acc_rw[list], size.x);
        atomicMax(&acc_rw[list + 1u], size.y);
    }
    return listed;
}

// The ends of edge i of triangle t of `inst` (local corners p), or of its cut line
// (DRAW_CUT in `mode`: where its plane meets the triangle), and the triangle across it.
struct EdgeEnds {
    a: vec3<f32>,
    b: vec3<f32>,
    n: u32,
}

fn edge_ends(inst: u32, t: u32, p: array<vec3<f32>, 3>, i: u32, mode: u32) -> EdgeEnds {
    var e = EdgeEnds(p[i], p[(i + 1u) % 3u], neighbour(instances[slot(inst)].triangle_base + t, i));
#if SECTIONS
    if (mode & DRAW_CUT) != 0u {
        let cut = cut_segment(inst, p[0], p[1], p[2], cut_plane(mode));
        e = EdgeEnds(cut[0], cut[1], BACKGROUND_ID);
    }
#endif
    return e;
}

// The local corners of triangle t of `inst`.
fn triangle_corners(inst: u32, t: u32) -> array<vec3<f32>, 3> {
    let v = corners(instances[slot(inst)].triangle_base + t) + instances[slot(inst)].vertex_base;
    return array<vec3<f32>, 3>(vertex_at(v.x).xyz, vertex_at(v.y).xyz, vertex_at(v.z).xyz);
}

// The segment of a listed piece's edge (an outline, a drawn edge or a cut line), its
// pattern anchored.
fn listed_edge(item: Listed) -> Clipped {
    let e = edge_ends(item.inst, item.t, triangle_corners(item.inst, item.t), item.i, item.mode);
    let anchor = pattern_anchor(item.inst, item.t, item.i, e.a, e.b, item.mode);
    var c = clip_outline(On(item.inst, item.t, item.inst, e.n, false, false), e.a, e.b, anchor, cut_plane(item.mode));
    c.seg.cap = capped(item.inst, item.t, item.i, item.mode);
    return c;
}

// Draws the listed piece `item` of the segment `c`, unless only its hidden line is drawn and
// that can change no pixel (`hidden_settled`). (Loops, not `if`s: a software rasterizer
// skips a loop no lane enters, and runs the body of an `if` for every lane.)
fn draw_listed(item: Listed, c: Clipped) {
    let pieces = f32(item.pieces);
    let k0 = f32(item.piece) / pieces;
    let k1 = f32(item.piece + 1u) / pieces;
#if HIDDEN
    var settled = false;
    for (var hidden_only = item.mode == DRAW_HIDDEN; hidden_only; hidden_only = false) {
        settled = hidden_settled(c.seg, k0, k1, c.length_px * (k1 - k0));
        if settled {
            // Counted for PreparedFrame::edge_work in the overflow list's header.
            atomicAdd(&acc_rw[overflow_list() + 1u], 1u);
        }
    }
    for (var draw = !settled; draw; draw = false) {
        draw_piece(c.seg, k0, k1, c.length_px, item.mode);
    }
#else
    draw_piece(c.seg, k0, k1, c.length_px, item.mode);
#endif
}

#if HIDDEN
// Whether every pixel within reach of the segment's part k0..k1 (`length_px` long) already
// holds a hidden-line key at least as strong as any this part could write there
// (`splat_runs`, whatever its runs and pattern): then its hidden runs cannot change the
// frame, and finding them is skipped. Where hidden edges are denser than pixels, most
// pixels near a piece hold a nearer line by the time it is drawn. Only parts up to
// SETTLE_PX long of lines whose reach is up to SETTLE_REACH are looked at (a bounded loop).
fn hidden_settled(seg: Segment, k0: f32, k1: f32, length_px: f32) -> bool {
    let inst = seg.on.inst;
    let width = instances[slot(inst)].hidden_width;
    let reach = line_reach(width);
    if !(length_px <= SETTLE_PX) || reach > SETTLE_REACH {
        return false;
    }
    // Target pixel coordinates.
    let q0 = mix(seg.start.xy, seg.end.xy, k0) - frame.target_origin;
    let q1 = mix(seg.start.xy, seg.end.xy, k1) - frame.target_origin;
    let lo = max(vec2<i32>(floor(min(q0, q1) - reach)), vec2<i32>(0));
    let hi = min(vec2<i32>(ceil(max(q0, q1) + reach)), vec2<i32>(frame.target_size) - 1);
    let box = hi - lo + 1;
    let d = q1 - q0;
    let dd = dot(d, d);
    let words = hidden_lines();
    for (var k = 0; k < box.x * box.y; k++) {
        let xy = lo + vec2<i32>(k % box.x, k / box.x);
        let p = vec2<f32>(xy) + 0.5;
        let u = select(0.0, clamp(dot(p - q0, d) / dd, 0.0, 1.0), dd > 0.0);
        // The nearest any point of the part can be, less the rounding of splat_runs' own
        // distance.
        let near = max(distance(p, q0 + u * d) - SETTLE_SLACK, 0.0);
        if !(near < reach + REACH_SLACK) {
            continue;
        }
        let bound = line_key(line_intensity(near, width), near);
        let index = u32(xy.y) * u32(frame.target_size.x) + u32(xy.x);
#if COLORS
        // And the colour word, whose ties the higher instance wins.
        let held = atomicLoad(&acc_rw[words + 2u * index]);
        let owner = atomicLoad(&acc_rw[words + 2u * index + 1u]);
        if held < bound || owner < ((bound & 0xfff00000u) | inst) {
            return false;
        }
#else
        if atomicLoad(&acc_rw[words + index]) < bound {
            return false;
        }
#endif
    }
    return true;
}

// What hidden_settled takes off a pixel's distance to a piece: more than f32 rounding
// of the pixel coordinates makes of `splat_runs`' own distance.
const SETTLE_SLACK: f32 = 1e-3;
#endif

// What a lane of the piece dispatch draws: one listed piece, or (a lane past the list's
// room, for an overflow entry) every piece of a triangle's lines (`found`, each i | mode << 2)
// or of an intersection segment (`segment`).
struct LaneWork {
    inst: u32,
    t: u32,
    found: Found,
    // The listed piece, the only one drawn (`overflow` false).
    piece: u32,
    pieces: u32,
    overflow: bool,
    segment: bool,
}

fn lane_work(group: vec3<u32>, lane: u32) -> LaneWork {
    var w: LaneWork;
    let k = list_group(group) * 64u + lane;
    let list = piece_list();
    let room = piece_room(list);
    let count = atomicLoad(&acc_rw[list + 3u]);
    if k < min(count, room) {
        let at = list + 4u + PIECE_WORDS * k;
        let word = atomicLoad(&acc_rw[at + 2u]);
        let piece = atomicLoad(&acc_rw[at + 3u]);
        w.inst = atomicLoad(&acc_rw[at]);
        w.t = atomicLoad(&acc_rw[at + 1u]);
        w.found.count = 1u;
        w.found.words[0] = word;
        w.piece = piece & 0xffffu;
        w.pieces = piece >> 16u;
        w.segment = (word & (DRAW_INTERSECTION << 2u)) != 0u;
        return w;
    }
    let o = overflow_list();
    let j = (k - min(k, room)) / 64u;
    if k < room || j >= min(atomicLoad(&acc_rw[o + 3u]), frame.overflow_room) {
        return w;
    }
    let entry = atomicLoad(&acc_rw[o + 4u + j]);
    w.overflow = true;
    if (entry & OVERFLOW_SEGMENTS) != 0u {
        w.t = (entry & ~OVERFLOW_SEGMENTS) * 64u + lane;
        w.segment = true;
        w.found.count = select(0u, 1u, w.t < frame.intersections);
        w.found.words[0] = (DRAW_VISIBLE | DRAW_INTERSECTION) << 2u;
        return w;
    }
    let item = cull.items[entry];
    w.inst = item.x;
    w.t = item.y * CLUSTER_TRIANGLES + lane;
    if w.t < instances[slot(item.x)].triangles {
        w.found = outline_lines(item.x, w.t);
    }
    return w;
}

// The segment of line `item` of a lane's work: an intersection segment's (`segment`), or
// a listed edge's (`listed_edge`). One call of clip_outline serves both.
fn lane_line(item: Listed, segment: bool) -> Clipped {
    // A segment's item names no triangle: the edge's part reads triangle 0 instead.
    let t = select(item.t, 0u, segment);
    let e = edge_ends(item.inst, t, triangle_corners(item.inst, t), item.i, item.mode);
    var on = On(item.inst, t, item.inst, e.n, false, false);
    var a = e.a;
    var b = e.b;
    var anchor = pattern_anchor(item.inst, t, item.i, e.a, e.b, item.mode);
    var cap = capped(item.inst, t, item.i, item.mode);
#if CROSSINGS
    if segment {
        let s = intersections[min(item.t, max(frame.intersections, 1u) - 1u)];
        on = On(s.slot, s.t, s.other, s.u, true, false);
        a = s.a;
        b = s.b;
        anchor = vec4<f32>(0.0, 1.0, 0.0, 1.0);
        cap = CAP_NONE;
    }
#endif
    var c = clip_outline(on, a, b, anchor, cut_plane(item.mode));
    c.seg.cap = cap;
    return c;
}

// Draws a lane's work (`lane_work`): one loop over the pieces of each of its lines, so that
// the shader holds one copy of the drawing code.
fn draw_lane(w: LaneWork) {
    var e = 0u;
    var piece = w.piece;
    loop {
        if e >= w.found.count {
            break;
        }
        let word = w.found.words[e];
        var item = Listed(w.inst, w.t, word & 3u, word >> 2u, piece, w.pieces);
        let c = lane_line(item, w.segment);
        item.inst = c.seg.on.inst;
        // An overflowed lane draws every piece within reach of the targets.
        var end = piece + 1u;
        if w.overflow {
            item.pieces = c.pieces;
            let range = pieces_in_reach(c, line_reach_of(item.inst, item.mode));
            piece = max(piece, range.x);
            item.piece = piece;
            end = range.y;
        }
        if piece < end {
            draw_listed(item, c);
            piece++;
        }
        if piece >= end {
            e++;
            piece = 0u;
        }
    }
}

// One invocation per listed piece (and 64 per overflow entry): draws it.
@compute @workgroup_size(64)
fn trace_pieces_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    draw_lane(lane_work(group, lane));
}

// The frame's intersection segments (src/gpu/frame.rs, IntersectionRecord): where
// triangle t of the instance in `slot` crosses triangle u of the instance in `other` (the
// same one where a mesh passes through itself), from a to b in the first's local
// coordinates.
struct Intersection {
    a: vec3<f32>,
    slot: u32,
    b: vec3<f32>,
    t: u32,
    u: u32,
    other: u32,
}
@group(0) @binding(28) var<storage, read> intersections: array<Intersection>;

// Intersection segment k on screen.
fn clip_intersection(k: u32) -> Clipped {
    let s = intersections[k];
    return clip_outline(On(s.slot, s.t, s.other, s.u, true, false), s.a, s.b, vec4<f32>(0.0, 1.0, 0.0, 1.0), NO_PLANE);
}

// One invocation per intersection segment: lists its pieces that reach the targets, after
// the outline edges' (a segment is no longer than its triangles, so few have more than one).
@compute @workgroup_size(64)
fn intersection_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let k = gid.x + gid.y * groups.x * CLUSTER_TRIANGLES;
    if k < frame.intersections {
        let c = clip_intersection(k);
        let mode = DRAW_VISIBLE | DRAW_INTERSECTION;
        let item = Listed(c.seg.on.inst, k, 0u, mode, 0u, c.pieces);
        let range = pieces_in_reach(c, line_reach(frame.intersection_width));
        if !list_all(item, range) {
            atomicStore(&overflowed, 1u);
        }
    }
    workgroupBarrier();
    if lane == 0u && atomicLoad(&overflowed) != 0u {
        push_overflow((k / 64u) | OVERFLOW_SEGMENTS);
    }
}

// Lists the pieces `range` of a line (`item`: its edge, mode and piece count): false where
// the list had no room for all of them, or the line has more than an item can number.
fn list_all(item: Listed, range: vec2<u32>) -> bool {
    let listable = item.pieces <= 0xffffu;
    let listed = list_pieces(item, vec2<u32>(range.x, select(0u, range.y, listable)));
    return listable && listed == range.y - min(range.x, range.y);
}

// The pieces range.x..range.y of the clipped line `c` that lie within `reach` of the
// targets (of a tile): those whose parameters meet the part of the line inside the targets
// grown by the reach and a pixel.
fn pieces_in_reach(c: Clipped, reach: f32) -> vec2<u32> {
    let p = c.seg.start.xy;
    let d = c.seg.end.xy - p;
    let lo = frame.target_origin - reach - 1.0;
    let hi = frame.target_origin + frame.target_size + reach + 1.0;
    var u = keep_between(vec2<f32>(0.0, 1.0), p.x, d.x, lo.x, hi.x);
    u = keep_between(u, p.y, d.y, lo.y, hi.y);
    if !(u.x <= u.y) || c.pieces == 0u {
        return vec2<u32>(0u);
    }
    let n = f32(c.pieces);
    let first = min(u32(max(floor(u.x * n), 0.0)), c.pieces - 1u);
    let end = min(u32(max(ceil(u.y * n), 0.0)), c.pieces);
    return vec2<u32>(first, max(end, first + 1u));
}

// The lines of a triangle the trace pass draws: up to 3 edges and a cut line a section
// plane, each i | mode << 2 (edge i, DRAW_* bits).
struct Found {
    count: u32,
    words: array<u32, 9>,
}

// Lists the pieces of the lines of triangle t of `inst` (`outline_lines`): false where the
// list had no room for them all.
fn list_triangle(inst: u32, t: u32) -> bool {
    let found = outline_lines(inst, t);
    let p = triangle_corners(inst, t);
    var all = true;
    for (var j = 0u; j < found.count; j++) {
        all = list_outline(inst, t, p, found.words[j]) && all;
    }
#if PATTERNS
    // Patterned outlines join the frame's outline chains.
    let chained = (instances[slot(inst)].flags & INSTANCE_OUTLINE_PHASES) != 0u;
    for (var j = select(found.count, 0u, chained); j < found.count; j++) {
        let mode = found.words[j] >> 2u;
        let i = found.words[j] & 3u;
        if (mode & DRAW_OUTLINE) != 0u && !hidden_on_chain(inst, t, i) {
            push_outline_edge(inst, t, p, i);
        }
    }
#endif
    return all;
}

// Finds the lines of triangle t of instance `inst` that the trace pass draws.
fn outline_lines(inst: u32, t: u32) -> Found {
    var found: Found;
    let base = instances[slot(inst)].triangle_base;
    var p = triangle_corners(inst, t);
    // Most triangles are seen well away from edge-on, further than their edges fold: none of
    // their neighboured edges can be a silhouette (Mesh::outline_hints), and they skip the
    // neighbours' vertices. The angle is taken from the triangle's farthest vertex, its least.
    let bits = info[base + t];
    let flags = instances[slot(inst)].flags;
    let outlines = (flags & INSTANCE_OUTLINES) != 0u;
    let boundary = outlines && (bits & 8u) != 0u;
    let allowed = select(0u, (bits >> 8u) & 7u, outlines);
    // Drawn edges of a large patch, drawn here like outlines (mesh_store::EdgeData); all
    // drawn edges where they are patterned, and near where another instance crosses this one.
    var listed = (flags & INSTANCE_LISTED_EDGES) != 0u;
#if CROSSINGS
    let crossed = INSTANCE_CROSSED | INSTANCE_EDGES;
    for (var near = (flags & crossed) == crossed; near; near = false) {
        listed = listed || triangle_meets(inst, p, crossing_reach_box(inst));
    }
#endif
    let patterned = select(0u, bits & 7u, listed);
    let splat = select(0u, (bits >> INFO_SPLAT_SHIFT) & 7u, (flags & INSTANCE_EDGES) != 0u && patterned == 0u);
#if HIDDEN
    // Drawn edges: their hidden parts, wherever they are, where the instance draws them.
    let hidden_lines = (flags & INSTANCE_HIDDEN) != 0u;
    let hidden_edges = INSTANCE_EDGES | INSTANCE_HIDDEN_EDGES;
    let hidden_drawn = select(0u, bits & 7u, (flags & hidden_edges) == hidden_edges && hidden_lines);
    let drawn = patterned | hidden_drawn;
#else
    let drawn = patterned;
#endif
    // Decoded as adjacency::fold_bound: 0 flat, 2^(q - 14) with a margin, 15 never skip;
    // each with EDGE_ON_MARGIN: a triangle within EDGE_ON of edge-on has every edge an
    // outline.
    let q = (bits >> 4u) & 15u;
    var fold_bound = exp2(f32(q) - 14.0) * 1.01 + 1e-6 + EDGE_ON_MARGIN;
    if q == 0u {
        fold_bound = 1e-6 + EDGE_ON_MARGIN;
    } else if q == 15u {
        fold_bound = 2.0;
    }
    let normal = cross(p[1] - p[0], p[2] - p[0]);
    let eye = instances[slot(inst)].eye;
    let e = eye.xyz / eye.w;
    let height = abs(dot(p[0] - e, normal));
    let farthest = sqrt(max(dot(p[0] - e, p[0] - e), max(dot(p[1] - e, p[1] - e), dot(p[2] - e, p[2] - e))));
    // Seen along one direction (w = 0): the angle to edge-on is the same from every vertex.
    let along = !(abs(dot(eye.xyz, normal)) > fold_bound * length(eye.xyz) * length(normal));
    let may_fold = select(along, !(height > fold_bound * farthest * length(normal)), eye.w != 0.0);
#if SECTIONS
    let cuts = cut_planes(inst, p[0], p[1], p[2]);
    // Cut lines, one a plane the triangle crosses.
    for (var rest = cuts; rest != 0u; rest &= rest - 1u) {
        let k = firstTrailingBit(rest);
        found.words[found.count] = (DRAW_VISIBLE | DRAW_CUT | (k << CUT_PLANE_SHIFT)) << 2u;
        found.count++;
    }
#endif
    for (var i = 0u; i < 3u; i++) {
        if ((allowed | splat | drawn) & (1u << i)) == 0u {
            continue;
        }
        let word = neighbour_word(base + t, i);
        let n = neighbour_of(word);
        let a = p[i];
        let b = p[(i + 1u) % 3u];
        // An outline (of its own class, width and colour), or a drawn edge of a large patch.
        var outline = (allowed & (1u << i)) != 0u && n == BACKGROUND_ID;
        if !outline && (allowed & (1u << i)) != 0u && may_fold && t < n {
            // Shared edges are drawn by the lower id only. The neighbour's centroid, its
            // corners summed in its own order; only the one off the edge is read.
            let q = beyond_edge(inst, word, vec4<f32>(a, 0.0), vec4<f32>(b, 0.0));
            let d = (q.q0.xyz + q.q1.xyz + q.q2.xyz) / 3.0;
            outline = is_silhouette(a, b, p[(i + 2u) % 3u], d, eye);
        }
        // A shared drawn edge is drawn by the lower id only.
        let lower = n == BACKGROUND_ID || t < n;
        let splats = (splat & (1u << i)) != 0u || ((patterned & (1u << i)) != 0u && lower);
        var mode = select(0u, DRAW_VISIBLE, outline || splats) | select(0u, DRAW_OUTLINE, outline);
#if HIDDEN
        let hidden = (outline && hidden_lines) || ((hidden_drawn & (1u << i)) != 0u && lower);
        mode |= select(0u, DRAW_HIDDEN, hidden);
#endif
        if mode != 0u {
            found.words[found.count] = i | (mode << 2u);
            found.count++;
        }
    }
    return found;
}

// Whether a comes before b in (x, y, z) order: the end of an edge that anchors its line
// pattern, the same whichever triangle draws the edge and whatever the vertices' numbers
// (twin of `comes_first` in src/mesh/chains.rs).
fn comes_first(a: vec3<f32>, b: vec3<f32>) -> bool {
    return a.x < b.x || (a.x == b.x && (a.y < b.y || (a.y == b.y && a.z < b.z)));
}

// Where the line patterns of edge i (a -> b) of triangle t of `inst` stand: the visible
// line's position at the edge's start along its pattern (at a, or at b), and +1 as it runs
// from a towards b, -1 from b towards a; then the hidden line's. A drawn edge in a chain of
// drawn edges (src/mesh/chains.rs) takes the positions `chain_phases` found for it this
// frame, where its instance's edges (for the visible line) or their hidden parts (for the
// hidden line) are patterned; an outline's visible line, and any other edge, start the
// pattern at the edge's end that comes first.
fn pattern_anchor(inst: u32, t: u32, i: u32, a: vec3<f32>, b: vec3<f32>, mode: u32) -> vec4<f32> {
    let first = select(-1.0, 1.0, comes_first(a, b));
    var anchor = vec4<f32>(0.0, first, 0.0, first);
#if PATTERNS
    let flags = instances[slot(inst)].flags;
    let chained = (info[instances[slot(inst)].triangle_base + t] >> (INFO_CHAINED_SHIFT + i)) & 1u;
    if frame.chain_work.x != 0u && chained != 0u && (flags & INSTANCE_PHASES) != 0u && (mode & DRAW_CUT) == 0u {
        let e = chain_anchor(inst, phase_key(t, i));
        if (flags & INSTANCE_LISTED_EDGES) != 0u && (mode & DRAW_OUTLINE) == 0u {
            anchor = vec4<f32>(e.y, e.z, anchor.zw);
        }
        if hidden_on_chain(inst, t, i) {
            anchor = vec4<f32>(anchor.xy, e.x, e.z);
        }
    }
    if (flags & INSTANCE_OUTLINE_PHASES) != 0u && (mode & DRAW_OUTLINE) != 0u && !hidden_on_chain(inst, t, i) {
        let o = outline_chain_anchor(inst, phase_key(t, i));
        anchor = select(anchor, vec4<f32>(o.y, o.z, o.x, o.z), o.z != 0.0);
    }
#endif
    return anchor;
}

#if PATTERNS
// Whether the hidden-line pattern of edge i of triangle t of `inst` runs along its chain of
// drawn edges (`chain_phases`): the edge is chained, and the instance's drawn edges show
// their hidden parts in a pattern.
fn hidden_on_chain(inst: u32, t: u32, i: u32) -> bool {
    let flags = instances[slot(inst)].flags;
    let chained = (info[instances[slot(inst)].triangle_base + t] >> (INFO_CHAINED_SHIFT + i)) & 1u;
    let hidden_edges = INSTANCE_EDGES | INSTANCE_HIDDEN | INSTANCE_HIDDEN_EDGES | INSTANCE_PHASES;
    return frame.chain_work.x != 0u && chained != 0u && (flags & hidden_edges) == hidden_edges && instances[slot(inst)].hidden_period > 0.0;
}
#endif

#if PATTERNS
// The mesh store's chain records (src/gpu/mesh_records.rs, ChainRecords): per chain (first
// edge record, edge count), then per edge (start vertex, end vertex, key | forward << 31,
// phase table slot), the vertices as the listing triangle runs the edge.
@group(0) @binding(26) var<storage, read> chains: array<vec4<u32>>;

// The instances whose chains are visited (src/gpu/frame.rs, ChainWork).
struct ChainWork {
    slot: u32,
    chain_base: u32,
    chains: u32,
    before: u32,
}
@group(0) @binding(27) var<storage, read> chain_work: array<ChainWork>;

// Twins of `phase_key` and `phase_slot` in mesh_records.rs.
fn phase_key(t: u32, i: u32) -> u32 {
    return (t << 2u) | i;
}

fn phase_slot(key: u32, log2: u32) -> u32 {
    return (key * 0x9e3779b1u) >> (32u - log2);
}

// One invocation per chain of every instance in `chain_work`: walks the chain from its
// start, writing into the instance's phase table, for each edge, its key and the patterns'
// positions where the chain enters it (the hidden lines', the edges'): the summed length of
// the projections of the edges before it (each in front of the near plane and not beyond
// the far one, as `edge_span` clips them), reduced modulo each pattern's period (the
// pattern repeats, and small positions keep f32's precision).
@compute @workgroup_size(64)
fn chain_phases(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let g = gid.x + gid.y * groups.x * 64u;
    if g >= frame.chain_work.y {
        return;
    }
    var lo = 0u;
    var hi = frame.chain_work.z;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if chain_work[mid].before <= g {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let work = chain_work[lo];
    let inst = work.slot;
    let head = chains[work.chain_base + g - work.before];
    let table = phase_tables() + instances[slot(inst)].phase_table;
    let vbase = instances[slot(inst)].vertex_base;
    let periods = vec2<f32>(instances[slot(inst)].hidden_period, instances[slot(inst)].edge_pattern.y);
    var position = vec2<f32>(0.0);
    for (var k = 0u; k < head.y; k++) {
        let e = chains[work.chain_base + head.x + k];
        let at = table + PHASE_ENTRY_WORDS * e.w;
        atomicStore(&acc_rw[at], e.z);
        atomicStore(&acc_rw[at + 1u], bitcast<u32>(position.x));
        atomicStore(&acc_rw[at + 2u], bitcast<u32>(position.y));
        let span = edge_span(inst, vertex_at(vbase + e.x).xyz, vertex_at(vbase + e.y).xyz, NO_PLANE);
        position += select(0.0, length(span.p1.xy - span.p0.xy), span.s.x <= span.s.y);
        position = select(vec2<f32>(0.0), position - periods * floor(position / periods), periods > vec2<f32>(0.0));
    }
}

// A phase table entry (PHASE_ENTRY_WORDS): key | forward << 31, the hidden lines' position,
// the edges'.
// The patterns' positions (the hidden lines', the edges') and their direction
// (`pattern_anchor`) on the chained edge `key` of `inst`, from its phase table: probed from
// `phase_slot` on, every slot up to the key's was written this frame (the table's layout is
// fixed at upload).
fn chain_anchor(inst: u32, key: u32) -> vec3<f32> {
    let log2 = instances[slot(inst)].table_log2;
    let table = phase_tables() + instances[slot(inst)].phase_table;
    let mask = (1u << log2) - 1u;
    var at = phase_slot(key, log2);
    for (var probe = 0u; probe <= mask; probe++) {
        let entry = table + PHASE_ENTRY_WORDS * at;
        let word = atomicLoad(&acc_rw[entry]);
        if (word & 0x7fffffffu) == key {
            let hidden = bitcast<f32>(atomicLoad(&acc_rw[entry + 1u]));
            let edges = bitcast<f32>(atomicLoad(&acc_rw[entry + 2u]));
            return vec3<f32>(hidden, edges, select(-1.0, 1.0, (word >> 31u) != 0u));
        }
        at = (at + 1u) & mask;
    }
    return vec3<f32>(0.0, 0.0, 1.0);
}
#endif

#if PATTERNS
// Outline chains. An outline's patterns (its visible line's, its hidden parts') run on
// along the frame's chains of outline edges, as a drawn edge's run along its chain: a
// silhouette of a smooth part is a loop of edges a pixel or two long, and a pattern
// restarting on each would look solid. The chains depend on the view, so they are found
// each frame (src/truth/traced.rs defines the same in f64): each outline edge of an
// instance flagged INSTANCE_OUTLINE_PHASES, but one whose hidden part runs along a chain of
// drawn edges, runs with its front side on its left (`outline_forward`), and it continues
// into the edge that starts where it ends when exactly one such edge starts there and
// exactly one ends there (vertices compared by position). A chain that closes starts at
// its edge whose start comes first in (x, y, z) order (`comes_first`), an open one at its
// first edge; a pattern's position on an edge is the projected length of the chain before
// it, modulo the pattern's period.
//
// `trace_list_main` appends the edges (`push_outline_edge`); `outline_chain_ends` counts
// the ends at each vertex and hashes the edges by key; `outline_chain_start` links each edge
// to the one before it; then 2⌈log₂(capacity)/2⌉ rounds of `outline_chain_jump_ab` and
// `_ba`, each doubling how far every edge has looked back (list ranking by pointer
// jumping): the lengths summed on the way back to the chain's start, and the edge seen
// whose start comes first, with the length back to it. No chain is longer than the
// capacity, so every chain is seen whole, closed or not.
//
// The area, after the phase tables, for a capacity of C edges (`frame.chain_work.w`, a power
// of two; OUTLINE_CHAIN_WORDS per edge): a header (indirect dispatch size x, y, z, count);
// per edge (instance, key, forward, projected length, start x, y, z, unused); the looks back
// A and B, 6 words per edge (`OutlineLook`); 4C vertex buckets (tag: 2 edge + end + 1; ends
// in | out << 16; the first edge to end there; the first to start there); and 2C edge slots
// (edge + 1).
const OUTLINE_NONE: u32 = 0xffffffffu;

fn outline_area() -> u32 {
    return phase_tables() + frame.chain_work.x - 4u - OUTLINE_CHAIN_WORDS * frame.chain_work.w;
}

fn outline_record(e: u32) -> u32 {
    return outline_area() + 4u + 8u * e;
}

fn outline_look(e: u32, b: bool) -> u32 {
    return outline_area() + 4u + frame.chain_work.w * select(8u, 14u, b) + 6u * e;
}

fn outline_buckets() -> u32 {
    return outline_area() + 4u + 20u * frame.chain_work.w;
}

// The start of outline chain edge e (`outline_chain_ends` stores it).
fn outline_start(e: u32) -> vec3<f32> {
    let r = outline_record(e) + 4u;
    return bitcast<vec3<f32>>(vec3<u32>(atomicLoad(&acc_rw[r]), atomicLoad(&acc_rw[r + 1u]), atomicLoad(&acc_rw[r + 2u])));
}

fn outline_slots() -> u32 {
    return outline_buckets() + 16u * frame.chain_work.w;
}

// Appends outline edge i of triangle t of `inst` (local corners p) to the frame's outline
// chains, with its direction.
fn push_outline_edge(inst: u32, t: u32, p: array<vec3<f32>, 3>, i: u32) {
    let base = instances[slot(inst)].triangle_base;
    let word = neighbour_word(base + t, i);
    let a = p[i];
    let b = p[(i + 1u) % 3u];
    let across = neighbour_of(word) != BACKGROUND_ID;
    var d = a;
    for (var go = across; go; go = false) {
        let q = beyond_edge(inst, word, vec4<f32>(a, 0.0), vec4<f32>(b, 0.0));
        d = (q.q0.xyz + q.q1.xyz + q.q2.xyz) / 3.0;
    }
    let forward = outline_forward(a, b, p[(i + 2u) % 3u], d, across, instances[slot(inst)].eye);
    let area = outline_area();
    let e = atomicAdd(&acc_rw[area + 3u], 1u);
    if e >= frame.chain_work.w {
        return;
    }
    let r = outline_record(e);
    atomicStore(&acc_rw[r], inst);
    atomicStore(&acc_rw[r + 1u], phase_key(t, i));
    atomicStore(&acc_rw[r + 2u], select(0u, 1u, forward));
    let size = list_size(e, 64u);
    atomicMax(&acc_rw[area], size.x);
    atomicMax(&acc_rw[area + 1u], size.y);
}

// The outline chain edge of a lane of an indirect dispatch over them, or OUTLINE_NONE.
fn outline_edge_of(group: vec3<u32>, lane: u32) -> u32 {
    let e = list_group(group) * 64u + lane;
    let count = min(atomicLoad(&acc_rw[outline_area() + 3u]), frame.chain_work.w);
    return select(OUTLINE_NONE, e, e < count);
}

// The ends of outline chain edge e as it runs: start, end.
fn outline_ends(e: u32) -> array<vec3<f32>, 2> {
    let r = outline_record(e);
    let inst = atomicLoad(&acc_rw[r]);
    let key = atomicLoad(&acc_rw[r + 1u]);
    let p = triangle_corners(inst, key >> 2u);
    let a = p[key & 3u];
    let b = p[((key & 3u) + 1u) % 3u];
    let forward = atomicLoad(&acc_rw[r + 2u]) != 0u;
    return array<vec3<f32>, 2>(select(b, a, forward), select(a, b, forward));
}

fn mix_bits(x: u32) -> u32 {
    var h = x;
    h ^= h >> 16u;
    h *= 0x7feb352du;
    h ^= h >> 15u;
    h *= 0x846ca68bu;
    h ^= h >> 16u;
    return h;
}

// The bucket (word index) of the vertex at `end` (0 start, 1 end) of outline chain edge e:
// the one whose tag names an end at the same position of the same instance, claimed if
// none does.
fn outline_bucket(e: u32, end: u32) -> u32 {
    let inst = atomicLoad(&acc_rw[outline_record(e)]);
    let v = outline_ends(e)[end];
    // -0 and 0 are one position.
    let z = select(v, vec3<f32>(0.0), v == vec3<f32>(0.0));
    let mask = 4u * frame.chain_work.w - 1u;
    var h = mix_bits(mix_bits(mix_bits(mix_bits(inst) ^ bitcast<u32>(z.x)) ^ bitcast<u32>(z.y)) ^ bitcast<u32>(z.z)) & mask;
    let tag = 2u * e + end + 1u;
    let buckets = outline_buckets();
    for (var probe = 0u; probe <= 2u * mask; probe++) {
        let at = buckets + 4u * h;
        let old = atomicCompareExchangeWeak(&acc_rw[at], 0u, tag);
        if old.exchanged {
            return at;
        }
        if old.old_value == 0u {
            continue;
        }
        let other = (old.old_value - 1u) >> 1u;
        let same_inst = atomicLoad(&acc_rw[outline_record(other)]) == inst;
        if same_inst && all(outline_ends(other)[(old.old_value - 1u) & 1u] == v) {
            return at;
        }
        h = (h + 1u) & mask;
    }
    return OUTLINE_NONE;
}

// The slot of the edge hash for (instance, key).
fn outline_slot(inst: u32, key: u32) -> u32 {
    return mix_bits(mix_bits(inst) ^ key) & (2u * frame.chain_work.w - 1u);
}

// One invocation per outline chain edge: counts its ends at their vertices, enters it in
// the edge hash, and measures its projection.
@compute @workgroup_size(64)
fn outline_chain_ends(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let e = outline_edge_of(group, lane);
    if e == OUTLINE_NONE {
        return;
    }
    let start = outline_bucket(e, 0u);
    let end = outline_bucket(e, 1u);
    if start != OUTLINE_NONE && (atomicAdd(&acc_rw[start + 1u], 1u << 16u) >> 16u) == 0u {
        atomicStore(&acc_rw[start + 3u], e);
    }
    if end != OUTLINE_NONE && (atomicAdd(&acc_rw[end + 1u], 1u) & 0xffffu) == 0u {
        atomicStore(&acc_rw[end + 2u], e);
    }
    let r = outline_record(e);
    let inst = atomicLoad(&acc_rw[r]);
    let key = atomicLoad(&acc_rw[r + 1u]);
    let mask = 2u * frame.chain_work.w - 1u;
    var h = outline_slot(inst, key);
    let slots = outline_slots();
    for (var probe = 0u; probe <= 2u * mask; probe++) {
        let old = atomicCompareExchangeWeak(&acc_rw[slots + h], 0u, e + 1u);
        if old.exchanged {
            break;
        }
        if old.old_value != 0u {
            h = (h + 1u) & mask;
        }
    }
    let ends = outline_ends(e);
    let span = edge_span(inst, ends[0], ends[1], NO_PLANE);
    let length = select(0.0, length(span.p1.xy - span.p0.xy), span.s.x <= span.s.y);
    atomicStore(&acc_rw[r + 3u], bitcast<u32>(length));
    atomicStore(&acc_rw[r + 4u], bitcast<u32>(ends[0].x));
    atomicStore(&acc_rw[r + 5u], bitcast<u32>(ends[0].y));
    atomicStore(&acc_rw[r + 6u], bitcast<u32>(ends[0].z));
}

// One invocation per outline chain edge: the edge before it (the only one ending where it
// starts, where only it starts there), and its first look back.
@compute @workgroup_size(64)
fn outline_chain_start(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let e = outline_edge_of(group, lane);
    if e == OUTLINE_NONE {
        return;
    }
    let start = outline_bucket(e, 0u);
    var before = OUTLINE_NONE;
    if start != OUTLINE_NONE && atomicLoad(&acc_rw[start + 1u]) == (1u | (1u << 16u)) {
        before = atomicLoad(&acc_rw[start + 2u]);
    }
    before = select(before, OUTLINE_NONE, before == e);
    store_look(outline_look(e, false), OutlineLook(before, e, vec2<f32>(0.0), vec2<f32>(0.0)));
}

// A look back (`outline_look`): the edge before the window, the edge in it whose start comes
// first, and the patterns' positions (hidden line, outline) from the window's start to the
// edge and from that edge.
struct OutlineLook {
    before: u32,
    best: u32,
    total: vec2<f32>,
    back: vec2<f32>,
}

fn load_look(at: u32) -> OutlineLook {
    let total = vec2<u32>(atomicLoad(&acc_rw[at + 2u]), atomicLoad(&acc_rw[at + 3u]));
    let back = vec2<u32>(atomicLoad(&acc_rw[at + 4u]), atomicLoad(&acc_rw[at + 5u]));
    return OutlineLook(atomicLoad(&acc_rw[at]), atomicLoad(&acc_rw[at + 1u]), bitcast<vec2<f32>>(total), bitcast<vec2<f32>>(back));
}

fn store_look(at: u32, l: OutlineLook) {
    atomicStore(&acc_rw[at], l.before);
    atomicStore(&acc_rw[at + 1u], l.best);
    atomicStore(&acc_rw[at + 2u], bitcast<u32>(l.total.x));
    atomicStore(&acc_rw[at + 3u], bitcast<u32>(l.total.y));
    atomicStore(&acc_rw[at + 4u], bitcast<u32>(l.back.x));
    atomicStore(&acc_rw[at + 5u], bitcast<u32>(l.back.y));
}

// x modulo the periods p; 0 where a period is 0 (no pattern).
fn wrap_periods(x: vec2<f32>, p: vec2<f32>) -> vec2<f32> {
    return select(vec2<f32>(0.0), x - p * floor(x / p), p > vec2<f32>(0.0));
}

// One round of looking back: edge e's window joins the window of the edge before it.
fn outline_jump(e: u32, from_b: bool) {
    var next = load_look(outline_look(e, from_b));
    let j = next.before;
    for (var go = j != OUTLINE_NONE; go; go = false) {
        let theirs = load_look(outline_look(j, from_b));
        let r = outline_record(j);
        let inst = instances[slot(atomicLoad(&acc_rw[r]))];
        let periods = vec2<f32>(inst.hidden_period, inst.outline_pattern.y);
        let step = bitcast<f32>(atomicLoad(&acc_rw[r + 3u])) + next.total;
        let take = comes_first(outline_start(theirs.best), outline_start(next.best));
        next = OutlineLook(theirs.before, select(next.best, theirs.best, take), wrap_periods(theirs.total + step, periods), select(next.back, wrap_periods(theirs.back + step, periods), take));
    }
    store_look(outline_look(e, !from_b), next);
}

@compute @workgroup_size(64)
fn outline_chain_jump_ab(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let e = outline_edge_of(group, lane);
    if e != OUTLINE_NONE {
        outline_jump(e, false);
    }
}

@compute @workgroup_size(64)
fn outline_chain_jump_ba(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let e = outline_edge_of(group, lane);
    if e != OUTLINE_NONE {
        outline_jump(e, true);
    }
}

// Where the patterns stand on outline edge `key` of `inst`: the hidden line's and the
// outline's position at the edge's start along the pattern, and +1 as they run from corner
// i, -1 from corner i + 1; a direction 0 where the edge is not in the outline chains (beyond
// their capacity).
fn outline_chain_anchor(inst: u32, key: u32) -> vec3<f32> {
    let mask = 2u * frame.chain_work.w - 1u;
    var h = outline_slot(inst, key);
    let slots = outline_slots();
    for (var probe = 0u; probe <= mask; probe++) {
        let k = atomicLoad(&acc_rw[slots + h]);
        if k == 0u {
            break;
        }
        let r = outline_record(k - 1u);
        if atomicLoad(&acc_rw[r]) == inst && atomicLoad(&acc_rw[r + 1u]) == key {
            // The looks back end in A: the rounds are even.
            let look = load_look(outline_look(k - 1u, false));
            let position = select(look.total, look.back, look.before != OUTLINE_NONE);
            return vec3<f32>(position, select(-1.0, 1.0, atomicLoad(&acc_rw[r + 2u]) != 0u));
        }
        h = (h + 1u) & mask;
    }
    return vec3<f32>(0.0);
}
#endif

// What a listed edge draws: its visible runs (into the lines), its hidden runs (HIDDEN, into
// the hidden lines); DRAW_OUTLINE: its visible line is an outline, else a drawn edge.
const DRAW_VISIBLE: u32 = 1u;
const DRAW_HIDDEN: u32 = 2u;
const DRAW_OUTLINE: u32 = 4u;
// A section's cut line (its plane in the bits from CUT_PLANE_SHIFT), of its own class.
const DRAW_CUT: u32 = 8u;
const CUT_PLANE_SHIFT: u32 = 4u;
// No section plane (`edge_span`'s `skip`).
const NO_PLANE: u32 = MAX_SECTIONS;
// An intersection line, of its own class.
const DRAW_INTERSECTION: u32 = 128u;

// Narrows [range.x, range.y] to the parameters u where lo <= p0 + u d <= hi.
fn keep_between(range: vec2<f32>, p0: f32, d: f32, lo: f32, hi: f32) -> vec2<f32> {
    if d == 0.0 {
        return select(vec2<f32>(1.0, 0.0), range, p0 >= lo && p0 <= hi);
    }
    let u0 = (lo - p0) / d;
    let u1 = (hi - p0) / d;
    return vec2<f32>(max(range.x, min(u0, u1)), min(range.y, max(u0, u1)));
}

// Where a clip-space point lands: full-image pixel coordinates, and 1/w, near/w, reverse
// depth (depth row / w, exact where it is small, unlike 1 − near/w) and view depth/w, which
// are affine along a screen segment.
struct Projected {
    xy: vec2<f32>,
    inv_w: f32,
    near_w: f32,
    reverse: f32,
    fade_w: f32,
}

fn project(c: vec4<f32>, depth: f32, fade: f32) -> Projected {
    let inv_w = 1.0 / c.w;
    let ndc = c.xy * inv_w;
    return Projected(vec2<f32>(0.5 * (ndc.x + 1.0), 0.5 * (1.0 - ndc.y)) * frame.image_size, inv_w, c.z * inv_w, depth * inv_w, fade * inv_w);
}

fn lerp_projected(a: Projected, b: Projected, k: f32) -> Projected {
    return Projected(mix(a.xy, b.xy, k), mix(a.inv_w, b.inv_w, k), mix(a.near_w, b.near_w, k), mix(a.reverse, b.reverse, k), mix(a.fade_w, b.fade_w, k));
}

// The loops' constants (RUN_SAMPLES_PER_PX visibility samples per pixel of edge length, each
// change between two then bisected RUN_BISECTIONS times; FOLD_STEPS and WALK_STEPS; up to
// MAX_RUNS visible runs a piece, the last absorbing the rest) and the pieces' lengths on a
// software rasterizer (SOFTWARE_PIECE_PX) are declared from src/gpu/loop_budget.rs:
// llvmpipe caps the loop iterations of a batch of lanes, and a piece's loops must keep under
// the cap.

// The length in pixels of the pieces of a line whose visibility window (`line_window`) has
// radius r: on a GPU (SHORT_PIECES) 1 px, which gives a frame's few outline edges more
// lanes; on a software rasterizer the longest that keeps under its loop cap.
fn piece_px(r: i32) -> f32 {
#if SHORT_PIECES
    return 1.0;
#else
    return select(select(SOFTWARE_PIECE_PX.z, SOFTWARE_PIECE_PX.y, r <= 2), SOFTWARE_PIECE_PX.x, r <= 1);
#endif
}
// The triangles a line lies on: t of `inst`, and n of `other`: an edge's neighbour across
// it (of the same instance; BACKGROUND_ID for none), or for an intersection line
// (`crossing`) the triangle it crosses, of the same instance or of another.
struct On {
    inst: u32,
    t: u32,
    other: u32,
    n: u32,
    crossing: bool,
    // The line's image reaches the box round where the instance crosses another
    // (`near_crossing`, set by clip_outline).
    near_crossing: bool,
}

// The screen segment of a line, clipped to the view and the targets, and the triangles
// it lies on.
struct Segment {
    start: Projected,
    end: Projected,
    on: On,
    // Position of `start` along the visible line's pattern (pixels from the pattern's
    // anchor), and +1 or -1 as the pattern runs towards `end` or away from it; then the
    // hidden line's.
    phase: f32,
    phase_dir: f32,
    hidden_phase: f32,
    hidden_dir: f32,
    // How the eye's ray reaches the line where no other surface tells (`capped`).
    cap: u32,
    // The line's ends (`LineEnds`).
    ends: LineEnds,
}

fn seg_at(s: Segment, k: f32) -> Projected {
    return lerp_projected(s.start, s.end, k);
}

// The class of the segment's point at k: 0 visible, 1 hidden (by a surface of the scene, or
// by the host's where hidden lines are drawn behind it), 2 neither drawn (behind the host).
// Without HIDDEN only visible or not: 0 or 1.
fn seg_class(s: Segment, k: f32) -> u32 {
    // Each end's class is that of the point END_INSET pixels along (twin of `END_INSET` in
    // src/edge_math.rs): at a vertex every triangle round it agrees with the line only to
    // rounding, and a run of no length is still drawn as a dot a line wide.
    let inset = min(END_INSET / max(distance(s.start.xy, s.end.xy), 1e-30), 0.5);
    let q = seg_at(s, clamp(k, inset, 1.0 - inset));
    let w = 1.0 / q.inv_w;
    let c = class_at(q.xy, q.near_w * w, w, q.reverse, s.on, s.cap, s.ends);
#if HIDDEN
    let behind_host = (instances[slot(s.on.inst)].flags & INSTANCE_BEHIND_HOST) != 0u;
    return select(c, 1u, c == 2u && behind_host);
#else
    return min(c, 1u);
#endif
}

// Edge a -> b of `inst` projected: the parameters s.x..s.y of the part in front of the near
// plane and not beyond the far one (none where s.x > s.y), and the projections of its ends.
struct Span {
    s: vec2<f32>,
    p0: Projected,
    p1: Projected,
}

fn edge_span(inst: u32, a: vec3<f32>, b: vec3<f32>, skip: u32) -> Span {
    var span: Span;
    let clip = instances[slot(inst)].clip;
    let ha = vec4<f32>(a, 1.0);
    let hb = vec4<f32>(b, 1.0);
    let ca = clip * ha;
    let cb = clip * hb;
    let depth_row = instances[slot(inst)].depth_row;
    let fade_row = instances[slot(inst)].fade_row;
    let near_cut = keep_positive(vec2<f32>(0.0, 1.0), ca.z, cb.z);
    var s = keep_positive(near_cut, dot(depth_row, ha), dot(depth_row, hb));
    // Not behind a section plane (unused planes are 0, which keeps everything); a cut line
    // is not clipped by its own plane, on which it lies (`skip`).
#if SECTIONS
    for (var k = 0u; k < MAX_SECTIONS; k++) {
        let own = k == skip;
        s = keep_positive(s, select(dot(frame.sections[k], ca), 1.0, own), select(dot(frame.sections[k], cb), 1.0, own));
    }
#endif
    span.s = s;
    if !(s.x <= s.y) {
        return span;
    }
    let da = dot(depth_row, ha);
    let db = dot(depth_row, hb);
    let fa = dot(fade_row, ha);
    let fb = dot(fade_row, hb);
    span.p0 = project(on_near_plane(mix(ca, cb, s.x), s.x > 0.0 && s.x == near_cut.x), mix(da, db, s.x), mix(fa, fb, s.x));
    span.p1 = project(on_near_plane(mix(ca, cb, s.y), s.y < 1.0 && s.y == near_cut.y), mix(da, db, s.y), mix(fa, fb, s.y));
    return span;
}

// Clip-space point c, where the near plane cut the edge there (`cut`), with the near plane's
// own w (`frame.near_w`) and near row 0: interpolated between the edge's ends, w loses its
// leading digits where they lie far from the plane, and a cut that projects far off-screen
// moves by pixels, and with it the patterns measured from it.
fn on_near_plane(c: vec4<f32>, cut: bool) -> vec4<f32> {
    return select(c, vec4<f32>(c.xy, 0.0, frame.near_w), cut && frame.near_w > 0.0);
}

// Line a -> b (in the local coordinates of `on.inst`) on screen: its segment in front of
// the near plane, not beyond the far one, and inside the image and its guard band (not the
// targets: a tile then samples and bisects the same points as the whole image, and computes
// exactly what the whole image does), its length, and the pieces it is drawn in (0 when
// nothing is left of it). The line patterns stand at `anchor` (`pattern_anchor`: visible,
// hidden) where the near or far plane leaves the edge's start (a when the direction is +1,
// b when -1).
struct Clipped {
    seg: Segment,
    length_px: f32,
    pieces: u32,
}

fn clip_outline(on: On, a: vec3<f32>, b: vec3<f32>, anchor: vec4<f32>, skip: u32) -> Clipped {
    let inst = on.inst;
    var c: Clipped;
    c.pieces = 0u;
    let span = edge_span(inst, a, b, skip);
    if !(span.s.x <= span.s.y) {
        return c;
    }
    let p0 = span.p0;
    let p1 = span.p1;
    let d = p1.xy - p0.xy;
    let lo = -frame.output_offset;
    let hi = frame.image_size + frame.output_offset;
    var u = keep_between(vec2<f32>(0.0, 1.0), p0.xy.x, d.x, lo.x, hi.x);
    u = keep_between(u, p0.xy.y, d.y, lo.y, hi.y);
    if !(u.x <= u.y) {
        return c;
    }
    c.seg.start = lerp_projected(p0, p1, u.x);
    c.seg.end = lerp_projected(p0, p1, u.y);
    c.seg.on = on;
    // An edge's ends are mesh vertices; a cut line's and an intersection line's are not.
    c.seg.ends = LineEnds(skip == NO_PLANE && !on.crossing, a, b);
    let full = length(d);
    c.seg.phase = anchor.x + select((1.0 - u.x) * full, u.x * full, anchor.y > 0.0);
    c.seg.phase_dir = anchor.y;
    c.seg.hidden_phase = anchor.z + select((1.0 - u.x) * full, u.x * full, anchor.w > 0.0);
    c.seg.hidden_dir = anchor.w;
    c.length_px = length(c.seg.end.xy - c.seg.start.xy);
    c.seg.on.near_crossing = near_crossing(on, c.seg.start.xy, c.seg.end.xy);
    c.pieces = max(u32(ceil(c.length_px / piece_px(line_window(c.seg.on).r))), 1u);
    return c;
}

// Whether the image segment p -> q of a line on `on` reaches the box round the crossings of
// an instance it lies on that another passes through (`Instance.cross_box`): only there do
// its visibility and its drawn edges need the crossing way.
fn near_crossing(on: On, p: vec2<f32>, q: vec2<f32>) -> bool {
    let lo = min(p, q);
    let hi = max(p, q);
    var near = false;
#if CROSSINGS
    // Loops, not `if`s: a software rasterizer skips a loop no lane enters, and runs the
    // body of an `if` for every lane.
    for (var j = 0u; j < 2u; j++) {
        let inst = select(on.other, on.inst, j == 0u);
        for (var crossed = (instances[slot(inst)].flags & INSTANCE_CROSSED) != 0u; crossed; crossed = false) {
            let b = instances[slot(inst)].cross_box;
            near = near || (all(lo <= b.zw) && all(hi >= b.xy));
        }
    }
#endif
    return near;
}

// The planes (of clip points: rows x, y, near, w) bounding what lies in front of the near
// plane and projects into the box of image pixels `lo`..`hi`, that box cut to the image
// and its guard band first (unbounded boxes stay finite).
fn box_planes(lo_px: vec2<f32>, hi_px: vec2<f32>) -> array<vec4<f32>, 5> {
    let lo = 2.0 * max(lo_px, -frame.output_offset) / frame.image_size - 1.0;
    let hi = 2.0 * min(hi_px, frame.image_size + frame.output_offset) / frame.image_size - 1.0;
    // Image y runs down, clip y up.
    return array<vec4<f32>, 5>(
        vec4<f32>(1.0, 0.0, 0.0, -lo.x),
        vec4<f32>(-1.0, 0.0, 0.0, hi.x),
        vec4<f32>(0.0, -1.0, 0.0, -lo.y),
        vec4<f32>(0.0, 1.0, 0.0, hi.y),
        vec4<f32>(0.0, 0.0, 1.0, 0.0),
    );
}

// The box round the crossings of `inst` (`Instance.cross_box`) grown by its drawn edges'
// reach and a pixel: the edge pass leaves the edges of a triangle whose pixel lies in the
// box, so every triangle with an edge within reach of the box has its edges drawn here.
fn crossing_reach_box(inst: u32) -> vec4<f32> {
    let grow = line_reach(instances[slot(inst)].line_width) + 1.0;
    return instances[slot(inst)].cross_box + vec4<f32>(-grow, -grow, grow, grow);
}

// Whether triangle p (local corners of `inst`) may reach the box `b` of image pixels: no
// plane of the box has all three corners outside it.
fn triangle_meets(inst: u32, p: array<vec3<f32>, 3>, b: vec4<f32>) -> bool {
    let planes = box_planes(b.xy, b.zw);
    let clip = instances[slot(inst)].clip;
    let c0 = clip * vec4<f32>(p[0], 1.0);
    let c1 = clip * vec4<f32>(p[1], 1.0);
    let c2 = clip * vec4<f32>(p[2], 1.0);
    var meets = b.x <= b.z && b.y <= b.w;
    for (var k = 0u; k < 5u; k++) {
        let r = planes[k];
        meets = meets && !(dot(r, c0) < 0.0 && dot(r, c1) < 0.0 && dot(r, c2) < 0.0);
    }
    return meets;
}

// The reach of a line of `inst` drawn as `mode` says: of its visible line and, with
// DRAW_HIDDEN, its hidden one.
fn line_reach_of(inst: u32, mode: u32) -> f32 {
    var visible_width = select(instances[slot(inst)].line_width, instances[slot(inst)].outline_width, (mode & DRAW_OUTLINE) != 0u);
    visible_width = select(visible_width, frame.section_width, (mode & DRAW_CUT) != 0u);
    visible_width = select(visible_width, frame.intersection_width, (mode & DRAW_INTERSECTION) != 0u);
    var reach = select(0.0, line_reach(visible_width), (mode & DRAW_VISIBLE) != 0u);
#if HIDDEN
    reach = max(reach, select(0.0, line_reach(instances[slot(inst)].hidden_width), (mode & DRAW_HIDDEN) != 0u));
#endif
    return reach;
}

// Lists the pieces of line `word` (i | mode << 2: edge i, or a cut line) of triangle t of
// `inst` (local corners p) that lie within reach of the targets (of a tile) for
// trace_pieces_main, to draw as `mode` says (DRAW_VISIBLE, DRAW_HIDDEN): false where the
// list had no room for them all.
fn list_outline(inst: u32, t: u32, p: array<vec3<f32>, 3>, word: u32) -> bool {
    let i = word & 3u;
    let mode = word >> 2u;
    let e = edge_ends(inst, t, p, i, mode);
    // The pattern's anchor only matters where a piece is drawn (the piece pass finds it for
    // the pieces it draws): looking it up for every listed edge would cost every lane.
    let c = clip_outline(On(inst, t, inst, e.n, false, false), e.a, e.b, vec4<f32>(0.0, 1.0, 0.0, 1.0), cut_plane(mode));
    let item = Listed(inst, t, i, mode, 0u, c.pieces);
    return list_all(item, pieces_in_reach(c, line_reach_of(inst, mode)));
}

// Finds the visible (and, with DRAW_HIDDEN in `mode`, the hidden) runs of the segment
// between parameters k0 and k1, then writes the key of the nearest of them into every pixel
// within reach.
fn draw_piece(seg: Segment, k0: f32, k1: f32, length_px: f32, mode: u32) {
    var runs: array<vec2<f32>, MAX_RUNS>;
    var count = 0u;
    var hidden_runs: array<vec2<f32>, MAX_RUNS>;
    var hidden_count = 0u;
    let steps = max(u32(ceil(length_px * (k1 - k0) * RUN_SAMPLES_PER_PX)), 1u);
    // One loop and one call of seg_class: sample k0 and then each step; where the class
    // changes between two steps, the next RUN_BISECTIONS iterations bisect that interval.
    // (A shader holding one copy of the visibility test instead of three compiles smaller,
    // and lavapipe runs every copy for every lane.)
    var j = 0u;
    var bisections = 0u;
    var last_k = k0;
    var last_class = 0u;
    var step_class = 0u;
    var start = k0;
    var lo = k0;
    var hi = k0;
    var step_k = k0;
    loop {
        var k = mix(k0, k1, f32(j) / f32(steps));
        if bisections > 0u {
            k = 0.5 * (lo + hi);
        }
        let now = seg_class(seg, k);
        var ended = false;
        if bisections > 0u {
            if now == last_class {
                lo = k;
            } else {
                hi = k;
            }
            bisections -= 1u;
            if bisections == 0u {
                // The change between last_k and step_k lies between lo and hi.
                ended = true;
                j++;
            }
        } else if j == 0u {
            last_class = now;
            j = 1u;
        } else if now != last_class {
            lo = last_k;
            hi = k;
            step_k = k;
            step_class = now;
            bisections = RUN_BISECTIONS;
        } else {
            last_k = k;
            j++;
        }
        if ended {
            // The run of last_class from start ends at lo.
            push_run(&runs, &count, &hidden_runs, &hidden_count, last_class, vec2<f32>(start, lo));
            start = hi;
            last_class = step_class;
            last_k = step_k;
        }
        if bisections == 0u && j > steps {
            push_run(&runs, &count, &hidden_runs, &hidden_count, last_class, vec2<f32>(start, k1));
            break;
        }
    }
    if (mode & DRAW_VISIBLE) != 0u && count > 0u {
        var kind = select(select(LINE_CLASS_EDGE, LINE_CLASS_OUTLINE, (mode & DRAW_OUTLINE) != 0u), LINE_CLASS_CUT, (mode & DRAW_CUT) != 0u);
        kind = select(kind, LINE_CLASS_INTERSECTION, (mode & DRAW_INTERSECTION) != 0u);
        splat_runs(seg, k0, k1, &runs, count, kind);
    }
#if HIDDEN
    if (mode & DRAW_HIDDEN) != 0u && hidden_count > 0u {
        splat_runs(seg, k0, k1, &hidden_runs, hidden_count, LINE_CLASS_HIDDEN);
    }
#endif
}

// Appends a run of class `kind` (seg_class) to the visible or the hidden runs; past MAX_RUNS
// the last one absorbs it.
fn push_run(runs: ptr<function, array<vec2<f32>, MAX_RUNS>>, count: ptr<function, u32>, hidden_runs: ptr<function, array<vec2<f32>, MAX_RUNS>>, hidden_count: ptr<function, u32>, kind: u32, run: vec2<f32>) {
    if kind == 0u {
        if *count < MAX_RUNS {
            (*runs)[*count] = run;
            *count += 1u;
        } else {
            (*runs)[MAX_RUNS - 1u].y = run.y;
        }
    } else if kind == 1u {
        if *hidden_count < MAX_RUNS {
            (*hidden_runs)[*hidden_count] = run;
            *hidden_count += 1u;
        } else {
            (*hidden_runs)[MAX_RUNS - 1u].y = run.y;
        }
    }
}

// Writes into every pixel within reach of the segment's `runs` (parameters, between k0 and
// k1) the key of their nearest point, for a line of class `kind`: an edge's or an
// outline's visible line, or (LINE_CLASS_HIDDEN) a dash of the hidden-line pattern, in the hidden
// lines' word.
fn splat_runs(seg: Segment, k0: f32, k1: f32, runs: ptr<function, array<vec2<f32>, MAX_RUNS>>, count: u32, kind: u32) {
    var width = select(instances[slot(seg.on.inst)].line_width, instances[slot(seg.on.inst)].outline_width, kind == LINE_CLASS_OUTLINE);
    width = select(width, frame.section_width, kind == LINE_CLASS_CUT);
    width = select(width, frame.intersection_width, kind == LINE_CLASS_INTERSECTION);
    var pattern = vec2<f32>(0.0);
    var phase = seg.phase;
    var phase_dir = seg.phase_dir;
    var behind_host = false;
    let hidden = kind == LINE_CLASS_HIDDEN;
#if PATTERNS
    pattern = select(instances[slot(seg.on.inst)].edge_pattern, instances[slot(seg.on.inst)].outline_pattern, kind == LINE_CLASS_OUTLINE);
    pattern = select(pattern, vec2<f32>(0.0), kind == LINE_CLASS_CUT || kind == LINE_CLASS_INTERSECTION);
#endif
#if HIDDEN
    if hidden {
        let inst = instances[slot(seg.on.inst)];
        width = inst.hidden_width;
#if PATTERNS
        pattern = vec2<f32>(inst.hidden_dash, inst.hidden_period);
        phase = seg.hidden_phase;
        phase_dir = seg.hidden_dir;
#endif
        behind_host = (inst.flags & INSTANCE_BEHIND_HOST) != 0u;
    }
#endif
    let reach = line_reach(width);
    let along = seg.end.xy - seg.start.xy;
    let q0 = seg.start.xy + k0 * along;
    let q1 = seg.start.xy + k1 * along;
    let span = q1 - q0;
    let len2 = dot(along, along);
    // Pattern positions: phase + phase_dir * k * seg_length.
    let seg_length = sqrt(len2);
    let scale = phase_dir * seg_length;
    // Walk the pixels along the piece's major axis; across it, the band within reach of the
    // line is at most reach × √2 wide on either side (slope <= 1), plus a pixel for rounding.
    // Pixels are addressed in target coordinates.
    let major = select(1u, 0u, abs(span.x) >= abs(span.y));
    let minor = 1u - major;
    let last = vec2<i32>(frame.target_size) - 1;
    let origin = frame.target_origin;
    let band = reach * 1.4142135 + 1.0;
    let first_m = max(i32(floor(min(q0[major], q1[major]) - reach - origin[major])), 0);
    let last_m = min(i32(ceil(max(q0[major], q1[major]) + reach - origin[major])), last[major]);
    let first_o = max(i32(floor(min(q0[minor], q1[minor]) - band - origin[minor])), 0);
    let last_o = min(i32(ceil(max(q0[minor], q1[minor]) + band - origin[minor])), last[minor]);
    mark_traced_tiles(first_m, last_m, first_o, last_o, major);
    for (var m = first_m; m <= last_m; m++) {
        var f = 0.0;
        if span[major] != 0.0 {
            f = clamp((f32(m) + 0.5 + origin[major] - q0[major]) / span[major], 0.0, 1.0);
        }
        let across = q0[minor] + f * span[minor] - origin[minor];
        let first_o = max(i32(floor(across - band)), 0);
        let last_o = min(i32(ceil(across + band)), last[minor]);
        for (var o = first_o; o <= last_o; o++) {
            var xy = vec2<i32>(m, o);
            if major == 1u {
                xy = vec2<i32>(o, m);
            }
            let pixel = vec2<f32>(xy) + origin + 0.5;
            // Nearest point of the nearest run (of a dash in it, for a pattern).
            var k = 0.0;
            if len2 > 0.0 {
                k = dot(pixel - seg.start.xy, along) / len2;
            }
            var best = NO_EDGE;
            var best_k = 0.0;
            for (var r = 0u; r < count; r++) {
                let run = (*runs)[r];
                var kr = clamp(k, run.x, run.y);
                if pattern.y > 0.0 && scale != 0.0 {
                    let sa = phase + scale * run.x;
                    let sb = phase + scale * run.y;
                    let sr = dash_nearest(phase + scale * k, min(sa, sb) - DASH_SLACK, max(sa, sb) + DASH_SLACK, pattern.x, pattern.y);
                    if sr == NO_EDGE {
                        continue;
                    }
                    kr = clamp((sr - phase) / scale, run.x, run.y);
                }
                let dr = distance(pixel, seg.start.xy + kr * along);
                if dr < best {
                    best = dr;
                    best_k = kr;
                }
            }
            // Within reach, and the slack the f64 definition allows too (the line is of no
            // intensity out there).
            if !(best < reach + REACH_SLACK) {
                continue;
            }
            let q = seg_at(seg, best_k);
#if HOST
            // The pixel shows the host, and its surface is in front of the line's point.
            if !behind_host && host_hides_line(xy, q.reverse, best) {
                continue;
            }
#endif
            let fade = depth_fade(q.fade_w / q.inv_w, frame.fade);
            let key = line_key(line_intensity(best, width) * fade, best);
            let index = u32(xy.y) * u32(frame.target_size.x) + u32(xy.x);
#if HIDDEN
            if hidden {
#if COLORS
                atomicMax(&acc_rw[hidden_lines() + 2u * index], key);
                atomicMax(&acc_rw[hidden_lines() + 2u * index + 1u], (key & 0xfff00000u) | seg.on.inst);
#else
                atomicMax(&acc_rw[hidden_lines() + index], key);
#endif
                continue;
            }
#endif
#if COLORS
            atomicMax(&acc_rw[2u * index], key);
            var owner = select(select(0u, OWNER_OUTLINE, kind == LINE_CLASS_OUTLINE), OWNER_CUT, kind == LINE_CLASS_CUT);
            owner = select(owner, OWNER_INTERSECTION, kind == LINE_CLASS_INTERSECTION);
            atomicMax(&acc_rw[2u * index + 1u], (key & 0xfff00000u) | owner | seg.on.inst);
#else
            atomicMax(&acc_rw[index], key);
#endif
        }
    }
}

// Lists the output tiles that pixels [first_m, last_m] along axis `major` and
// [first_o, last_o] across it (target pixels) fall in, each once a frame (its mark is
// cleared with the lines).
fn mark_traced_tiles(first_m: i32, last_m: i32, first_o: i32, last_o: i32, major: u32) {
    var lo = vec2<i32>(first_m, first_o);
    var hi = vec2<i32>(last_m, last_o);
    if major == 1u {
        lo = lo.yx;
        hi = hi.yx;
    }
    let offset = vec2<i32>(frame.output_offset);
    let columns = (u32(frame.output_size.x) + 7u) / 8u;
    let tiles = vec2<i32>(i32(columns), i32((u32(frame.output_size.y) + 7u) / 8u)) - 1;
    let t0 = clamp((lo - offset) / 8, vec2<i32>(0), tiles);
    let t1 = clamp((hi - offset) / 8, vec2<i32>(0), tiles);
    let marks = traced_tile_marks();
    let list = traced_tile_list();
    for (var y = t0.y; y <= t1.y; y++) {
        for (var x = t0.x; x <= t1.x; x++) {
            if atomicExchange(&acc_rw[marks + u32(y) * columns + u32(x)], 1u) == 0u {
                let k = atomicAdd(&acc_rw[list + 3u], 1u);
                atomicStore(&acc_rw[list + 4u + k], u32(x) | (u32(y) << 16u));
                let size = list_size(k, 1u);
                atomicMax(&acc_rw[list], size.x);
                atomicMax(&acc_rw[list + 1u], size.y);
            }
        }
    }
}

// Whether the point at screen point x (near row `near`, w `w`, reverse depth `reverse`) of a
// line on the triangles `on` is visible (0), hidden by a triangle other than those
// (`lies_on`) that covers x nearer than the point (1), or by the host (2,
// host_hides_point). The candidates are the triangles the rasterizer gave the 3×3 pixel
// centres around x (5×5, and the line's triangles' other neighbours, in a frame with
// section planes; a sliver of surface in front of the edge may own no centre next to x,
// but one a pixel further on), and those a walk across edges
// from them reaches when they do not cover x themselves (x may lie in a small triangle that
// owns none of those centres). A walk ends at a fold (`locate`): beyond it the surface lies
// on this side of the fold's edge, and a walk towards x, a point of a silhouette, would
// only bounce between the edge's two triangles or wander over the far side for all its
// steps, the slowest lane holding up its batch.
//
// In a frame with section planes (`cap` not CAP_NONE) a point the eye's ray reaches from
// inside a cut solid lies behind its section face, and is hidden too: where the nearest
// surface in front of it (within HIDDEN_MARGIN) faces away, the ray came out of the solid
// through it; where that surface faces the eye, it went in there; where none is nearer by
// CAP_MARGIN, the line's own triangles tell (CAP_INSIDE).
fn class_at(x: vec2<f32>, near: f32, w: f32, reverse: f32, on: On, cap: u32, ends: LineEnds) -> u32 {
    let centre = vec2<i32>(floor(x - frame.target_origin));
    if host_hides_point(x - frame.target_origin, reverse) {
        return 2u;
    }
    // The last triangle walked from, and its walk's steps: a walk starts from a triangle,
    // not from its pixel, so the same triangle again needs walking only with more steps (a
    // triangle met first in the outer ring, then next to x).
    var last = vec2<u32>(BACKGROUND_ID, 0u);
    var last_steps = 0u;
    // The nearest surface in front of the point within HIDDEN_MARGIN: its near row, and 1
    // where it faces away (where none is, the line's own triangles tell).
    var front = vec2<f32>(near, select(0.0, 1.0, cap == CAP_INSIDE));
    let window = line_window(on);
    let wide = window.wide;
    let r = window.r;
    let across = 2 * r + 1;
    for (var k = 0; k < across * across; k++) {
        let offset = vec2<i32>(k % across - r, k / across - r);
        let id = id_at(centre + offset);
        // The outer ring's walks only cross the sheet's last few triangles to x.
        let steps = select(WALK_STEPS, FOLD_STEPS, max(abs(offset.x), abs(offset.y)) > 1);
        if id.x >= HOST_ID || lies_on(on, id.x, id.y) || (all(id == last) && steps <= last_steps) {
            continue;
        }
        last = id;
        last_steps = steps;
        if hides(locate(id.x, id.y, x, steps, true), on, ends, near, w, &front) {
            return 1u;
        }
    }
#if WIDE
    if wide {
        // And the line's own triangles' other neighbours, and a few triangles on from them
        // that face the same way: a sheet that folds back over the line starts there (the
        // walks from the pixels stop at such folds).
        for (var j = 0u; j < 6u; j++) {
            let owner = select(on.n, on.t, j < 3u);
            let owner_inst = select(on.other, on.inst, j < 3u);
            if owner == BACKGROUND_ID {
                continue;
            }
            let m = neighbour(instances[slot(owner_inst)].triangle_base + owner, j % 3u);
            if m == BACKGROUND_ID || lies_on(on, owner_inst, m) {
                continue;
            }
            if hides(locate(owner_inst, m, x, FOLD_STEPS, true), on, ends, near, w, &front) {
                return 1u;
            }
        }
    }
#endif
    return select(0u, 1u, cap != CAP_NONE && front.y > 0.0);
}

// The window of pixel ids `class_at` looks at round a point of a line on the triangles `on`
// (`on.crossing`: an intersection line on both): its radius (one of
// loop_budget::WINDOW_RADII), and whether it is wide, where class_at also walks from the
// line's triangles' other neighbours.
struct Window {
    r: i32,
    wide: bool,
}

fn line_window(on: On) -> Window {
#if !WIDE
    return Window(1, false);
#else
    // Through a section's cut the eye sees the inside of folded surfaces, where the sheet in
    // front of an interior silhouette thins out near a fold of its own: look two pixels
    // round for it there.
    // Where surfaces cross, the surface a line passes into may show only a few pixels away
    // (where those in front of it end): look four pixels round (instance_crossings::CROSSING_BAND).
    let bits = info[instances[slot(on.inst)].triangle_base + on.t] | select(0u, info[instances[slot(on.other)].triangle_base + on.n], on.n != BACKGROUND_ID);
    let crossed = (bits & INFO_CROSSED) != 0u || on.near_crossing;
    let wide = frame.sections_on != 0u || crossed;
    // An intersection line lies on both surfaces that cross there, so no surface passes
    // into view beyond it: it takes a section's window.
    return Window(select(select(select(WINDOW_RADII.x, WINDOW_RADII.y, wide), WINDOW_RADII.z, crossed), WINDOW_RADII.y, on.crossing), wide);
#endif
}

// Whether triangle `tri` of instance `inst` is one the line lies on.
fn lies_on(on: On, inst: u32, tri: u32) -> bool {
    return (inst == on.inst && tri == on.t) || (inst == on.other && tri == on.n);
}

// Whether sample s of a triangle the line does not lie on covers the line's point (near
// row `near`, w `w`) nearer than it (by HIDDEN_MARGIN); else keeps in `front` the nearest
// one within that margin but nearer by CAP_MARGIN, and whether it faces away. A triangle
// with a corner at an end of the line (an edge's, `ends`) that covers a point within
// COVERAGE_MARGIN of its edges covers it only where `fan_covers` agrees: its two edges
// through that vertex pass within f32 rounding of the line's points near it, and of all its
// points where the line runs along one of them on screen (beside a triangle seen edge-on).
fn hides(s: Sample, on: On, ends: LineEnds, near: f32, w: f32, front: ptr<function, vec2<f32>>) -> bool {
    if lies_on(on, s.inst, s.tri) {
        return false;
    }
    let in_front = nearer(s.near, near, w);
    var covers = s.covers;
    // Farther from the triangle's edges rounding does not decide, and behind the point
    // coverage does not matter. (A loop, not an `if`: a software rasterizer skips a loop no
    // lane enters, and runs the body of an `if` for every lane.)
    for (var near_edge = s.covers && in_front && ends.edge && s.inst == on.inst && s.margin < COVERAGE_MARGIN; near_edge; near_edge = false) {
        let at_a = all(s.v0.xyz == ends.a) || all(s.v1.xyz == ends.a) || all(s.v2.xyz == ends.a);
        let at_b = all(s.v0.xyz == ends.b) || all(s.v1.xyz == ends.b) || all(s.v2.xyz == ends.b);
        if at_a || at_b {
            let v = select(ends.b, ends.a, at_a);
            covers = fan_covers(s, v, select(ends.a, ends.b, at_a) - v);
        }
    }
    if !covers {
        return false;
    }
    if in_front {
        return true;
    }
#if SECTIONS
    if nearer_than_cap(s.near, near, w) && s.near < (*front).x {
        *front = vec2<f32>(s.near, select(0.0, 1.0, faces_away(s.inst, s.v0.xyz, s.v1.xyz, s.v2.xyz)));
    }
#endif
    return false;
}

// A line's ends in the local coordinates of its instance, and whether they are mesh
// vertices (`edge`: an edge's, not a cut line's or an intersection line's).
struct LineEnds {
    edge: bool,
    a: vec3<f32>,
    b: vec3<f32>,
}

// Whether sample s, a triangle with a corner at v that rounding says covers a point of the
// line leaving v along direction `d`, in front of it, does: the line's direction lies inside
// the triangle's angle at v as seen from the eye (the triangle lies inside that angle), and
// the line leaves v to the far side of the triangle's plane. Both hold all along the line or
// nowhere on it, and are triple products of the differences from v in the instance's own
// coordinates (as `is_silhouette`'s): f32 keeps them where a point near v, or near the
// triangle's edges through v, loses its side, and where a line runs along such an edge
// (beside a triangle seen edge-on). Where one of them is within EDGE_ON of 0 they do not
// decide, nor with v behind the eye (a line the near plane cuts): the sample's coverage
// stands.
fn fan_covers(s: Sample, v: vec3<f32>, d: vec3<f32>) -> bool {
    // The triangle's two other corners.
    var p = array<vec3<f32>, 2>(s.v1.xyz, s.v2.xyz);
    if all(s.v1.xyz == v) {
        p = array<vec3<f32>, 2>(s.v2.xyz, s.v0.xyz);
    } else if all(s.v2.xyz == v) {
        p = array<vec3<f32>, 2>(s.v0.xyz, s.v1.xyz);
    }
    let e1 = p[0] - v;
    let e2 = p[1] - v;
    let to_eye = towards_eye(v, instances[slot(s.inst)].eye);
    let n = cross(e1, e2);
    let turn = select(-1.0, 1.0, dot(to_eye, n) > 0.0);
    // Each side of d against an edge, positive inside the angle, and the sines' margins.
    let side1 = turn * dot(to_eye, cross(e1, d));
    let side2 = turn * dot(to_eye, cross(d, e2));
    let scale = EDGE_ON * length(to_eye) * length(d);
    let margin = scale * vec2<f32>(length(e1), length(e2));
    let inside = dot(to_eye, n) != 0.0 && side1 > margin.x && side2 > margin.y;
    let outside = side1 < -margin.x || side2 < -margin.y;
    // Positive where the line leaves v towards the eye's side of the triangle's plane.
    let eye_side = dot(n, d) * sign(dot(n, to_eye));
    let plane = EDGE_ON * length(n) * length(d);
    let in_front = eye_side < -plane;
    let behind = eye_side > plane;
    let ahead = (instances[slot(s.inst)].clip * vec4<f32>(v, 1.0)).w > 0.0;
    let decided = ahead && (outside || (inside && (in_front || behind)));
    return !decided || (inside && in_front);
}
