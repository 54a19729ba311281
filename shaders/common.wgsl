// Definitions every wirepass shader shares. Each function has a Rust twin of the same name
// (src/edge_math.rs, src/style.rs, src/gpu/mesh_store.rs); tests keep the two equal.
//
// No `if` or loop condition in these shaders depends on uniform values alone (a frame
// setting, the record of a frame's one instance): lavapipe (Mesa 22) then specialises the
// pipeline for those values again at every dispatch, which costs milliseconds for a large
// shader even when the dispatch has no work. Such choices are `select`s, or `#if` flags
// (src/gpu/shaders.rs).

// Per frame (src/gpu/frame.rs, FrameUniforms).
struct Frame {
    // Size of the full image the projection maps onto, in pixels: the edge math's screen.
    image_size: vec2<f32>,
    // Full-image pixel coordinates of the targets' pixel (0, 0).
    target_origin: vec2<f32>,
    // Size of the id and depth targets, in pixels.
    target_size: vec2<f32>,
    // Where the output starts in the targets, and its size (pixels).
    output_offset: vec2<f32>,
    output_size: vec2<f32>,
    // Depth fade (start, end) in view depth; (0, 0) for none. See `depth_fade`.
    fade: vec2<f32>,
    // The visibility raster's clip transform onto the targets: x' = x * crop.x + w * crop.z,
    // y' = y * crop.y + w * crop.w.
    crop: vec4<f32>,
    // Unit direction towards the key light, world axes (xyz).
    light_dir: vec4<f32>,
    // Linear RGBA colours.
    fill_color: vec4<f32>,
    background: vec4<f32>,
    // Share of ambient light in the shading, 0..1.
    ambient: f32,
    // Instances in the frame.
    instances: u32,
    // First element of the second binding of the vertex and per-triangle buffers, for a
    // store split over two bindings (src/gpu/mesh_store.rs); the capacity otherwise.
    vertex_split: u32,
    triangle_split: u32,
    // Clusters of all instances together: the trace cull's range.
    clusters: u32,
    // Host depth: 1 when the id target was seeded from the host's depth.
    host_depth: u32,
    // Room of the trace pass's overflow list (`overflow_list` in trace.wgsl).
    overflow_room: u32,
    // Opacity of the shaded surface over the background (`see_through`).
    fill_opacity: f32,
    // Hidden lines (HIDDEN): linear RGBA colour of every instance's (without COLORS, they
    // share one).
    hidden_color: vec4<f32>,
    // Chains of drawn edges (PATTERNS, `chain_phases`): words of the phase tables in the
    // trace buffer, chains over all instances, entries of `chain_work`.
    chain_work: vec4<u32>,
    // Linear RGBA of back faces seen through a section's cut (`sections_on` 1), and the
    // section planes as coefficients of clip-space points (`section_sides`; unused: 0).
    section_color: vec4<f32>,
    sections: array<vec4<f32>, MAX_SECTIONS>,
    sections_on: u32,
    // The cut lines' width in pixels and linear RGBA colour.
    section_width: f32,
    // The frame's intersection segments (`intersections` in trace.wgsl), and their lines'
    // width and colour.
    intersections: u32,
    intersection_width: f32,
    section_line_color: vec4<f32>,
    intersection_line_color: vec4<f32>,
    // The clip-space w of every point of the near plane (`View::near_plane_w`), 0 where the
    // projection gives them none.
    near_w: f32,
}

