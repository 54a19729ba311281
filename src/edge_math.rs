//! The edge distance, defined once: the f64 twin of `edge_eval` in `shaders/common.wgsl`.
//!
//! A clip-space vertex `(x, y, z, w)` maps to homogeneous pixel coordinates
//! `P = ((x + w)/2 · W, (w − y)/2 · H, w)`. The screen line through an edge is `L = Pa × Pb`
//! and the distance of pixel centre `p = (px, py, 1)` to it is `|L · p| / ‖L.xy‖` pixels.
//! Nothing divides by `w`, so the result stays exact when a vertex is at or behind the eye
//! (Olano & Greer 1997). Coordinates are taken relative to the pixel centre, which keeps the
//! cross products small. An edge with both ends behind the near plane (clip `z < 0`) is not
//! visible; the three `L · p`, normalised to sum to 1, are the perspective-correct
//! barycentrics.

use glam::{DVec2, DVec3, DVec4};

/// Distance reported for an edge that is masked out, not visible, or degenerate.
pub const NO_EDGE: f64 = f64::INFINITY;

/// Result of [`edge_eval`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeEval {
    /// Pixels from the pixel centre to the screen line of edge `i` (corner `i` → `i + 1`).
    pub distance: [f64; 3],
    /// Perspective-correct barycentrics of the pixel centre.
    pub bary: [f64; 3],
}

impl EdgeEval {
    /// Distance to the nearest drawn edge.
    pub fn min_distance(&self) -> f64 {
        self.distance[0].min(self.distance[1]).min(self.distance[2])
    }
}

/// Homogeneous pixel coordinates of a clip-space vertex, relative to the pixel centre.
pub fn pixel_relative(clip: DVec4, pixel: DVec2, size: DVec2) -> DVec3 {
    let half = 0.5 * size;
    DVec3::new(
        clip.x * half.x + clip.w * (half.x - pixel.x),
        clip.w * (half.y - pixel.y) - clip.y * half.y,
        clip.w,
    )
}

/// Edge distances and barycentrics of `pixel` (a pixel centre, e.g. `(x + 0.5, y + 0.5)`) for
/// the triangle with clip-space corners `clip`; bit `i` of `mask` enables edge `i`.
pub fn edge_eval(clip: [DVec4; 3], mask: u8, pixel: DVec2, size: DVec2) -> EdgeEval {
    let p = clip.map(|c| pixel_relative(c, pixel, size));
    let l = [p[0].cross(p[1]), p[1].cross(p[2]), p[2].cross(p[0])];
    let behind = clip.map(|c| c.z < 0.0);
    let distance = std::array::from_fn(|i| {
        let drawn = mask & (1 << i) != 0 && !(behind[i] && behind[(i + 1) % 3]);
        line_distance(l[i], drawn)
    });
    let e = [l[1].z, l[2].z, l[0].z];
    let sum = e[0] + e[1] + e[2];
    let bary = if sum != 0.0 {
        e.map(|v| v / sum)
    } else {
        [1.0 / 3.0; 3]
    };
    EdgeEval { distance, bary }
}

/// Twin of `towards_eye` in common.wgsl: the direction from `a` towards the homogeneous eye
/// `eye` (a point with w = 1, or a direction towards the viewer with w = 0), up to a
/// positive factor.
pub fn towards_eye(a: DVec3, eye: DVec4) -> DVec3 {
    eye.truncate() - a * eye.w
}

/// The homogeneous eye `eye` (world) in the coordinates of a model placed by `model`: a
/// point with w = 1, or a unit direction towards the viewer with w = 0.
pub fn local_eye(model: glam::DMat4, eye: DVec4) -> DVec4 {
    let local = model.inverse() * eye;
    if local.w != 0.0 {
        local / local.w
    } else {
        local.truncate().normalize_or_zero().extend(0.0)
    }
}

