//! The ground truth's ray casting: an `obvhs` BVH over every object's triangles in world
//! space, cast in f64 (the culling and watertight test described in [`super::raycast`]);
//! the rays of a view's pixels; each object's line style; and the host's own surfaces as
//! occluders. The per-pixel truth (`raycast.rs`) and the outline definition
//! (`outline.rs`) both cast through it.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::camera::{ClipRows, DepthRange, View};
use crate::edge_math;
use crate::error::{Error, Result};
use crate::style;
use crate::world::{Shot, World};
use glam::{DMat3, DMat4, DVec2, DVec3, DVec4, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::ray::{Ray, RayHit};
use rayon::prelude::*;

/// A ray hit: the triangle and where along the pixel's near-to-far segment it lies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Global triangle id (objects in order, each object's triangles in its mesh's order).
    pub id: u32,
    /// The object hit.
    pub object: u32,
    /// The triangle of the object's mesh.
    pub tri: u32,
    /// Parameter along the segment: 0 at its start, 1 at its end.
    pub t: f64,
    /// The hit point in world space.
    pub point: DVec3,
}

/// A BVH over a world's triangles for exact (f64) ray casting.
pub struct RayCaster<'a> {
    world: &'a World,
    first_ids: Vec<u32>,
    bvh: Bvh2,
    /// Centre of the world bounds; the BVH and the f64 tests work relative to it.
    centre: DVec3,
    /// Half extent of the padded bounds, per axis, relative to `centre`.
    half: DVec3,
    /// Triangle corners in world space relative to `centre`, by global id.
    corners: Vec<[DVec3; 3]>,
    /// World units per BVH unit: the BVH works on the world scaled to about ±1, so tiny
    /// and huge worlds keep f32's precision and range.
    unit: f64,
}

impl<'a> RayCaster<'a> {
    /// Builds the BVH over every object of `world`.
    pub fn new(world: &'a World) -> Self {
        let first_ids = world.first_ids();
        let (lo, hi) = world.bounds();
        let centre = (lo + hi) * 0.5;
        let extent = (hi - lo) * 0.5;
        // Every f32 rounding in the BVH's box tests (ray origin and direction, box bounds,
        // the slab products) is ~1e-7 of the scene's size, because rays are clipped to the
        // bounds first; a margin of 1e-4 of the size keeps the culling conservative.
        let radius = extent
            .length()
            .max(centre.abs().max_element() * 1e-6)
            .max(1e-300);
        let pad = 1e-4 * radius;
        let half = extent + DVec3::splat(2.0 * pad);
        let corners: Vec<[DVec3; 3]> = world
            .objects
            .iter()
            .flat_map(|o| {
                let mesh = &world.meshes[o.mesh].mesh;
                let p = mesh.positions();
                let m = o.transform;
                mesh.triangles()
                    .iter()
                    .map(move |t| t.map(|v| m.transform_point3(p[v as usize].as_dvec3()) - centre))
            })
            .collect();
        let unit = radius;
        let boxes: Vec<Aabb> = corners
            .iter()
            .map(|c| {
                let lo = (c[0].min(c[1]).min(c[2]) - DVec3::splat(pad)) / unit;
                let hi = (c[0].max(c[1]).max(c[2]) + DVec3::splat(pad)) / unit;
                Aabb::new(to_vec3a(lo), to_vec3a(hi))
            })
            .collect();
        let bvh = build_bvh(&boxes);
        Self {
            world,
            first_ids,
            bvh,
            centre,
            half,
            corners,
            unit,
        }
    }

    /// The nearest triangle hit by the segment from `from` (t = 0) to `to` (t = 1), both in
    /// world space, with `0 ≤ t ≤ 1`.
    pub fn cast(&self, from: DVec3, to: DVec3) -> Option<Hit> {
        self.cast_past(from, to, [u32::MAX; 2])
    }