// Per instance (src/gpu/frame.rs, InstanceRecord). "Local" coordinates are the mesh
// store's: each mesh rebased to its centre and scaled to about ±1.
struct Instance {
    // Local position -> clip rows x, y, near, w: row 2 is >= 0 exactly in front of the near
    // plane, whatever the view's depth convention.
    clip: mat4x4<f32>,
    // Reverse depth row: dot(depth_row, p) / w is 1 at the near plane and 0 at the far one.
    depth_row: vec4<f32>,
    // The eye in homogeneous local coordinates: (eye, 1), or (towards the viewer, 0) for an
    // orthographic view.
    eye: vec4<f32>,
    // View depth (distance in front of the eye along the view axis) of a local point.
    fade_row: vec4<f32>,
    // Rows of the local -> world normal matrix, each with a number of the hidden-line
    // pattern (INSTANCE_HIDDEN): its width, dash and period (0 for solid, `dash_nearest`) in
    // pixels.
    normal_x: vec3<f32>,
    hidden_width: f32,
    normal_y: vec3<f32>,
    hidden_dash: f32,
    normal_z: vec3<f32>,
    hidden_period: f32,
    wire_color: vec4<f32>,
    // Linear RGBA of the shaded surface.
    fill_color: vec4<f32>,
    line_width: f32,
    // INSTANCE_EDGES, INSTANCE_OUTLINES.
    flags: u32,
    vertex_base: u32,
    triangle_base: u32,
    triangles: u32,
    cluster_base: u32,
    // The first of this instance's clusters among all instances' (the trace cull's index).
    cluster_first: u32,
    // This record's place in the instance buffer.
    index: u32,
    // The outline's and the hidden lines' linear RGBA as f16 (`unpack_color`); the outline's
    // width in pixels.
    outline_color: vec2<u32>,
    hidden_color: vec2<u32>,
    outline_width: f32,
    // Its phase table (`chain_phases`): word offset among the frame's phase tables, and
    // log2 of its slots.
    phase_table: u32,
    table_log2: u32,
    _pad: u32,
    // The visible lines' patterns, (dash, period) in pixels, period 0 for solid
    // (`dash_nearest`): the drawn edges', the outline's.
    edge_pattern: vec2<f32>,
    outline_pattern: vec2<f32>,
    // With INSTANCE_CROSSED, the image pixels (min x, min y, max x, max y) round the
    // crossings, where its lines are drawn the crossing way (`near_crossing`).
    cross_box: vec4<f32>,
}

// Whether image point x lies in the box `b` (min x, min y, max x, max y).
fn in_box(b: vec4<f32>, x: vec2<f32>) -> bool {
    return all(x >= b.xy) && all(x <= b.zw);
}

// A colour packed as two pairs of f16 (src/gpu/frame.rs, pack_color).
fn unpack_color(c: vec2<u32>) -> vec4<f32> {
    return vec4<f32>(unpack2x16float(c.x), unpack2x16float(c.y));
}

// Instance ids of the id target, BACKGROUND_ID (background) and HOST_ID (host geometry in
// front), are written before this file from `gpu::BACKGROUND_ID` and `gpu::HOST_ID`.

// How host depth maps to the pass's reverse depth (src/gpu/host_depth.rs, HostParams).
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

// Host geometry hides a point only when it is nearer by more than this margin (in reverse
// depth, for a host depth of reverse value `r` and format step `quantum`), so a host that
// draws the wireframed meshes itself too does not hide their lines with its own copy of
// them: two format steps (the host stores its depth rounded) and the f32 rounding of two
// transforms (src/edge_math.rs).
fn host_margin(r: f32, quantum: f32) -> f32 {
    return 1.0e-5 * r + 2.0 * quantum + 1.0e-6;
}

// Twin of `host_slope` in src/edge_math.rs: how much the host's reverse depth `h` changes per
// pixel, from its values at the left, right, upper and lower neighbours (negative where the
// host has no geometry there): per axis the smaller change to a neighbour with geometry (the
// surface's own slope, not the jump at its edge), summed over both axes.
fn host_slope(h: f32, left: f32, right: f32, up: f32, down: f32) -> f32 {
    return host_axis_slope(h, left, right) + host_axis_slope(h, up, down);
}

fn host_axis_slope(h: f32, a: f32, b: f32) -> f32 {
    var m = 3.0e38;
    if a >= 0.0 {
        m = abs(h - a);
    }
    if b >= 0.0 {
        m = min(m, abs(b - h));
    }
    return select(0.0, m, m < 3.0e38);
}

// Twin of `host_hides` in src/edge_math.rs: whether the host's surface at a pixel (reverse
// depth `host`, changing by `slope` per pixel) hides a line point of reverse depth `point`
// that lies `distance` pixels from the pixel's centre. The host must be nearer by twice its
// own depth change over that distance and one pixel more: a point on or in front of the
// host's surface where it lies (an outline where an object meets the ground) is never
// hidden by the host's depth sampled a pixel or two away.
fn host_hides(host: f32, point: f32, distance: f32, slope: f32) -> bool {
    return host - point > 2.0 * (distance + 1.0) * slope;
}

