// The outline pass (Style::silhouettes), assembled after edge_pass.wgsl, whose mesh bindings
// and exact per-point triangle test (`sample`) it shares. It runs between the visibility pass
// and the edge pass, which reads what it leaves in `outline_acc`.
//
// A triangle only colours its own pixels, so the edge pass alone draws an outline edge (a
// boundary, or a silhouette: see `is_silhouette`) at half width. Outline triangles are nearly
// edge-on and often own no pixel centre at all, so they cannot be found from the ids around a
// pixel; instead one invocation per triangle finds its outline edges, the visible runs of each
// (points every 1/4 px tested, changes bisected), and writes into every pixel within the line's
// reach the distance to the nearest visible run. Only triangles of the clusters that
// `outline_cull` lists are visited, so the pass reads few triangles beyond those near an
// outline. Definition (src/outline.rs implements it in f64 for the ground truth): pixel p is
// at distance d from an outline when d is the distance from p's centre to the visible part of
// the edge's projection (in front of the near plane, inside the image, not hidden by another
// surface). No depth test at p is needed: a nearer surface between p and a farther edge has
// its own outline between them, which is nearer to p and wins the minimum. Each pixel keeps
// the least distance (and its depth fade) by an atomic max on `pack_outline`, so nothing is
// drawn twice.

@group(1) @binding(6) var<storage, read_write> outline_acc: array<atomic<u32>>;
// One Cluster per OUTLINE_GROUP triangles of `cluster_triangles` (src/mesh/clusters.rs).
@group(1) @binding(7) var<storage, read> clusters: array<Cluster>;
@group(1) @binding(8) var<storage, read_write> outline_list: OutlineList;
@group(1) @binding(9) var<storage, read_write> outline_args: OutlineArgs;
// Triangle ids in cluster order: cluster c holds entries OUTLINE_GROUP × c and on.
@group(1) @binding(10) var<storage, read> cluster_triangles: array<u32>;

// The clusters that `outline_cull` finds may hold an outline edge; starts with count zero.
struct OutlineList {
    count: atomic<u32>,
    clusters: array<u32>,
}

// The indirect dispatch size of `outline_main`, as `outline_cull` leaves it; starts zeroed.
struct OutlineArgs {
    x: atomic<u32>,
    y: u32,
    z: u32,
}

// Triangles per cluster, and invocations per workgroup of both entry points.
const OUTLINE_GROUP: u32 = 64u;
// Workgroups of `outline_main` at most; each then takes every MAX_OUTLINE_GROUPS-th listed
// cluster. Below every device's max_compute_workgroups_per_dimension (at least 65535).
const MAX_OUTLINE_GROUPS: u32 = 16384u;

// A point on an edge is hidden when a surface there is nearer than this share of its depth.
// Triangles sharing the edge's end vertices meet it at equal depth; this keeps their f32
// rounding from hiding it.
const HIDDEN_MARGIN: f32 = 1.0e-4;

// Lists the clusters that may hold an outline edge from this eye (`cluster_may_fold`), so that
// the triangles of the others, usually nearly all, are never read.
@compute @workgroup_size(64)
fn outline_cull(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Dispatched as a 2D grid: huge meshes have more clusters than one dimension allows.
    let c = gid.x + gid.y * groups.x * OUTLINE_GROUP;
    if c == 0u {
        outline_args.y = 1u;
        outline_args.z = 1u;
    }
    if c >= (frame.triangles + OUTLINE_GROUP - 1u) / OUTLINE_GROUP || !cluster_may_fold(clusters[c], frame.eye.xyz) {
        return;
    }
    let k = atomicAdd(&outline_list.count, 1u);
    outline_list.clusters[k] = c;
    atomicMax(&outline_args.x, min(k + 1u, MAX_OUTLINE_GROUPS));
}

