// Definitions every wirepass shader shares. Each has a Rust twin of the same name
// (src/edge_math.rs, src/style.rs); tests keep the two equal.

struct Frame {
    // Mesh-local (rebased) position -> clip space.
    view_proj: mat4x4<f32>,
    // Reverse-Z depth row (clip w row minus clip z row): dot(depth_row, p) / w is 1 at the
    // near plane and 0 at the far plane, computed without cancellation for precision.
    depth_row: vec4<f32>,
    // Eye in mesh-local coordinates (xyz).
    eye: vec4<f32>,
    // Unit direction towards the key light, world axes (xyz).
    light_dir: vec4<f32>,
    // Linear RGBA colours.
    wire_color: vec4<f32>,
    fill_color: vec4<f32>,
    background: vec4<f32>,
    // Image size in pixels.
    size: vec2<f32>,
    // Line width in pixels.
    line_width: f32,
    // Share of ambient light in the shading, 0..1.
    ambient: f32,
    // Depth fade (start, end) in view depth; (0, 0) for none. See `depth_fade`.
    fade: vec2<f32>,
    // Triangles in the first binding of the per-triangle buffers (indices, neighbours), which
    // meshes past max_storage_buffer_binding_size split over two (src/gpu/mesh.rs).
    index_split: u32,
    // 1: draw outlines at full width (outline.wgsl); 0: every edge inside its own triangles.
    silhouettes: u32,
    // Triangles in the mesh.
    triangles: u32,
}

// Distance returned for an edge that is not drawn or not visible.
const NO_EDGE: f32 = 3.0e38;

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
// `mask` bit i enables edge i. A clip z below 0 lies behind the near plane (depth 0..1).
fn edge_eval(c0: vec4<f32>, c1: vec4<f32>, c2: vec4<f32>, mask: u32, pixel: vec2<f32>, size: vec2<f32>) -> EdgeEval {
    let p0 = pixel_relative(c0, pixel, size);
    let p1 = pixel_relative(c1, pixel, size);
    let p2 = pixel_relative(c2, pixel, size);
    // Screen lines through each edge; l.z is the line evaluated at the pixel centre.
    let l0 = cross(p0, p1);
    let l1 = cross(p1, p2);
    let l2 = cross(p2, p0);
    var out: EdgeEval;
    out.distance = edge_distances(l0, l1, l2, vec3<f32>(c0.z, c1.z, c2.z), mask);
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

// Distances to the three edge lines of `edge_eval`, applying the mask and the near-plane rule
// (`clip_z` holds the corners' clip z; below 0 is behind the near plane).
fn edge_distances(l0: vec3<f32>, l1: vec3<f32>, l2: vec3<f32>, clip_z: vec3<f32>, mask: u32) -> vec3<f32> {
    let raw = vec3<f32>(line_distance(l0, true), line_distance(l1, true), line_distance(l2, true));
    return drawn_distances(raw, clip_z, mask);
}

// `raw` (the distances to all three edge lines) with NO_EDGE for edges that are masked out
// or have both ends behind the near plane.
fn drawn_distances(raw: vec3<f32>, clip_z: vec3<f32>, mask: u32) -> vec3<f32> {
    let behind = clip_z < vec3<f32>(0.0);
    let masked = (vec3<u32>(mask) & vec3<u32>(1u, 2u, 4u)) == vec3<u32>(0u);
    let hidden = behind & behind.yzx;
    return select(raw, vec3<f32>(NO_EDGE), masked | hidden);
}

fn line_distance(l: vec3<f32>, drawn: bool) -> f32 {
    let len = length(l.xy);
    if !drawn || !(len > 0.0) {
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

// A line's strength at view depth `w`: 1 up to fade.x, falling linearly to 0 at fade.y;
// 1 everywhere when fade.y <= fade.x (no fade).
fn depth_fade(w: f32, fade: vec2<f32>) -> f32 {
    if !(fade.y > fade.x) {
        return 1.0;
    }
    return clamp((fade.y - w) / (fade.y - fade.x), 0.0, 1.0);
}

// True when the edge a -> b, shared by a triangle with third corner c and a neighbour with a
// point d off the edge, is a silhouette seen from `eye`: both triangles lie on the same side
// of the plane through the eye and the edge, so on screen they fold onto one side of it and
// the other side shows something else. Independent of winding. Each side is the triple
// product of (a - eye) with a triangle's own edge vectors, which stay small and exact for a
// far eye. An edge-on triangle (side 0) counts as folded.
fn is_silhouette(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, d: vec3<f32>, eye: vec3<f32>) -> bool {
    let to_edge = a - eye;
    let side_c = dot(to_edge, cross(b - a, c - a));
    let side_d = dot(to_edge, cross(b - a, d - a));
    return !(side_c * side_d < 0.0);
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

// Twin of clusters::may_fold: false when, seen from `eye`, no triangle of the cluster can have
// an outline edge: every direction from the eye into the sphere (within β of its centre's)
// makes an angle with every normal (within the spread of the axis) that stays off 90°.
fn cluster_may_fold(c: Cluster, eye: vec3<f32>) -> bool {
    let d = c.center - eye;
    let distance = length(d);
    if !(distance > c.radius) {
        return true;
    }
    let beta = asin(c.radius / distance);
    let gamma = atan2(length(cross(d, c.axis)), dot(d, c.axis));
    let reach = beta + c.spread;
    let quarter = 1.5707963;
    return !(gamma + reach < quarter || gamma - reach > quarter);
}

// Diffuse key light plus ambient; the normal is turned towards the viewer so back faces
// seen through open meshes are lit like front faces.
fn shade(base: vec3<f32>, normal: vec3<f32>, to_eye: vec3<f32>, light_dir: vec3<f32>, ambient: f32) -> vec3<f32> {
    var n = normal;
    if dot(n, to_eye) < 0.0 {
        n = -n;
    }
    let diffuse = max(dot(n, light_dir), 0.0);
    return base * (ambient + (1.0 - ambient) * diffuse);
}

// The shaded colour of the surface point `world` of a triangle: the interpolated normal,
// falling back to the face normal where it vanishes, then to the view direction. Every method
// shades through this; the ground truth (src/raycast.rs) follows the same steps in f64.
fn surface_color(f: Frame, world: vec3<f32>, normal: vec3<f32>, face_normal: vec3<f32>) -> vec3<f32> {
    let to_eye = f.eye.xyz - world;
    var n = normal;
    if !(dot(n, n) > 1e-12) {
        n = face_normal;
    }
    if !(dot(n, n) > 0.0) {
        n = to_eye;
    }
    return shade(f.fill_color.rgb, normalize(n), to_eye, f.light_dir.xyz, f.ambient);
}

fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    return select(1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * x, x <= vec3<f32>(0.0031308));
}

// Clip position for rasterising with reverse-Z depth (1 at near, 0 at far), whose precision
// is nearly uniform in distance; x, y and w are those of `view_proj`.
fn reverse_z(view_proj: mat4x4<f32>, depth_row: vec4<f32>, p: vec3<f32>) -> vec4<f32> {
    let h = vec4<f32>(p, 1.0);
    let c = view_proj * h;
    return vec4<f32>(c.x, c.y, dot(depth_row, h), c.w);
}