// Homogeneous pixel coordinates of a clip-space vertex, relative to the pixel centre `pixel`:
// ((x + w)/2 * W - px * w, (w - y)/2 * H - py * w, w). Working relative to the pixel keeps the
// cross products below small where they matter, and nothing divides by w.
fn pixel_relative(clip: vec4<f32>, pixel: vec2<f32>, size: vec2<f32>) -> vec3<f32> {
    let half = 0.5 * size;
    return vec3<f32>(
        clip.x * half.x + clip.w * (half.x - pixel.x),
        clip.w * (half.y - pixel.y) - clip.y * half.y,
        clip.w,
    );
}

struct EdgeEval {
    // Distance in pixels from the pixel centre to the screen line of edge i (corner i -> i+1),
    // NO_EDGE where the edge is masked out, entirely behind the near plane, or degenerate.
    distance: vec3<f32>,
    // Perspective-correct barycentrics of the pixel centre (sum to 1).
    bary: vec3<f32>,
}

// Edge distances and barycentrics of the pixel centre for a triangle given in clip space.
// `mask` bit i enables edge i. A clip z (the near row) below 0 lies behind the near plane.
fn edge_eval(c0: vec4<f32>, c1: vec4<f32>, c2: vec4<f32>, mask: u32, pixel: vec2<f32>, size: vec2<f32>) -> EdgeEval {
    let p0 = pixel_relative(c0, pixel, size);
    let p1 = pixel_relative(c1, pixel, size);
    let p2 = pixel_relative(c2, pixel, size);
    // Screen lines through each edge; l.z is the line evaluated at the pixel centre.
    let l0 = cross(p0, p1);
    let l1 = cross(p1, p2);
    let l2 = cross(p2, p0);
    var out: EdgeEval;
    let raw = vec3<f32>(line_distance(l0), line_distance(l1), line_distance(l2));
    out.distance = drawn_distances(raw, vec3<f32>(c0.z, c1.z, c2.z), mask);
    // Corner i's weight is the line of the opposite edge evaluated at the pixel.
    let e = vec3<f32>(l1.z, l2.z, l0.z);
    let sum = e.x + e.y + e.z;
    if sum != 0.0 {
        out.bary = e / sum;
    } else {
        out.bary = vec3<f32>(1.0 / 3.0);
    }
    return out;
}