// One invocation per triangle of each listed cluster.
@compute @workgroup_size(64)
fn outline_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32, @builtin(num_workgroups) groups: vec3<u32>) {
    let count = atomicLoad(&outline_list.count);
    for (var k = group.x; k < count; k += groups.x) {
        let i = outline_list.clusters[k] * OUTLINE_GROUP + lane;
        if i < frame.triangles {
            outline_triangle(cluster_triangles[i]);
        }
    }
}

// Finds the outline edges of triangle t and draws them.
fn outline_triangle(t: u32) {
    let v = corners(t);
    var p = array<vec3<f32>, 3>(position(v.x), position(v.y), position(v.z));
    // Most triangles are seen well away from edge-on, further than their edges fold: none of
    // their neighboured edges can be a silhouette (Mesh::outline_hints), and they skip the
    // neighbours' vertices. The angle is taken from the triangle's farthest vertex, its least.
    let hints = (edge_masks[t >> 2u] >> ((t & 3u) * 8u + 3u)) & 31u;
    let boundary = (hints & 1u) != 0u;
    // Decoded as adjacency::fold_bound: 0 flat, 2^(q - 14) with a margin, 15 never skip.
    let q = hints >> 1u;
    var fold_bound = exp2(f32(q) - 14.0) * 1.01 + 1e-6;
    if q == 0u {
        fold_bound = 1e-6;
    } else if q == 15u {
        fold_bound = 2.0;
    }
    let normal = cross(p[1] - p[0], p[2] - p[0]);
    let eye = frame.eye.xyz;
    let height = abs(dot(p[0] - eye, normal));
    let farthest = sqrt(max(dot(p[0] - eye, p[0] - eye), max(dot(p[1] - eye, p[1] - eye), dot(p[2] - eye, p[2] - eye))));
    let may_fold = !(height > fold_bound * farthest * length(normal));
    if !may_fold && !boundary {
        return;
    }
    for (var i = 0u; i < 3u; i++) {
        let n = neighbour(t, i);
        let a = p[i];
        let b = p[(i + 1u) % 3u];
        var outline = n == BACKGROUND_ID;
        if !outline && may_fold && t < n {
            // Shared edges are drawn by the lower id only.
            let w = corners(n);
            let d = (position(w.x) + position(w.y) + position(w.z)) / 3.0;
            outline = is_silhouette(a, b, p[(i + 2u) % 3u], d, eye);
        }
        if outline {
            draw_outline(t, n, a, b);
        }
    }
}

// Narrows [range.x, range.y] to the parameters s where f0 + s (f1 - f0) >= 0.
fn keep_positive(range: vec2<f32>, f0: f32, f1: f32) -> vec2<f32> {
    var r = range;
    if f0 < 0.0 && f1 < 0.0 {
        return vec2<f32>(1.0, 0.0);
    }
    if f0 < 0.0 {
        r.x = max(r.x, f0 / (f0 - f1));
    } else if f1 < 0.0 {
        r.y = min(r.y, f0 / (f0 - f1));
    }
    return r;
}

// Narrows [range.x, range.y] to the parameters u where lo <= p0 + u d <= hi.
fn keep_between(range: vec2<f32>, p0: f32, d: f32, lo: f32, hi: f32) -> vec2<f32> {
    if d == 0.0 {
        return select(vec2<f32>(1.0, 0.0), range, p0 >= lo && p0 <= hi);
    }
    let u0 = (lo - p0) / d;
    let u1 = (hi - p0) / d;
    return vec2<f32>(max(range.x, min(u0, u1)), min(range.y, max(u0, u1)));
}

// Where a clip-space point lands: pixel coordinates, and 1/w, which is affine along a screen
// segment.
struct Projected {
    xy: vec2<f32>,
    inv_w: f32,
}

fn project(c: vec4<f32>) -> Projected {
    let inv_w = 1.0 / c.w;
    let ndc = c.xy * inv_w;
    return Projected(vec2<f32>(0.5 * (ndc.x + 1.0), 0.5 * (1.0 - ndc.y)) * frame.size, inv_w);
}

