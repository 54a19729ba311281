//! The CPU ground truth: one ray per pixel centre through an `obvhs` BVH, with the hit and the
//! edge distance computed in f64 by the same definitions the GPU uses (`edge_math`, `style`).
//!
//! The ray of pixel `(x, y)` is the segment from the near plane (NDC z = 0) to the far plane
//! (NDC z = 1) through NDC `u = (x + 0.5)/W·2 − 1`, `v = 1 − (y + 0.5)/H·2`, unprojected with
//! the f64 inverse of [`Camera::view_projection`](crate::Camera::view_projection): exactly the
//! part of the line that rasterization keeps, so nothing in front of the near plane or beyond
//! the far plane is hit.
//!
//! The BVH only culls: it is built in f32 over triangle boxes padded by a margin far larger
//! than any f32 rounding of the ray, so it never drops a triangle the ray meets. Every
//! candidate is then tested in f64 with a watertight edge test (each edge's sign is the triple
//! product of its endpoints relative to the ray origin and the ray direction, so the two
//! triangles sharing an edge compute exactly opposite values and a ray cannot slip between
//! them). A pixel centre exactly on a shared edge may pick either triangle; exact depth ties
//! pick the lower id, as the GPU's strict depth test keeps the first triangle drawn.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::error::{Error, Result};
use crate::gpu::light_world_dir;
use crate::render::{Frame, Scene};
use crate::style::{self, Color};
use crate::{edge_math, Mesh};
use glam::{DMat4, DVec2, DVec3, DVec4, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::ray::{Ray, RayHit};
use rayon::prelude::*;

/// Background id, as in every other map.
const BACKGROUND: u32 = u32::MAX;

/// A ray hit: the triangle and where along the pixel's near-to-far segment it lies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Triangle id (index into [`Mesh::triangles`]).
    pub id: u32,
    /// Parameter along the segment: 0 on the near plane, 1 on the far plane.
    pub t: f64,
    /// The hit point in world space.
    pub point: DVec3,
}

/// A BVH over a mesh's triangles for exact (f64) ray casting.
pub struct RayCaster<'a> {
    mesh: &'a Mesh,
    bvh: Bvh2,
    /// Centre of the mesh bounds; the BVH and the f64 tests work relative to it.
    centre: DVec3,
    /// Half extent of the padded bounds, per axis, relative to `centre`.
    half: DVec3,
    /// Triangle corners relative to `centre`, in f64.
    corners: Vec<[DVec3; 3]>,
}

impl<'a> RayCaster<'a> {
    /// Builds the BVH over `mesh`.
    pub fn new(mesh: &'a Mesh) -> Self {
        let (lo, hi) = mesh.bounds();
        let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
        let centre = (lo + hi) * 0.5;
        let extent = (hi - lo) * 0.5;
        // Every f32 rounding in the BVH's box tests (ray origin and direction, box bounds,
        // the slab products) is ~1e-7 of the scene's size, because rays are clipped to the
        // mesh bounds first; a margin of 1e-4 of the size keeps the culling conservative.
        let radius = extent
            .length()
            .max(centre.abs().max_element() * 1e-6)
            .max(1e-30);
        let pad = 1e-4 * radius;
        let half = extent + DVec3::splat(2.0 * pad);
        let positions = mesh.positions();
        let corners: Vec<[DVec3; 3]> = mesh
            .triangles()
            .iter()
            .map(|t| t.map(|v| positions[v as usize].as_dvec3() - centre))
            .collect();
        let boxes: Vec<Aabb> = corners
            .iter()
            .map(|c| {
                let lo = c[0].min(c[1]).min(c[2]) - DVec3::splat(pad);
                let hi = c[0].max(c[1]).max(c[2]) + DVec3::splat(pad);
                Aabb::new(to_vec3a(lo), to_vec3a(hi))
            })
            .collect();
        let bvh = obvhs::bvh2::builder::build_bvh2(
            &boxes,
            obvhs::BvhBuildParams::medium_build(),
            &mut std::time::Duration::default(),
        );
        Self {
            mesh,
            bvh,
            centre,
            half,
            corners,
        }
    }