// `raw` (the distances to all three edge lines) with NO_EDGE for edges that are masked out
// or have both ends behind the near plane (`near` holds the corners' near rows).
fn drawn_distances(raw: vec3<f32>, near: vec3<f32>, mask: u32) -> vec3<f32> {
    let behind = near < vec3<f32>(0.0);
    let masked = (vec3<u32>(mask) & vec3<u32>(1u, 2u, 4u)) == vec3<u32>(0u);
    let hidden = behind & behind.yzx;
    return select(raw, vec3<f32>(NO_EDGE), masked | hidden);
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

// Twin of edge_math::segment_distance: pixels from `pixel` to the screen segment between the
// clip-space points ca and cb, cut to its part in front of the near plane (NO_EDGE when none
// is). Where the nearest point of a drawn edge need not lie between its ends (across
// undrawn edges), the edge's line passes closer than the edge.
fn segment_distance(ca: vec4<f32>, cb: vec4<f32>, pixel: vec2<f32>, size: vec2<f32>) -> f32 {
    let s = keep_positive(vec2<f32>(0.0, 1.0), ca.z, cb.z);
    if !(s.x <= s.y) {
        return NO_EDGE;
    }
    let pa = pixel_relative(mix(ca, cb, s.x), pixel, size);
    let pb = pixel_relative(mix(ca, cb, s.y), pixel, size);
    return screen_segment_distance(pa.xy / pa.z, pb.xy / pb.z);
}

// The length of the shortest vector from the origin to the screen segment a -> b (a and b
// in pixels from the pixel centre); NO_EDGE where that is not a number.
fn screen_segment_distance(a: vec2<f32>, b: vec2<f32>) -> f32 {
    let ab = b - a;
    let len2 = dot(ab, ab);
    var k = 0.0;
    if len2 > 0.0 {
        k = clamp(-dot(a, ab) / len2, 0.0, 1.0);
    }
    let d = length(a + k * ab);
    return select(NO_EDGE, d, d == d);
}

// Distance from the origin (the pixel centre) to the screen line l, NO_EDGE when l is no line.
fn line_distance(l: vec3<f32>) -> f32 {
    let len = length(l.xy);
    if !(len > 0.0) {
        return NO_EDGE;
    }
    return abs(l.z) / len;
}

// The line profile: intensity of a line of `width` pixels at distance `d` from its centre.
// A core of width - 2 px at full intensity, then a Gaussian falloff exp2(-2 t^2) over
// the next 2 px (NVIDIA "Solid Wireframe"); lines under 2 px keep the falloff and fade
// in proportion to their width instead of thinning to nothing.
fn line_intensity(d: f32, width: f32) -> f32 {
    let t = max(d - max(0.5 * width - 1.0, 0.0), 0.0);
    if !(t < 2.0) {
        return 0.0;
    }
    return min(0.5 * width, 1.0) * exp2(-2.0 * t * t);
}

// How far from its centre a line of `width` pixels colours pixels.
fn line_reach(width: f32) -> f32 {
    return max(0.5 * width - 1.0, 0.0) + 2.0;
}

// A line's strength at view depth `depth`: 1 up to fade.x, falling linearly to 0 at fade.y;
// 1 everywhere when fade.y <= fade.x (no fade).
fn depth_fade(depth: f32, fade: vec2<f32>) -> f32 {
    return select(1.0, clamp((fade.y - depth) / (fade.y - fade.x), 0.0, 1.0), fade.y > fade.x);
}

// The shaded surface `surface` over `under` (premultiplied, linear) at opacity k (the
// frame's fill opacity): `surface` itself, bit for bit, where the surface is opaque.
fn see_through(surface: vec3<f32>, under: vec4<f32>, k: f32) -> vec4<f32> {
    if k < 1.0 {
        return vec4<f32>(surface * k + under.rgb * (1.0 - k), k + under.a * (1.0 - k));
    }
    return vec4<f32>(surface, 1.0);
}

// Twin of `style::dash_nearest`: of the points of the dashes [j period, j period + dash]
// (every integer j; period 0 for a solid line) that lie in [lo, hi], the one nearest s
// (positions along a line, pixels); NO_EDGE where the interval holds none.
fn dash_nearest(s: f32, lo: f32, hi: f32, dash: f32, period: f32) -> f32 {
    if !(lo <= hi) {
        return NO_EDGE;
    }
    let c = clamp(s, lo, hi);
    if !(period > 0.0) {
        return c;
    }
    let start = floor(c / period) * period;
    if c - start <= dash {
        return c;
    }
    // c lies in the gap between a dash's end and the next one's start.
    let end = start + dash;
    let next = start + period;
    let has_end = end >= lo;
    let has_next = next <= hi;
    if has_end && (!has_next || s - end <= next - s) {
        return end;
    }
    return select(NO_EDGE, next, has_next);
}

// Which line colours a pixel most: lines are ranked by their intensity in 1/4095 steps, and
// equal ones by nearness (src/style.rs, line_key, is the twin). The trace pass keeps the
// greatest key per pixel with an atomic max; the distance is kept in KEY_DISTANCE_STEPS a
// pixel.
fn line_key(intensity: f32, d: f32) -> u32 {
    let level = u32(round(clamp(intensity, 0.0, 1.0) * 4095.0));
    let q = u32(clamp(d * KEY_DISTANCE_STEPS, 0.0, f32(KEY_DISTANCE_MAX)));
    return (level << 20u) | (KEY_DISTANCE_MAX - q);
}

// The intensity a key was ranked with.
fn key_intensity(key: u32) -> f32 {
    return f32(key >> 20u) / 4095.0;
}

// The distance a key holds (NO_EDGE for the empty key 0).
fn key_distance(key: u32) -> f32 {
    if key == 0u {
        return NO_EDGE;
    }
    return (f32(KEY_DISTANCE_MAX - (key & KEY_DISTANCE_MAX)) + 0.5) / KEY_DISTANCE_STEPS;
}

// The point of view `eye` (homogeneous: a point with w = 1, a direction towards the viewer
// with w = 0) as seen from `a`: the direction from `a` towards it, up to a positive factor.
fn towards_eye(a: vec3<f32>, eye: vec4<f32>) -> vec3<f32> {
    return eye.xyz - a * eye.w;
}

// True when the edge a -> b, shared by a triangle with third corner c and a neighbour with a
// point d off the edge, is a silhouette seen from `eye`: both triangles lie on the same side
// of the plane through the eye and the edge, so on screen they fold onto one side of it and
// the other side shows something else. Independent of winding, so mirrored instances get
// the same silhouettes. Each side is the triple product of the direction to the eye with a
// triangle's own edge vectors, which stay small and exact for a far eye. An edge-on
// triangle counts as folded: one within EDGE_ON of it, since the eye in a face's plane (a
// box seen along a face, an axis-aligned orthographic view) puts it at 0 only to rounding,
// which f32 and the ground truth's f64 round differently.
fn is_silhouette(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, d: vec3<f32>, eye: vec4<f32>) -> bool {
    let to_eye = towards_eye(a, eye);
    let normal_c = cross(b - a, c - a);
    let normal_d = cross(b - a, d - a);
    let side_c = dot(to_eye, normal_c);
    let side_d = dot(to_eye, normal_d);
    let scale = EDGE_ON * length(to_eye);
    let edge_on = abs(side_c) <= scale * length(normal_c) || abs(side_d) <= scale * length(normal_d);
    return edge_on || !(side_c * side_d < 0.0);
}

// Whether an outline edge a -> b (of a triangle with third corner c; with `across`, across
// an edge to a neighbour with a point d off the edge) runs with the side that faces `eye` on
// its left: the way its outline chain runs (`outline_chain_ends` in trace.wgsl). Told by the
// triangle further from edge-on, as the two sides of a silhouette tell the same but an
// edge-on one rounds either way (twin of `edge_math::outline_forward`).
fn outline_forward(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, d: vec3<f32>, across: bool, eye: vec4<f32>) -> bool {
    let to_eye = towards_eye(a, eye);
    let normal_c = cross(b - a, c - a);
    let normal_d = cross(b - a, d - a);
    let side_c = dot(to_eye, normal_c);
    let side_d = dot(to_eye, normal_d);
    let by_c = !across || abs(side_c) * length(normal_d) >= abs(side_d) * length(normal_c);
    return select(side_d > 0.0, side_c > 0.0, by_c);
}

// Bounds on a cluster of nearby triangles (src/mesh/clusters.rs): a sphere holding their
// corners, and the axis and spread (cone half-angle plus largest fold, radians; over π/2:
// never skipped) of their normals.
struct Cluster {
    center: vec3<f32>,
    radius: f32,
    axis: vec3<f32>,
    spread: f32,
}

// Whether the cluster holds drawn edges of a large patch, which the trace pass draws
// whatever the eye: mesh_store::cluster_records stores its spread as -1 - spread.
fn cluster_splats(c: Cluster) -> bool {
    return c.spread < 0.0;
}

// Whether the cluster holds a drawn edge: mesh_records::cluster_records stores the radius
// of one without as -1 - radius.
fn cluster_draws(c: Cluster) -> bool {
    return c.radius >= 0.0;
}

// The radius of the cluster's bounding sphere.
fn cluster_radius(c: Cluster) -> f32 {
    return select(c.radius, -1.0 - c.radius, c.radius < 0.0);
}

// Twin of clusters::may_fold: false when, seen from `eye`, no triangle of the cluster can have
// an outline edge: every direction from the eye into the sphere (within β of its centre's)
// makes an angle with every normal (within the spread of the axis) that stays off 90°. An
// orthographic eye sees along one direction (β = 0).
fn cluster_may_fold(c: Cluster, eye: vec4<f32>) -> bool {
    let spread = select(c.spread, -1.0 - c.spread, cluster_splats(c));
    let perspective = eye.w != 0.0;
    let d = select(-eye.xyz, c.center - eye.xyz / eye.w, perspective);
    let distance = length(d);
    let radius = cluster_radius(c);
    let inside = perspective && !(distance > radius);
    let beta = select(0.0, asin(radius / distance), perspective);
    let gamma = atan2(length(cross(d, c.axis)), dot(d, c.axis));
    let reach = beta + spread;
    let quarter = 1.5707963;
    return inside || !(gamma + reach < quarter || gamma - reach > quarter);
}

// Twin of mesh_store::unpack_normal: a unit normal packed octahedrally into two 16-bit
// snorms; 0x80008000 marks a vertex without one (zero).
fn unpack_normal(packed: u32) -> vec3<f32> {
    if packed == 0x80008000u {
        return vec3<f32>(0.0);
    }
    let f = unpack2x16snorm(packed);
    var n = vec3<f32>(f, 1.0 - abs(f.x) - abs(f.y));
    let t = max(-n.z, 0.0);
    n.x += select(t, -t, n.x >= 0.0);
    n.y += select(t, -t, n.y >= 0.0);
    return normalize(n);
}

// Diffuse key light plus ambient; `facing` (the local normal dotted with the direction to the
// eye) turns the normal towards the viewer, so back faces seen through open meshes are lit
// like front faces.
fn shade(base: vec3<f32>, normal: vec3<f32>, facing: f32, light_dir: vec3<f32>, ambient: f32) -> vec3<f32> {
    var n = normal;
    if facing < 0.0 {
        n = -n;
    }
    let diffuse = max(dot(n, light_dir), 0.0);
    return base * (ambient + (1.0 - ambient) * diffuse);
}

// The shaded colour of the local surface point `p` of an instance's triangle: the
// interpolated normal, falling back to the face normal where it vanishes, then to the view
// direction; normals are taken to world axes for the light. Every method shades through
// this; the ground truth (src/raycast.rs) follows the same steps in f64.
fn surface_color(f: Frame, inst: Instance, p: vec3<f32>, normal: vec3<f32>, face_normal: vec3<f32>) -> vec3<f32> {
    let to_eye = towards_eye(p, inst.eye);
    var n = normal;
    if !(dot(n, n) > 1e-12) {
        n = face_normal;
    }
    if !(dot(n, n) > 0.0) {
        // Seen edge-on or degenerate: light it as if it faced the viewer.
        return shade(inst.fill_color.rgb, normalize(f.light_dir.xyz), 1.0, f.light_dir.xyz, f.ambient);
    }
    let world = vec3<f32>(dot(inst.normal_x.xyz, n), dot(inst.normal_y.xyz, n), dot(inst.normal_z.xyz, n));
    return shade(inst.fill_color.rgb, normalize(world), dot(n, to_eye), f.light_dir.xyz, f.ambient);
}

fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    return select(1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * x, x <= vec3<f32>(0.0031308));
}

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    return select(pow((x + 0.055) / 1.055, vec3<f32>(2.4)), x / 12.92, x <= vec3<f32>(0.04045));
}

// Clip position for rasterising onto the targets with reverse depth (1 at near, 0 at far):
// x and y mapped by the frame's crop, depth from the instance's depth row.
// The sides of clip-space point c of the frame's section planes 0..3 and 4..5: negative
// where c is cut away (0 for unused planes). Affine in c, so interpolated over a triangle
// they are each pixel centre's own.
struct SectionSides {
    a: vec4<f32>,
    b: vec2<f32>,
}

fn section_sides(f: Frame, c: vec4<f32>) -> SectionSides {
    let s = f.sections;
    return SectionSides(vec4<f32>(dot(s[0], c), dot(s[1], c), dot(s[2], c), dot(s[3], c)), vec2<f32>(dot(s[4], c), dot(s[5], c)));
}

fn raster_position(f: Frame, clip: mat4x4<f32>, depth_row: vec4<f32>, p: vec3<f32>) -> vec4<f32> {
    let h = vec4<f32>(p, 1.0);
    let c = clip * h;
    return vec4<f32>(c.x * f.crop.x + c.w * f.crop.z, c.y * f.crop.y + c.w * f.crop.w, dot(depth_row, h), c.w);
}