/// Twin of `is_silhouette` in common.wgsl: the edge `a → b`, shared by a triangle with third
/// corner `c` and a neighbour with a point `d` off the edge, is a silhouette seen from `eye`
/// (homogeneous, as [`towards_eye`] takes it) when both triangles lie on the same side of the
/// plane through the eye and the edge (so on screen they fold onto one side of it).
/// Independent of winding, so mirrored instances have the same silhouettes; an edge-on
/// triangle counts as folded, and so does one within [`EDGE_ON`] of edge-on.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // as in WGSL: NaN sides count as folded
pub fn is_silhouette(a: DVec3, b: DVec3, c: DVec3, d: DVec3, eye: DVec4) -> bool {
    let to_eye = towards_eye(a, eye);
    let (normal_c, normal_d) = ((b - a).cross(c - a), (b - a).cross(d - a));
    let (side_c, side_d) = (to_eye.dot(normal_c), to_eye.dot(normal_d));
    let scale = EDGE_ON * to_eye.length();
    let edge_on =
        side_c.abs() <= scale * normal_c.length() || side_d.abs() <= scale * normal_d.length();
    edge_on || !(side_c * side_d < 0.0)
}

/// Whether an outline edge `a -> b` (of a triangle with third corner `c`; with `d`, across
/// an edge to a neighbour with a point `d` off the edge) runs with the side that faces `eye`
/// on its left: the direction of the outline chains along which a hidden-line pattern runs.
/// Told by the triangle further from edge-on: both sides of a silhouette tell the same, but
/// an edge-on one rounds either way in f32 and f64.
pub fn outline_forward(a: DVec3, b: DVec3, c: DVec3, d: Option<DVec3>, eye: DVec4) -> bool {
    let to_eye = towards_eye(a, eye);
    let normal_c = (b - a).cross(c - a);
    let side_c = to_eye.dot(normal_c);
    match d {
        Some(d) => {
            let normal_d = (b - a).cross(d - a);
            let side_d = to_eye.dot(normal_d);
            if side_c.abs() * normal_d.length() >= side_d.abs() * normal_c.length() {
                side_c > 0.0
            } else {
                side_d > 0.0
            }
        }
        None => side_c > 0.0,
    }
}

/// Whether the triangle with corners `c` is seen from `eye` (homogeneous) within
/// [`EDGE_ON`] of edge-on, taken at its centroid; one without area, or with NaN, counts as
/// edge-on. Such a triangle draws as a line: it hides nothing, and no pixel's ray meets it.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN counts as edge-on
pub fn is_edge_on(c: [DVec3; 3], eye: DVec4) -> bool {
    let n = (c[1] - c[0]).cross(c[2] - c[0]);
    let towards = towards_eye((c[0] + c[1] + c[2]) / 3.0, eye);
    !(n.dot(towards).abs() > EDGE_ON * n.length() * towards.length())
}

/// Twin of `EDGE_ON` in common.wgsl: the sine of the angle between the direction to the eye
/// and a triangle's plane within which [`is_silhouette`] takes the triangle as edge-on. The
/// eye in a face's plane (a box seen along a face, an axis-aligned orthographic view) puts
/// the face at 0 only to rounding, which f32 and f64 round differently: an edge between a
/// front face and such a face was an outline in one and a plain edge in the other. Below
/// the clusters' `SPREAD_MARGIN` and the outline hints' `EDGE_ON_MARGIN`, so no cull skips
/// such a fold.
pub const EDGE_ON: f64 = 1e-5;
const _: () = assert!(EDGE_ON < crate::mesh::clusters::SPREAD_MARGIN / 2.0);
const _: () = assert!(EDGE_ON < crate::mesh::adjacency::EDGE_ON_MARGIN / 1.5);

/// Twin of `HIDDEN_MARGIN` in scene.wgsl: how much nearer a surface must be than a point of
/// a line, in near-row units relative to the point's, to hide it. Triangles that meet at an
/// edge or a vertex agree there only to rounding.
pub const HIDDEN_MARGIN: f64 = 1e-4;