// Visibility samples per pixel of edge length; each change between two is then bisected.
const RUN_SAMPLES_PER_PX: f32 = 4.0;
const RUN_BISECTIONS: u32 = 12u;
// An edge is drawn in pieces of at most this many pixels, each with up to MAX_RUNS visible
// runs (more is beyond any real mesh at this scale; the last run then absorbs the rest).
const PIECE_PX: f32 = 16.0;
const MAX_RUNS: u32 = 8u;

// The screen segment of an outline edge, clipped to the view and the image.
struct Segment {
    start: vec2<f32>,
    along: vec2<f32>,
    // 1/w at both ends; affine along the segment.
    inv_w: vec2<f32>,
    t: u32,
    n: u32,
}

fn seg_point(s: Segment, k: f32) -> vec2<f32> {
    return s.start + k * s.along;
}

fn seg_w(s: Segment, k: f32) -> f32 {
    return 1.0 / mix(s.inv_w.x, s.inv_w.y, k);
}

fn seg_visible(s: Segment, k: f32) -> bool {
    return visible_at(seg_point(s, k), seg_w(s, k), s.t, s.n);
}

// Writes edge a -> b (of triangle t, with neighbour n) into every pixel within reach of its
// visible part.
fn draw_outline(t: u32, n: u32, a: vec3<f32>, b: vec3<f32>) {
    let ca = frame.view_proj * vec4<f32>(a, 1.0);
    let cb = frame.view_proj * vec4<f32>(b, 1.0);
    let ra = dot(frame.depth_row, vec4<f32>(a, 1.0));
    let rb = dot(frame.depth_row, vec4<f32>(b, 1.0));
    // In front of the near plane (clip z >= 0) and not beyond the far one (reverse-Z >= 0).
    var s = keep_positive(vec2<f32>(0.0, 1.0), ca.z, cb.z);
    s = keep_positive(s, ra, rb);
    if !(s.x <= s.y) {
        return;
    }
    let p0 = project(mix(ca, cb, s.x));
    let p1 = project(mix(ca, cb, s.y));
    // Inside the image.
    let d = p1.xy - p0.xy;
    var u = keep_between(vec2<f32>(0.0, 1.0), p0.xy.x, d.x, 0.0, frame.size.x);
    u = keep_between(u, p0.xy.y, d.y, 0.0, frame.size.y);
    if !(u.x <= u.y) {
        return;
    }
    var seg: Segment;
    seg.start = p0.xy + u.x * d;
    seg.along = (u.y - u.x) * d;
    seg.inv_w = vec2<f32>(mix(p0.inv_w, p1.inv_w, u.x), mix(p0.inv_w, p1.inv_w, u.y));
    seg.t = t;
    seg.n = n;
    let length_px = length(seg.along);
    let pieces = max(u32(ceil(length_px / PIECE_PX)), 1u);
    for (var piece = 0u; piece < pieces; piece++) {
        draw_piece(seg, f32(piece) / f32(pieces), f32(piece + 1u) / f32(pieces), length_px);
    }
}