    /// [`cast`](Self::cast), passing through the triangles with the global ids `skip` (a line's
    /// own triangles, for what lies in front of a point of it).
    pub fn cast_past(&self, from: DVec3, to: DVec3, skip: [u32; 2]) -> Option<Hit> {
        let o = from - self.centre;
        let d = to - from;
        // Clip the segment to the padded bounds in f64, so the f32 ray the BVH sees starts
        // near the world and its rounding is relative to the world's size.
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
        let unit = self.unit;
        let span = d * (t1 - t0);
        let scale = span.abs().max_element();
        if !(scale > 0.0) || !scale.is_finite() {
            return None;
        }
        // Direction with largest component 1, so the BVH's tiny-component guard
        // (`safe_inverse`) only applies to rays within 1.2e-7 rad of a slab, whose error the
        // padding covers; tau in 0..scale/unit spans the clipped segment (in the BVH's
        // units).
        let ray = Ray::new(
            to_vec3a((o + d * t0) / unit),
            to_vec3a(span / scale),
            0.0,
            (scale / unit * (1.0 + 1e-6)) as f32,
        );
        let to_tau = scale / unit / (t1 - t0);
        let mut best: Option<(f64, u32)> = None;
        let mut hit = RayHit::none();
        self.bvh.ray_traverse(ray, &mut hit, |_, slot| {
            let id = self.bvh.primitive_indices[slot];
            if skip.contains(&id) {
                return f32::INFINITY;
            }
            let Some(t) = intersect(&self.corners[id as usize], o, d) else {
                return f32::INFINITY;
            };
            // What a section plane cuts away is not there.
            let point = self.centre + o + d * t;
            if self.world.sections.iter().any(|s| s.side(point) < 0.0) {
                return f32::INFINITY;
            }
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
        best.map(|(t, id)| {
            let (object, tri) = self.world.locate(&self.first_ids, id);
            Hit {
                id,
                object: object as u32,
                tri,
                t,
                point: self.centre + o + d * t,
            }
        })
    }

    /// The world this caster was built over.
    pub fn world(&self) -> &World {
        self.world
    }

    /// The world-space corners of global triangle `id`.
    pub fn corners(&self, id: u32) -> [DVec3; 3] {
        self.corners[id as usize].map(|c| c + self.centre)
    }

    /// The outward normal of global triangle `id`, not unit: its world winding, turned where
    /// its object's transform mirrors, so a mirrored instance keeps its mesh's outside (twin
    /// of `faces_away` in trace.wgsl).
    pub fn outward(&self, id: u32) -> DVec3 {
        let (object, _) = self.world.locate(&self.first_ids, id);
        let mirror = self.world.objects[object].transform.determinant().signum();
        let c = self.corners(id);
        (c[1] - c[0]).cross(c[2] - c[0]) * mirror
    }

    /// Whether global triangle `id` faces away from `eye` (homogeneous world), seen at its
    /// point `at`.
    pub fn faces_away(&self, id: u32, at: DVec3, eye: DVec4) -> bool {
        self.outward(id).dot(crate::edge_math::towards_eye(at, eye)) < 0.0
    }

    /// The global id of each object's first triangle.
    pub fn first_ids(&self) -> &[u32] {
        &self.first_ids
    }
}

fn to_vec3a(v: DVec3) -> Vec3A {
    Vec3A::new(v.x as f32, v.y as f32, v.z as f32)
}

/// Watertight, double-sided segment/triangle test in f64: the segment `o + t·d`, `0 ≤ t ≤ 1`.
/// Returns `t` of the hit.
pub fn intersect(c: &[DVec3; 3], o: DVec3, d: DVec3) -> Option<f64> {
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

/// The pixel rays of a view: each pixel centre's segment from the near plane to the far
/// plane (or past the world, for an infinite far plane), in world space.
pub struct Rays {
    rows: ClipRows,
    inv: DMat4,
    size: DVec2,
    /// Length that takes a segment from its start past the whole world.
    reach: f64,
    infinite: bool,
}

impl Rays {
    /// The rays of `view` for an image of `size`, long enough to cross `world`.
    pub fn new(view: &View, size: (u32, u32), world: &World) -> Result<Rays> {
        let rows = view.clip_rows(DMat4::IDENTITY);
        let inv = rows.clip.inverse();
        if !inv.is_finite() {
            return Err(Error::InvalidCamera(
                "the view-projection matrix is not invertible".into(),
            ));
        }
        let far = inv * DVec4::new(0.0, 0.0, 1.0, 1.0);
        let infinite = !(far.w.abs() > 1e-12 * far.truncate().length());
        let (lo, hi) = world.bounds();
        let near = inv * DVec4::new(0.0, 0.0, 0.0, 1.0);
        let start = near.truncate() / near.w;
        let reach = 4.0 * ((lo - start).length().max((hi - start).length()) + (hi - lo).length());
        Ok(Rays {
            rows,
            inv,
            size: DVec2::new(f64::from(size.0), f64::from(size.1)),
            reach,
            infinite,
        })
    }

    /// The segment of the ray through full-image point `pixel` (pixel units).
    pub fn segment(&self, pixel: DVec2) -> (DVec3, DVec3) {
        let u = pixel.x / self.size.x * 2.0 - 1.0;
        let v = 1.0 - pixel.y / self.size.y * 2.0;
        let point = |near_row: f64| {
            let p = self.inv * DVec4::new(u, v, near_row, 1.0);
            p.truncate() / p.w
        };
        let from = point(0.0);
        if !self.infinite {
            return (from, point(1.0));
        }
        let dir = (point(0.5) - from).normalize_or_zero();
        (from, from + dir * self.reach)
    }

    /// Clip position (rows x, y, near, w) of a world point.
    pub fn clip(&self, p: DVec3) -> DVec4 {
        self.rows.clip * p.extend(1.0)
    }

    /// The view's clip rows.
    pub fn rows(&self) -> &ClipRows {
        &self.rows
    }

    /// The image size, in pixels.
    pub fn size(&self) -> DVec2 {
        self.size
    }
}

/// Each object's look, as the GPU's instance records carry it.
pub(crate) struct ObjectStyle {
    pub wire: [f64; 4],
    /// The outline's colour and width.
    pub outline: [f64; 4],
    pub outline_width: f64,
    /// The surface's colour (linear RGB).
    pub fill: [f64; 3],
    pub width: f64,
    pub edges: bool,
    pub outlines: bool,
    /// The visible lines' patterns, (dash, period) in pixels (period 0: solid): the drawn
    /// edges', the outline's.
    pub edge_pattern: [f64; 2],
    pub outline_pattern: [f64; 2],
    /// The world has section planes.
    pub sectioned: bool,
    /// Another object's surface passes through it ([`crossed_objects`]), and it draws its
    /// outline.
    pub crossed: bool,
    /// The cut lines' width.
    pub section_width: f64,
    /// Its hidden lines, where it draws any lines.
    pub hidden: Option<style::HiddenLines>,
    /// Model → world normal matrix.
    pub normal: DMat3,
}

/// Per object, whether its lines are drawn as where another's surface passes through it,
/// as the pass decides: a pair whose bounds, grown by the pair's tolerance, meet
/// (`scene::crossing_pairs`) and whose triangles cross (`crossings_between`, in world
/// coordinates), or either of which draws hidden lines.
fn crossed_objects(
    world: &World,
    placed: &[((DVec3, DVec3), DMat4)],
    style: &style::Style,
) -> Vec<bool> {
    use crate::mesh::crossings::{crossings_between, pair_tolerance};
    let hides = |o: usize| world.objects[o].style.hidden_in(style).is_some();
    let corners = |o: usize| -> Vec<[DVec3; 3]> {
        let object = &world.objects[o];
        let mesh = &world.meshes[object.mesh].mesh;
        let p = mesh.positions();
        mesh.triangles()
            .iter()
            .map(|t| t.map(|v| object.transform.transform_point3(p[v as usize].as_dvec3())))
            .collect()
    };
    let boxes: Vec<_> = placed
        .iter()
        .map(|&(bounds, t)| crate::scene::world_box(bounds, t))
        .collect();
    let mut crossed = vec![false; placed.len()];
    for (a, b) in crate::scene::crossing_pairs(placed) {
        let tolerance = pair_tolerance(boxes[a], boxes[b]);
        if hides(a)
            || hides(b)
            || !crossings_between(&corners(a), &corners(b), tolerance).is_empty()
        {
            crossed[a] = true;
            crossed[b] = true;
        }
    }
    crossed
}

impl ObjectStyle {
    /// Whether the object's drawn edges are in the traced map (dashed or dotted, cut by
    /// section planes, or crossed by another object), not measured from each pixel's
    /// own triangle.
    pub fn listed_edges(&self) -> bool {
        self.edges && (self.edge_pattern[1] > 0.0 || self.sectioned || self.crossed)
    }

    pub fn of(world: &World, style: &style::Style) -> Vec<ObjectStyle> {
        let placed: Vec<_> = world
            .objects
            .iter()
            .map(|o| (world.meshes[o.mesh].mesh.bounds_f64(), o.transform))
            .collect();
        let crossed = crossed_objects(world, &placed, style);
        world
            .objects
            .iter()
            .zip(crossed)
            .map(|(o, crossed)| ObjectStyle {
                wire: o
                    .style
                    .wire_color
                    .unwrap_or(style.wire_color)
                    .0
                    .map(f64::from),
                fill: {
                    let c = o.style.fill_color.unwrap_or(style.fill_color).0;
                    [0, 1, 2].map(|i| f64::from(c[i]))
                },
                outline: o.style.outline_color_in(style).0.map(f64::from),
                outline_width: f64::from(o.style.outline_width_in(style)),
                width: f64::from(o.style.line_width.unwrap_or(style.line_width)),
                edges: o.style.edges.unwrap_or(true),
                outlines: o.style.outlines.unwrap_or(style.outlines),
                edge_pattern: o.style.edge_pattern_in(style).dash_period().map(f64::from),
                outline_pattern: o
                    .style
                    .outline_pattern_in(style)
                    .dash_period()
                    .map(f64::from),
                sectioned: !world.sections.is_empty(),
                crossed: crossed && o.style.outlines.unwrap_or(style.outlines),
                section_width: f64::from(style.section_width()),
                hidden: o.style.hidden_in(style).filter(|_| {
                    o.style.edges.unwrap_or(true) || o.style.outlines.unwrap_or(style.outlines)
                }),
                normal: DMat3::from_mat4(o.transform).inverse().transpose(),
            })
            .collect()
    }
}

/// `obvhs::bvh2::builder::build_bvh2` with its medium preset, step for step, without the
/// build timer it reads from the system clock, which a browser's wasm32 has not.
fn build_bvh(boxes: &[Aabb]) -> Bvh2 {
    use obvhs::bvh2::{leaf_collapser::collapse, reinsertion::ReinsertionOptimizer};
    let config = obvhs::BvhBuildParams::medium_build();
    let mut bvh = obvhs::ploc::PlocBuilder::with_capacity(boxes.len()).build(
        config.ploc_search_distance,
        boxes,
        (0..boxes.len() as u32).collect::<Vec<_>>(),
        config.sort_precision,
        config.search_depth_threshold,
    );
    let mut reinsertion = ReinsertionOptimizer::default();
    reinsertion.run(&mut bvh, config.reinsertion_batch_ratio, None);
    collapse(
        &mut bvh,
        config.max_prims_per_leaf.clamp(1, 255),
        config.collapse_traversal_cost,
    );
    reinsertion.run(
        &mut bvh,
        config.reinsertion_batch_ratio * config.post_collapse_reinsertion_batch_ratio_multiplier,
        None,
    );
    bvh
}

/// Geometry the host draws itself, not wireframed, as its depth buffer shows it to the pass:
/// per pixel, the farthest of the host's samples (none where any sample misses), as the
/// depth format stores it, then moved back by [`host_margin`](edge_math::host_margin).
pub struct HostOccluders<'a> {
    /// The host's own meshes, placed.
    pub world: &'a World,
    /// The sample positions within a pixel, (0, 0) its top left corner.
    pub samples: Vec<DVec2>,
    /// The host's depth format.
    pub format: wgpu::TextureFormat,
    /// The matrices and depth convention the host rendered with, where they are not the
    /// shot's.
    pub view: Option<View>,
}

impl<'a> HostOccluders<'a> {
    /// One sample per pixel, at its centre, in a `Depth32Float` buffer, through the shot's
    /// own view.
    pub fn single(world: &'a World) -> Self {
        HostOccluders {
            world,
            samples: vec![DVec2::splat(0.5)],
            format: wgpu::TextureFormat::Depth32Float,
            view: None,
        }
    }

    /// The standard 4× multisample pattern of Vulkan, D3D and Metal.
    pub fn msaa4(world: &'a World) -> Self {
        HostOccluders {
            samples: [
                (0.375, 0.125),
                (0.875, 0.375),
                (0.125, 0.625),
                (0.625, 0.875),
            ]
            .map(|(x, y)| DVec2::new(x, y))
            .to_vec(),
            ..Self::single(world)
        }
    }

    /// The same samples in a depth buffer of `format`.
    pub fn with_format(self, format: wgpu::TextureFormat) -> Self {
        HostOccluders { format, ..self }
    }

    /// The same samples rendered through `view` (its matrices and depth convention).
    pub fn with_view(self, view: View) -> Self {
        HostOccluders {
            view: Some(view),
            ..self
        }
    }

    /// A depth value of the host's convention as `format` stores it.
    fn stored(&self, d: f64) -> f64 {
        use wgpu::TextureFormat as F;
        let unorm = |bits: i32| {
            let steps = 2f64.powi(bits) - 1.0;
            (d.clamp(0.0, 1.0) * steps).round() / steps
        };
        match self.format {
            F::Depth16Unorm => unorm(16),
            F::Depth24Plus | F::Depth24PlusStencil8 => unorm(24),
            _ => f64::from(d as f32),
        }
    }

    /// Per pixel of `shot`, the host's reverse depth (moved back by the margin) and its seed
    /// depth, which decides whether the pixel shows the host: that depth moved back further
    /// by the spread of the pixel's samples (the same for one sample); −1 where the host has
    /// no geometry. Mirrors host_depth.wgsl: the farthest and nearest samples of the host's
    /// convention, mapped to the shot's reverse depth (through the pixel's centre where the
    /// host's matrices differ from the shot's).
    pub(crate) fn depth_map(&self, shot: &Shot<'_>) -> Result<Vec<(f64, f64)>> {
        let caster = RayCaster::new(self.world);
        let rays = Rays::new(&shot.view, shot.size, self.world)?;
        let host = self.view.unwrap_or(shot.view);
        host.validate()?;
        let same = host.view == shot.view.view && host.projection == shot.view.projection;
        let reversed = host.depth == DepthRange::Reversed;
        let host_clip = host.projection * host.view;
        let unproject = host_clip.inverse();
        let scene = shot.view.clip_rows(DMat4::IDENTITY);
        let quantum = crate::gpu::depth_quantum(self.format, host.depth);
        let size = DVec2::new(f64::from(shot.size.0), f64::from(shot.size.1));
        let (width, height) = shot.size;
        Ok((0..height)
            .into_par_iter()
            .flat_map_iter(|y| {
                let (caster, rays) = (&caster, &rays);
                (0..width).map(move |x| {
                    let corner = DVec2::new(f64::from(x), f64::from(y));
                    let mut range: Option<(f64, f64)> = None;
                    for &s in &self.samples {
                        let (from, to) = rays.segment(corner + s);
                        let Some(hit) = caster.cast(from, to) else {
                            return (-1.0, -1.0);
                        };
                        let c = host_clip * hit.point.extend(1.0);
                        let d = self.stored(c.z / c.w);
                        range = Some(match range {
                            None => (d, d),
                            Some((far, near)) if reversed => (far.min(d), near.max(d)),
                            Some((far, near)) => (far.max(d), near.min(d)),
                        });
                    }
                    let Some((far, near)) = range else {
                        return (-1.0, -1.0);
                    };
                    let pixel = corner + 0.5;
                    let to_reverse = |d: f64| {
                        if same {
                            if reversed {
                                d
                            } else {
                                1.0 - d
                            }
                        } else {
                            let ndc = DVec2::new(
                                pixel.x / size.x * 2.0 - 1.0,
                                1.0 - pixel.y / size.y * 2.0,
                            );
                            let p = unproject * DVec4::new(ndc.x, ndc.y, d, 1.0);
                            scene.depth.dot(p) / scene.clip.row(3).dot(p)
                        }
                    };
                    let reverse = to_reverse(far);
                    let line = (reverse - edge_math::host_margin(reverse, quantum)).clamp(0.0, 1.0);
                    let spread = (to_reverse(near) - reverse).max(0.0);
                    (line, (line - spread).max(0.0))
                })
            })
            .collect())
    }
}

/// The host's depth as the outline rules read it: per pixel its reverse depth (−1 where it
/// has no geometry) and whether the pixel shows the host (its seeded depth nearer than every
/// object's surface at the centre, as [`Truth::sample`] decides).
pub(crate) struct HostMap {
    depth: Vec<f64>,
    shows_host: Vec<bool>,
    width: usize,
    height: usize,
}

impl HostMap {
    /// `seed` is the seed depth of [`HostOccluders::depth_map`].
    pub(crate) fn new(
        caster: &RayCaster<'_>,
        rays: &Rays,
        depth: Vec<f64>,
        seed: &[f64],
    ) -> HostMap {
        let width = rays.size().x as usize;
        let shows_host = seed
            .par_iter()
            .enumerate()
            .map(|(k, &h)| {
                if h < 0.0 {
                    return false;
                }
                let pixel = DVec2::new((k % width) as f64 + 0.5, (k / width) as f64 + 0.5);
                let (from, to) = rays.segment(pixel);
                !caster.cast(from, to).is_some_and(|hit| {
                    let c = rays.clip(hit.point);
                    1.0 - c.z / c.w >= h
                })
            })
            .collect();
        HostMap {
            height: depth.len() / width.max(1),
            depth,
            shows_host,
            width,
        }
    }

    /// The host's depth at pixel `(x, y)`, the image's edge pixels standing in for those
    /// past it (as the GPU's clamped loads have it).
    fn at(&self, x: i64, y: i64) -> f64 {
        let x = x.clamp(0, self.width as i64 - 1) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        self.depth[y * self.width + x]
    }

    /// Twin of `host_pixel` in scene.wgsl: the host's depth and slope at a pixel.
    fn pixel(&self, x: i64, y: i64) -> (f64, f64) {
        let h = self.at(x, y);
        let n = [
            self.at(x - 1, y),
            self.at(x + 1, y),
            self.at(x, y - 1),
            self.at(x, y + 1),
        ];
        (h, edge_math::host_slope(h, n))
    }

    /// Twin of `host_shown` in scene.wgsl: [`pixel`](Self::pixel) where the pixel shows the
    /// host; `None` where an object shows (the host hides nothing drawn there, not even its
    /// own copy of that object) or the host has nothing.
    fn shown(&self, x: i64, y: i64) -> Option<(f64, f64)> {
        let k = y.clamp(0, self.height as i64 - 1) as usize * self.width
            + x.clamp(0, self.width as i64 - 1) as usize;
        self.shows_host[k].then(|| self.pixel(x, y))
    }

    /// Twin of `host_hides_point` in scene.wgsl: whether the host hides an edge's point at
    /// screen point `x`, of reverse depth `point`.
    pub fn hides_point(&self, x: DVec2, point: f64) -> bool {
        let (px, py) = (x.x.floor(), x.y.floor());
        px >= 0.0 && py >= 0.0 && self.hides_line((px as usize, py as usize), point, 0.0)
    }

    /// Twin of `host_hides_line` in scene.wgsl: whether the host hides, in pixel `(x, y)`,
    /// the line of a point of reverse depth `point` that lies `distance` pixels from its
    /// centre.
    pub fn hides_line(&self, (x, y): (usize, usize), point: f64, distance: f64) -> bool {
        self.shown(x as i64, y as i64)
            .is_some_and(|(h, slope)| edge_math::host_hides(h, point, distance, slope))
    }
}

/// A line at a pixel: its rank, distance, intensity and whose it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// `style::line_key` of the line.
    pub key: u32,
    /// Distance from the pixel centre, pixels.
    pub distance: f64,
    /// Profile × depth fade, before the wire alpha.
    pub intensity: f64,
    /// The object it belongs to.
    pub object: u32,
    /// Whether it is an outline (drawn in the object's outline colour), not an edge.
    pub outline: bool,
    /// Whether it is a section's cut line (drawn in the section line colour).
    pub cut: bool,
    /// Whether it is an intersection line (drawn in the intersection line colour).
    pub intersection: bool,
}