/// Twin of `host_margin` in common.wgsl: the host's geometry hides a point only where it is
/// nearer by more than this (in reverse depth, for a host depth of reverse value `r` and a
/// depth format whose smallest step there is `quantum`): two format steps (the host stores
/// its depth rounded) and the f32 rounding of two transforms, so a host that also draws the wireframed meshes itself does
/// not hide their lines with its own copy of them. The host's depth is moved back by it
/// once, where the pass reads it.
pub fn host_margin(r: f64, quantum: f64) -> f64 {
    1e-5 * r + 2.0 * quantum + 1e-6
}

/// Twin of `host_slope` in common.wgsl: how much the host's reverse depth `h` changes per
/// pixel, from its values at the left, right, upper and lower neighbours (negative where the
/// host has no geometry): per axis the smaller change to a neighbour with geometry (the
/// surface's own slope, not the jump at its edge), summed over both axes.
pub fn host_slope(h: f64, [left, right, up, down]: [f64; 4]) -> f64 {
    let axis = |a: f64, b: f64| {
        let sides = [
            (a >= 0.0).then(|| (h - a).abs()),
            (b >= 0.0).then(|| (b - h).abs()),
        ];
        sides.into_iter().flatten().reduce(f64::min).unwrap_or(0.0)
    };
    axis(left, right) + axis(up, down)
}

/// Twin of `host_hides` in common.wgsl: whether the host's surface at a pixel (reverse depth
/// `host`, changing by `slope` per pixel) hides a line point of reverse depth `point` that
/// lies `distance` pixels from the pixel's centre. The host must be nearer by twice its own
/// depth change over that distance and one pixel more, so a point on or in front of the
/// host's surface where it lies (an outline where an object meets the ground) is never
/// hidden by the host's depth sampled a pixel or two away.
pub fn host_hides(host: f64, point: f64, distance: f64, slope: f64) -> bool {
    host - point > 2.0 * (distance + 1.0) * slope
}

/// Twin of `nearer` in scene.wgsl: true when the point with near row `a_near` is nearer than
/// the one with near row `b_near` and clip w `b_w` at the same screen point, by more than
/// [`HIDDEN_MARGIN`]. Along one pixel's ray the near row grows with depth, for perspective
/// and orthographic views alike.
pub fn nearer(a_near: f64, b_near: f64, b_w: f64) -> bool {
    nearer_by(a_near, b_near, b_w, HIDDEN_MARGIN)
}

/// Twin of `CAP_MARGIN` in scene.wgsl: how much nearer than a point of a line a surface
/// within [`HIDDEN_MARGIN`] of it must be to tell how the eye's ray reaches that point, in a
/// frame with section planes (from a cut solid's section face, through a back face or through
/// a front face).
pub const CAP_MARGIN: f64 = 1e-6;

/// Twin of `REACH_SLACK` in trace.wgsl: pixels past a line's reach that still take its
/// distance from the traced map (the line has no intensity there). Both implementations
/// allow it, so that f32 rounding decides only for pixels within its own error of this
/// boundary, not for all within a slack the GPU alone allows.
pub const REACH_SLACK: f64 = 1e-3;

/// Twin of `DASH_SLACK` in trace.wgsl: a dash (or dot) of a line pattern that reaches
/// within this many pixels of a drawn run of the line (a visible or hidden part of it, up to
/// its edge's end) is drawn from the run's nearest point. The pattern starts with a dash at
/// a chain's first vertex, which is where the run of its first edge ends: the two meet
/// exactly by definition and only to rounding in f32, so without the slack a dot there is
/// drawn or not by the last bit.
pub const DASH_SLACK: f64 = 1e-3;

/// Twin of `END_INSET` in trace.wgsl: pixels inside a line's ends at which the visibility
/// of each end is tested. At a vertex every triangle round it agrees with the line only to
/// rounding, so the end itself could flip to a class its line has nowhere else, and a run of
/// no length is still drawn as a dot a line wide.
pub const END_INSET: f64 = 1.0 / 256.0;

/// [`nearer`] by more than `margin` (relative, as [`HIDDEN_MARGIN`]); twin of `nearer` and
/// `nearer_than_cap` in scene.wgsl.
pub fn nearer_by(a_near: f64, b_near: f64, b_w: f64, margin: f64) -> bool {
    a_near < b_near - margin * (b_near.abs() + b_w)
}