    /// The nearest triangle hit by the segment from `from` (t = 0) to `to` (t = 1), both in
    /// world space, with `0 ≤ t ≤ 1`.
    pub fn cast(&self, from: DVec3, to: DVec3) -> Option<Hit> {
        let o = from - self.centre;
        let d = to - from;
        // Clip the segment to the padded bounds in f64, so the f32 ray the BVH sees starts
        // near the mesh and its rounding is relative to the mesh's size.
        let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
        for axis in 0..3 {
            let (oa, da, ha) = (o[axis], d[axis], self.half[axis]);
            if da == 0.0 {
                if oa.abs() > ha {
                    return None;
                }
                continue;
            }
            let (a, b) = ((-ha - oa) / da, (ha - oa) / da);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        if !(t1 > t0) {
            return None;
        }
        let span = d * (t1 - t0);
        let scale = span.abs().max_element();
        if !(scale > 0.0) || !scale.is_finite() {
            return None;
        }
        // Direction with largest component 1, so the BVH's tiny-component guard
        // (`safe_inverse`) only applies to rays within 1.2e-7 rad of a slab, whose error the
        // padding covers; tau in 0..scale spans the clipped segment.
        let ray = Ray::new(
            to_vec3a(o + d * t0),
            to_vec3a(span / scale),
            0.0,
            (scale * (1.0 + 1e-6)) as f32,
        );
        let to_tau = scale / (t1 - t0);
        let mut best: Option<(f64, u32)> = None;
        let mut hit = RayHit::none();
        self.bvh.ray_traverse(ray, &mut hit, |_, slot| {
            let id = self.bvh.primitive_indices[slot];
            let Some(t) = intersect(&self.corners[id as usize], o, d) else {
                return f32::INFINITY;
            };
            let better = match best {
                None => true,
                Some((bt, bid)) => t < bt || (t == bt && id < bid),
            };
            if !better {
                return f32::INFINITY;
            }
            best = Some((t, id));
            // Report the hit to the BVH rounded up, so its culling stays conservative.
            let tau = ((t - t0) * to_tau).max(0.0) as f32;
            tau.next_up()
        });
        best.map(|(t, id)| Hit {
            id,
            t,
            point: self.centre + o + d * t,
        })
    }

    /// The mesh this caster was built over.
    pub fn mesh(&self) -> &Mesh {
        self.mesh
    }
}

fn to_vec3a(v: DVec3) -> Vec3A {
    Vec3A::new(v.x as f32, v.y as f32, v.z as f32)
}

/// Watertight, double-sided segment/triangle test in f64: the segment `o + t·d`, `0 ≤ t ≤ 1`.
/// Returns `t` of the hit.
fn intersect(c: &[DVec3; 3], o: DVec3, d: DVec3) -> Option<f64> {
    let a = c[0] - o;
    let b = c[1] - o;
    let cc = c[2] - o;
    // Each edge's cross product depends only on its endpoints, and swapping them negates it
    // exactly in floating point, so neighbours agree on which side of their edge the ray is.
    let ab = a.cross(b);
    let bc = b.cross(cc);
    let ca = cc.cross(a);
    let e = [bc.dot(d), ca.dot(d), ab.dot(d)];
    let all_pos = e.iter().all(|&v| v >= 0.0);
    let all_neg = e.iter().all(|&v| v <= 0.0);
    if !(all_pos || all_neg) {
        return None;
    }
    let sum = e[0] + e[1] + e[2];
    if sum == 0.0 || !sum.is_finite() {
        // The ray lies in the triangle's plane (edge-on): it does not cover the pixel.
        return None;
    }
    // Plane normal n = ab + bc + ca, n·d = sum and n·a = (b × c)·a.
    let t = bc.dot(a) / sum;
    (0.0..=1.0).contains(&t).then_some(t)
}

/// Everything the ground truth knows about one pixel.
#[derive(Clone, Copy, Debug)]
struct Sample {
    id: u32,
    depth: f32,
    distance: f32,
    rgba: [u8; 4],
}

/// Renders `scene` by ray casting on the CPU in f64: the reference every GPU method is
/// measured against. Fills every map of the [`Frame`].
pub fn render_raycast(scene: &Scene<'_>) -> Result<Frame> {
    let (width, height) = scene.size;
    if width == 0 || height == 0 {
        return Err(Error::InvalidSetting(format!(
            "image size {width}x{height} has a zero side"
        )));
    }
    scene.camera.validate()?;
    scene.style.validate()?;
    let mesh = scene.mesh;
    let vp = scene.camera.view_projection(width, height);
    let inv = vp.inverse();
    if !inv.is_finite() {
        return Err(Error::InvalidCamera(
            "the view-projection matrix is not invertible".into(),
        ));
    }
    let caster = RayCaster::new(mesh);
    let masks = mesh.edge_mask(scene.edges);
    let shading = Shading::new(scene);
    let outline = crate::outline::outline_map(&caster, &scene.camera, &scene.style, scene.size);

    let pixels = u64::from(width) * u64::from(height);
    let bar = progress_bar(u64::from(height), pixels);
    let size = DVec2::new(f64::from(width), f64::from(height));
    let rows: Vec<Vec<Sample>> = (0..height)
        .into_par_iter()
        .map(|y| {
            let row = (0..width)
                .map(|x| {
                    let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                    let k = (y * width + x) as usize;
                    let line = (outline.distance[k], outline.fade[k]);
                    sample(&caster, &vp, &inv, &masks, &shading, pixel, size, line)
                })
                .collect();
            bar.inc(1);
            row
        })
        .collect();
    bar.finish_and_clear();

    let n = pixels as usize;
    let mut frame = Frame {
        size: scene.size,
        rgba: Vec::with_capacity(4 * n),
        ids: Vec::with_capacity(n),
        depth: Vec::with_capacity(n),
        edge_distance: Vec::with_capacity(n),
    };
    for s in rows.iter().flatten() {
        frame.rgba.extend_from_slice(&s.rgba);
        frame.ids.push(s.id);
        frame.depth.push(s.depth);
        frame.edge_distance.push(s.distance);
    }
    Ok(frame)
}

/// A progress bar on stderr when it is a terminal and the job is more than a moment.
fn progress_bar(rows: u64, pixels: u64) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if pixels < 250_000 || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(rows);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "ray casting {bar:40} {pos}/{len} rows, {elapsed} (eta {eta})",
    ) {
        bar.set_style(style);
    }
    bar
}