// Finds the visible runs of the segment between parameters k0 and k1, then writes the
// distance to the nearest of them into every pixel within reach.
fn draw_piece(seg: Segment, k0: f32, k1: f32, length_px: f32) {
    var runs: array<vec2<f32>, MAX_RUNS>;
    var count = 0u;
    let steps = max(u32(ceil(length_px * (k1 - k0) * RUN_SAMPLES_PER_PX)), 1u);
    var last_k = k0;
    var last_visible = seg_visible(seg, k0);
    var start = k0;
    for (var j = 1u; j <= steps; j++) {
        let k = mix(k0, k1, f32(j) / f32(steps));
        let now = seg_visible(seg, k);
        if now != last_visible {
            var lo = last_k;
            var hi = k;
            for (var i = 0u; i < RUN_BISECTIONS; i++) {
                let mid = 0.5 * (lo + hi);
                if seg_visible(seg, mid) == last_visible {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            if now {
                start = hi;
            } else if count < MAX_RUNS {
                runs[count] = vec2<f32>(start, lo);
                count++;
            } else {
                runs[MAX_RUNS - 1u].y = lo;
            }
        }
        last_k = k;
        last_visible = now;
    }
    if last_visible {
        if count < MAX_RUNS {
            runs[count] = vec2<f32>(start, k1);
            count++;
        } else {
            runs[MAX_RUNS - 1u].y = k1;
        }
    }
    if count == 0u {
        return;
    }

    let reach = line_reach(frame.line_width);
    let q0 = seg_point(seg, k0);
    let q1 = seg_point(seg, k1);
    let span = q1 - q0;
    let len2 = dot(seg.along, seg.along);
    // Walk the pixels along the piece's major axis; across it, the band within reach of the
    // line is at most reach × √2 wide on either side (slope <= 1), plus a pixel for rounding.
    let major = select(1u, 0u, abs(span.x) >= abs(span.y));
    let minor = 1u - major;
    let last = vec2<i32>(frame.size) - 1;
    let band = reach * 1.4142135 + 1.0;
    let first_m = max(i32(floor(min(q0[major], q1[major]) - reach)), 0);
    let last_m = min(i32(ceil(max(q0[major], q1[major]) + reach)), last[major]);
    for (var m = first_m; m <= last_m; m++) {
        var f = 0.0;
        if span[major] != 0.0 {
            f = clamp((f32(m) + 0.5 - q0[major]) / span[major], 0.0, 1.0);
        }
        let across = q0[minor] + f * span[minor];
        let first_o = max(i32(floor(across - band)), 0);
        let last_o = min(i32(ceil(across + band)), last[minor]);
        for (var o = first_o; o <= last_o; o++) {
            var xy = vec2<i32>(m, o);
            if major == 1u {
                xy = vec2<i32>(o, m);
            }
            let pixel = vec2<f32>(xy) + 0.5;
            // Nearest point of the nearest visible run.
            var k = 0.0;
            if len2 > 0.0 {
                k = dot(pixel - seg.start, seg.along) / len2;
            }
            var best = NO_EDGE;
            var best_k = 0.0;
            for (var r = 0u; r < count; r++) {
                let kr = clamp(k, runs[r].x, runs[r].y);
                let dr = distance(pixel, seg_point(seg, kr));
                if dr < best {
                    best = dr;
                    best_k = kr;
                }
            }
            if !(best < reach) {
                continue;
            }
            let fade = depth_fade(seg_w(seg, best_k), frame.fade);
            let index = u32(xy.y) * u32(frame.size.x) + u32(xy.x);
            atomicMax(&outline_acc[index], pack_outline(best, fade));
        }
    }
}

// True unless a triangle other than t and n covers the screen point x nearer than view depth
// w. The candidates are the triangles the rasterizer gave the four pixel centres around x,
// and those a walk across edges from them reaches when they do not cover x themselves (x may
// lie in a small triangle that owns none of those centres).
fn visible_at(x: vec2<f32>, w: f32, t: u32, n: u32) -> bool {
    let base = vec2<i32>(floor(x - 0.5));
    let last = vec2<i32>(frame.size) - 1;
    for (var k = 0; k < 4; k++) {
        let q = clamp(base + vec2<i32>(k & 1, k >> 1u), vec2<i32>(0), last);
        let id = textureLoad(ids, vec2<u32>(q), 0).x;
        if id == BACKGROUND_ID || id == t || id == n {
            continue;
        }
        var s = sample(id, x);
        if !s.covers {
            s = walk(s, x);
        }
        if s.covers && s.id != t && s.id != n && s.w < w * (1.0 - HIDDEN_MARGIN) {
            return false;
        }
    }
    return true;
}