/// Twin of `segment_distance` in common.wgsl: pixels from `pixel` to the screen segment
/// between the clip-space points `ca` and `cb`, cut to its part in front of the near plane
/// ([`NO_EDGE`] when none is). Used where the nearest point of a drawn edge need not lie
/// between its ends: across undrawn edges, an edge's line passes closer than the edge.
pub fn segment_distance(ca: DVec4, cb: DVec4, pixel: DVec2, size: DVec2) -> f64 {
    if ca.z < 0.0 && cb.z < 0.0 {
        return NO_EDGE;
    }
    let cut = |k: f64| ca.lerp(cb, k);
    let (a, b) = if ca.z < 0.0 {
        (cut(ca.z / (ca.z - cb.z)), cb)
    } else if cb.z < 0.0 {
        (ca, cut(ca.z / (ca.z - cb.z)))
    } else {
        (ca, cb)
    };
    let (pa, pb) = (
        pixel_relative(a, pixel, size),
        pixel_relative(b, pixel, size),
    );
    let (a, b) = (pa.truncate() / pa.z, pb.truncate() / pb.z);
    let ab = b - a;
    let len2 = ab.length_squared();
    let k = if len2 > 0.0 {
        (-a.dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let d = (a + ab * k).length();
    if d.is_nan() {
        NO_EDGE
    } else {
        d
    }
}

/// What [`patch_distance`] needs to know of one triangle.
#[derive(Clone, Copy, Debug)]
pub struct PatchTriangle {
    /// Corners in the coordinates the eye is given in.
    pub local: [DVec3; 3],
    /// Corners in clip space.
    pub clip: [DVec4; 3],
    /// Drawn edges (bit `i` for edge `i`).
    pub mask: u8,
    /// The triangle across each edge, or `u32::MAX`.
    pub neighbours: [u32; 3],
}

/// Twin of `patch_distance` in edge_pass.wgsl: pixels from `pixel` to the nearest drawn edge
/// (as a segment) of the patch around `start`, the triangles reached from it across undrawn
/// edges that are not silhouettes from `eye` (beyond a silhouette the surface folds back
/// under itself, and its edges there are hidden). A search of at most
/// [`PATCH_TRIANGLES`](crate::mesh::patches::PATCH_TRIANGLES) triangles, breadth first.
pub fn patch_distance(
    start: u32,
    eye: DVec4,
    pixel: DVec2,
    size: DVec2,
    triangle: impl Fn(u32) -> PatchTriangle,
) -> f64 {
    let cap = crate::mesh::patches::PATCH_TRIANGLES;
    let mut queue = vec![start];
    let mut best = NO_EDGE;
    let mut k = 0;
    while k < queue.len() {
        let t = triangle(queue[k]);
        k += 1;
        for i in 0..3 {
            let j = (i + 1) % 3;
            if t.mask & (1 << i) != 0 {
                best = best.min(segment_distance(t.clip[i], t.clip[j], pixel, size));
                continue;
            }
            let n = t.neighbours[i];
            if queue.len() >= cap || n == u32::MAX || queue.contains(&n) {
                continue;
            }
            let d = triangle(n).local;
            let d = (d[0] + d[1] + d[2]) / 3.0;
            if !is_silhouette(t.local[i], t.local[j], t.local[(i + 2) % 3], d, eye) {
                queue.push(n);
            }
        }
    }
    best
}

fn line_distance(l: DVec3, drawn: bool) -> f64 {
    let len = l.truncate().length();
    if !drawn || len.is_nan() || len <= 0.0 {
        return NO_EDGE;
    }
    l.z.abs() / len
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIZE: DVec2 = DVec2::new(200.0, 100.0);

    /// Clip coordinates of a screen point at depth w (z set in front of the near plane).
    fn at(sx: f64, sy: f64, w: f64) -> DVec4 {
        DVec4::new(
            (2.0 * sx / SIZE.x - 1.0) * w,
            (1.0 - 2.0 * sy / SIZE.y) * w,
            0.5 * w,
            w,
        )
    }

    #[test]
    fn distances_in_pixels_on_screen_triangle() {
        // Right triangle with legs on x = 10 and y = 10 (screen), hypotenuse x + y = 120.
        let tri = [
            at(10.0, 10.0, 1.0),
            at(110.0, 10.0, 2.0),
            at(10.0, 110.0, 3.0),
        ];
        let e = edge_eval(tri, 0b111, DVec2::new(20.5, 30.5), SIZE);
        assert!((e.distance[0] - 20.5).abs() < 1e-9); // edge 0: y = 10
        assert!((e.distance[2] - 10.5).abs() < 1e-9); // edge 2: x = 10
        assert!((e.distance[1] - (120.0 - 51.0) / 2f64.sqrt()).abs() < 1e-9);
        let sum: f64 = e.bary.iter().sum();
        assert!((sum - 1.0).abs() < 1e-12);
        // Masked edges are infinitely far.
        let e = edge_eval(tri, 0b010, DVec2::new(20.5, 30.5), SIZE);
        assert_eq!(e.min_distance(), e.distance[1]);
    }

    #[test]
    fn barycentrics_are_perspective_correct() {
        let view_proj = glam::dcamera::rh::proj::directx::perspective(1.0, 2.0, 0.1, 100.0)
            * glam::dcamera::rh::view::look_at_mat4(
                DVec3::new(0.3, 0.2, 4.0),
                DVec3::ZERO,
                DVec3::Y,
            );
        let world = [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(2.0, -0.5, -3.0),
            DVec3::new(0.0, 1.5, 1.0),
        ];
        let clip = world.map(|p| view_proj * p.extend(1.0));
        // A known interior point: project it, evaluate there, recover its weights.
        let weights = [0.2, 0.5, 0.3];
        let q = world[0] * weights[0] + world[1] * weights[1] + world[2] * weights[2];
        let c = view_proj * q.extend(1.0);
        let pixel = DVec2::new(
            (c.x / c.w + 1.0) * 0.5 * SIZE.x,
            (1.0 - c.y / c.w) * 0.5 * SIZE.y,
        );
        let e = edge_eval(clip, 0b111, pixel, SIZE);
        for (b, w) in e.bary.iter().zip(weights) {
            assert!((b - w).abs() < 1e-9, "{:?}", e.bary);
        }
    }

    #[test]
    fn exact_with_a_vertex_behind_the_eye() {
        // The 3D segment from a (in front) to b (behind the eye) projects to the ray from
        // a's image away from b's "image" through infinity: the line is the same line.
        let view_proj = glam::dcamera::rh::proj::directx::perspective(1.2, 2.0, 0.1, 100.0);
        let a = DVec3::new(0.5, 0.2, -2.0);
        let b = DVec3::new(-0.3, 0.1, 1.0); // behind the eye (z > 0 in view space)
        let c = DVec3::new(0.0, -1.0, -3.0);
        let clip = [a, b, c].map(|p| view_proj * p.extend(1.0));
        assert!(clip[1].w < 0.0);
        // A point on segment a-b in front of the near plane lies on edge 0's line.
        let q = a.lerp(b, 0.3);
        let cq = view_proj * q.extend(1.0);
        assert!(cq.w > 0.1);
        let pixel = DVec2::new(
            (cq.x / cq.w + 1.0) * 0.5 * SIZE.x,
            (1.0 - cq.y / cq.w) * 0.5 * SIZE.y,
        );
        let e = edge_eval(clip, 0b111, pixel, SIZE);
        assert!(e.distance[0] < 1e-9, "{:?}", e.distance);
        assert!(e.distance.iter().all(|d| d.is_finite()));
    }

    #[test]
    fn edges_behind_the_near_plane_are_invisible() {
        let mut tri = [
            at(10.0, 10.0, 1.0),
            at(110.0, 10.0, 2.0),
            at(10.0, 110.0, 3.0),
        ];
        tri[0].z = -0.1;
        tri[1].z = -0.2;
        let e = edge_eval(tri, 0b111, DVec2::new(20.5, 30.5), SIZE);
        assert_eq!(e.distance[0], NO_EDGE);
        assert!(e.distance[1].is_finite() && e.distance[2].is_finite());
    }

    #[test]
    fn a_quad_edge_is_found_across_its_diagonal() {
        // The quad (10, 10) (110, 10) (110, 60) (10, 60) on screen, split along a → c.
        let screen = [(10.0, 10.0), (110.0, 10.0), (110.0, 60.0), (10.0, 60.0)];
        let local = screen.map(|(x, y)| DVec3::new(x, y, 0.0));
        let clip = screen.map(|(x, y)| at(x, y, 1.0));
        let tris = [
            ([0, 1, 2], 0b011u8, [u32::MAX, u32::MAX, 1]),
            ([0, 2, 3], 0b110, [0, u32::MAX, u32::MAX]),
        ];
        let triangle = |t: u32| {
            let (corners, mask, neighbours) = tris[t as usize];
            PatchTriangle {
                local: corners.map(|c| local[c]),
                clip: corners.map(|c| clip[c]),
                mask,
                neighbours,
            }
        };
        let eye = DVec4::new(60.0, 35.0, 100.0, 1.0);
        // Above the diagonal, in the first triangle: its own edges are 44.5 and 9.5 px away,
        // the quad's bottom edge (the second triangle's) 5.5.
        let pixel = DVec2::new(100.5, 54.5);
        let own = edge_eval(triangle(0).clip, 0b011, pixel, SIZE).min_distance();
        assert!((own - 9.5).abs() < 1e-9);
        let d = patch_distance(0, eye, pixel, SIZE, triangle);
        assert!((d - 5.5).abs() < 1e-9, "{d}");
        // Beyond an end of the bottom edge the distance is to its end, not its line.
        let d = segment_distance(clip[2], clip[3], DVec2::new(113.5, 64.5), SIZE);
        assert!((d - 3.5f64.hypot(4.5)).abs() < 1e-9, "{d}");
        // Folded over the first triangle, so that the eye sees the diagonal as a silhouette:
        // not crossed.
        let over = DVec3::new(130.0, 20.0, 5.0);
        let folded = |t: u32| {
            let mut tri = triangle(t);
            if t == 1 {
                tri.local[2] = over;
            }
            tri
        };
        let centroid = (local[0] + local[2] + over) / 3.0;
        assert!(is_silhouette(local[2], local[0], local[1], centroid, eye));
        assert!((patch_distance(0, eye, pixel, SIZE, folded) - 9.5).abs() < 1e-9);
    }

    #[test]
    fn a_segment_behind_the_eye_is_cut_at_the_near_plane() {
        let mut a = at(50.0, 50.0, 1.0);
        let mut b = at(150.0, 50.0, 1.0);
        // b's end behind the near plane: the visible part ends where z crosses 0.
        b.z = -a.z;
        let d = segment_distance(a, b, DVec2::new(140.5, 50.5), SIZE);
        assert!((d - (140.5f64 - 100.0).hypot(0.5)).abs() < 1e-9, "{d}");
        a.z = -1.0;
        assert_eq!(
            segment_distance(a, b, DVec2::new(60.5, 50.5), SIZE),
            NO_EDGE
        );
    }

    #[test]
    fn degenerate_triangles_give_no_nan() {
        let p = at(50.0, 50.0, 1.0);
        let e = edge_eval([p, p, p], 0b111, DVec2::new(50.5, 50.5), SIZE);
        assert!(e.distance.iter().all(|d| *d == NO_EDGE));
        assert!(e.bary.iter().all(|b| b.is_finite()));
        let e = edge_eval(
            [
                at(0.0, 0.0, 1.0),
                at(50.0, 50.0, 1.0),
                at(100.0, 100.0, 1.0),
            ],
            0b111,
            DVec2::new(20.5, 20.5),
            SIZE,
        );
        assert!(e.distance.iter().all(|d| !d.is_nan()));
        assert!(e.bary.iter().all(|b| b.is_finite()));
    }
}