/// The frame's shading inputs in f64, as the GPU's `Frame` uniforms carry them.
struct Shading {
    eye: DVec3,
    light: DVec3,
    fill: [f64; 3],
    wire: [f64; 4],
    background: Color,
    ambient: f64,
    line_width: f64,
    fade: [f64; 2],
}

impl Shading {
    fn new(scene: &Scene<'_>) -> Self {
        let s = &scene.style;
        let rgb = |c: Color| [0, 1, 2].map(|i| f64::from(c.0[i]));
        Self {
            eye: scene.camera.eye.as_dvec3(),
            light: light_world_dir(&scene.camera, s),
            fill: rgb(s.fill_color),
            wire: s.wire_color.0.map(f64::from),
            background: s.background,
            ambient: f64::from(s.ambient),
            line_width: f64::from(s.line_width),
            fade: s.fade_range().map(f64::from),
        }
    }
}

/// The ground truth at one pixel centre; `outline` is the pixel's (distance, fade) from the
/// outline map.
#[allow(clippy::too_many_arguments)]
fn sample(
    caster: &RayCaster<'_>,
    vp: &DMat4,
    inv: &DMat4,
    masks: &[u8],
    shading: &Shading,
    pixel: DVec2,
    size: DVec2,
    outline: (f64, f64),
) -> Sample {
    let u = pixel.x / size.x * 2.0 - 1.0;
    let v = 1.0 - pixel.y / size.y * 2.0;
    let near = inv.project_point3(DVec3::new(u, v, 0.0));
    let far = inv.project_point3(DVec3::new(u, v, 1.0));
    let outline_line = style::line_intensity(outline.0, shading.line_width) * outline.1;
    let Some(hit) = caster.cast(near, far) else {
        let bg = shading.background.0.map(f64::from);
        let i = outline_line * shading.wire[3];
        let mix = |k: usize| (bg[k] + (shading.wire[k] - bg[k]) * i) as f32;
        return Sample {
            id: BACKGROUND,
            depth: 1.0,
            distance: outline.0 as f32,
            rgba: Color([mix(0), mix(1), mix(2), bg[3].max(i) as f32]).to_srgb8(),
        };
    };
    let mesh = caster.mesh();
    let tri = mesh.triangles()[hit.id as usize];
    let world = tri.map(|v| mesh.positions()[v as usize].as_dvec3());
    let clip: [DVec4; 3] = world.map(|p| *vp * p.extend(1.0));
    let e = edge_math::edge_eval(clip, masks[hit.id as usize], pixel, size);
    let distance = e.min_distance();
    let c = *vp * hit.point.extend(1.0);
    let depth = (c.z / c.w).clamp(0.0, 1.0);

    // Twin of `evaluate` in edge_pass.wgsl, in f64.
    let [b0, b1, b2] = e.bary;
    let point = world[0] * b0 + world[1] * b1 + world[2] * b2;
    let to_eye = shading.eye - point;
    let normals = tri.map(|v| mesh.normals()[v as usize].as_dvec3());
    let mut n = normals[0] * b0 + normals[1] * b1 + normals[2] * b2;
    if !(n.dot(n) > 1e-12) {
        n = (world[1] - world[0]).cross(world[2] - world[0]);
    }
    if !(n.dot(n) > 0.0) {
        n = to_eye;
    }
    let surface = style::shade(
        shading.fill,
        n.normalize_or_zero(),
        to_eye,
        shading.light,
        shading.ambient,
    );
    // As the edge pass: the stronger of the own edge and the outline.
    let own =
        style::line_intensity(distance, shading.line_width) * style::depth_fade(c.w, shading.fade);
    let i = own.max(outline_line) * shading.wire[3];
    let mix = |k: usize| (surface[k] + (shading.wire[k] - surface[k]) * i) as f32;
    Sample {
        id: hit.id,
        depth: depth as f32,
        distance: distance.min(outline.0) as f32,
        rgba: Color([mix(0), mix(1), mix(2), 1.0]).to_srgb8(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::EdgeSelection;
    use crate::{Camera, Style};
    use glam::Vec3;

    fn quad() -> Mesh {
        let p = vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ];
        Mesh::new(p, None, vec![[0, 1, 2], [0, 2, 3]], None).unwrap()
    }

    #[test]
    fn shared_edges_are_watertight() {
        // A fan of thin triangles around the origin; rays through points on and around the
        // shared edges must always hit something.
        let n = 97;
        let mut p = vec![Vec3::ZERO];
        for i in 0..n {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            p.push(Vec3::new(a.cos(), a.sin(), 0.1 * (3.0 * a).sin()));
        }
        let tris = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
        let mesh = Mesh::new(p.clone(), None, tris, None).unwrap();
        let caster = RayCaster::new(&mesh);
        for i in 0..n as usize {
            for k in 1..50 {
                let q = p[1 + i].as_dvec3() * (f64::from(k) / 50.0);
                // Through q, a point on the shared edge from the centre to corner i.
                let from = q + DVec3::new(0.3, 0.1, 5.0);
                let to = q - DVec3::new(0.3, 0.1, 5.0);
                assert!(
                    caster.cast(from, to).is_some(),
                    "ray {i} {k} slipped through"
                );
            }
        }
    }

    #[test]
    fn near_and_far_planes_bound_the_segment() {
        let mesh = quad();
        let caster = RayCaster::new(&mesh);
        let down =
            |z0: f64, z1: f64| caster.cast(DVec3::new(0.2, 0.3, z0), DVec3::new(0.2, 0.3, z1));
        let h = down(1.0, -1.0).unwrap();
        assert!((h.t - 0.5).abs() < 1e-15 && (h.point.z).abs() < 1e-15);
        assert!(
            down(2.0, 0.5).is_none(),
            "the plane lies beyond the far end"
        );
        assert!(
            down(-0.5, -2.0).is_none(),
            "the plane lies before the near end"
        );
        assert!(down(0.5, -0.5).is_some());
    }

    #[test]
    fn renders_a_quad_like_the_definition_says() {
        let mesh = quad();
        let camera = Camera {
            eye: Vec3::new(0.0, 0.0, 3.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 60.0,
            near: 0.5,
            far: 10.0,
        };
        let scene = Scene {
            mesh: &mesh,
            camera,
            style: Style::default(),
            size: (64, 48),
            edges: EdgeSelection::All,
        };
        let frame = render_raycast(&scene).unwrap();
        assert_eq!(frame.rgba.len(), 64 * 48 * 4);
        // The corner pixel is background; the centre is covered at the right depth.
        assert_eq!(frame.ids[0], BACKGROUND);
        assert_eq!(frame.depth[0], 1.0);
        assert!(frame.edge_distance[0].is_infinite());
        let centre = 24 * 64 + 20;
        assert!(frame.ids[centre] < 2);
        let view_z = -3.0_f64;
        let (n, f) = (0.5_f64, 10.0_f64);
        let expect = (f / (n - f) * view_z + n * f / (n - f)) / -view_z;
        assert!((f64::from(frame.depth[centre]) - expect).abs() < 1e-6);
        // Distances are finite on the quad and never NaN.
        assert!(frame.edge_distance[centre].is_finite());
        assert!(frame.edge_distance.iter().all(|d| !d.is_nan()));
    }
}
