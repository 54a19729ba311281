//! The CPU ground truth: one ray per pixel centre through an `obvhs` BVH over every object's
//! triangles (transformed to world space in f64), with the hit and the edge distance
//! computed in f64 by the same definitions the GPU uses (`edge_math`, `style`).
//!
//! The ray of pixel `(x, y)` is the segment from the near plane to the far plane through
//! NDC `u = (x + 0.5)/W·2 − 1`, `v = 1 − (y + 0.5)/H·2`, unprojected with the f64 inverse of
//! the view's clip rows ([`View::clip_rows`](crate::View::clip_rows)): exactly the part of
//! the line that rasterization keeps, so nothing in front of the near plane or beyond the
//! far plane is hit. Perspective rays meet at the eye, orthographic ones are parallel; with
//! an infinite far plane the segment runs past everything there is.
//!
//! The BVH only culls: it is built in f32 over triangle boxes padded by a margin far larger
//! than any f32 rounding of the ray, so it never drops a triangle the ray meets. Every
//! candidate is then tested in f64 with a watertight edge test (each edge's sign is the triple
//! product of its endpoints relative to the ray origin and the ray direction, so the two
//! triangles sharing an edge compute exactly opposite values and a ray cannot slip between
//! them). A pixel centre exactly on a shared edge may pick either triangle; exact depth ties
//! pick the lower global id.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::camera::{ClipRows, DepthRange, View};
use crate::edge_math;
use crate::error::{Error, Result};
use crate::gpu::light_world_dir;
use crate::mesh::{patches::Patches, ALL_EDGES};
use crate::style::{self, Color};
use crate::world::{Rendering, Shot, World, BACKGROUND, HOST};
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
        let bvh = obvhs::bvh2::builder::build_bvh2(
            &boxes,
            obvhs::BvhBuildParams::medium_build(),
            &mut std::time::Duration::default(),
        );
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

/// Everything the ground truth knows about one pixel.
#[derive(Clone, Copy, Debug)]
struct Sample {
    id: u32,
    depth: f32,
    distance: f32,
    rgba: [u8; 4],
}

/// Each object's look, as the GPU's instance records carry it.
pub(crate) struct ObjectStyle {
    pub wire: [f64; 4],
    pub width: f64,
    pub edges: bool,
    pub outlines: bool,
    /// Model → world normal matrix.
    pub normal: DMat3,
}

impl ObjectStyle {
    pub fn of(world: &World, style: &style::Style) -> Vec<ObjectStyle> {
        world
            .objects
            .iter()
            .map(|o| ObjectStyle {
                wire: o
                    .style
                    .wire_color
                    .unwrap_or(style.wire_color)
                    .0
                    .map(f64::from),
                width: f64::from(o.style.line_width.unwrap_or(style.line_width)),
                edges: o.style.edges.unwrap_or(true),
                outlines: o.style.outlines.unwrap_or(style.silhouettes),
                normal: DMat3::from_mat4(o.transform).inverse().transpose(),
            })
            .collect()
    }
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

    /// Per pixel of `shot`, the host's reverse depth (moved back by the margin), or −1 where
    /// the host has no geometry. Mirrors host_depth.wgsl: the farthest sample of the host's
    /// convention, mapped to the shot's reverse depth (through the pixel's centre where the
    /// host's matrices differ from the shot's).
    fn depth_map(&self, shot: &Shot<'_>) -> Result<Vec<f64>> {
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
                    let mut farthest: Option<f64> = None;
                    for &s in &self.samples {
                        let (from, to) = rays.segment(corner + s);
                        let Some(hit) = caster.cast(from, to) else {
                            return -1.0;
                        };
                        let c = host_clip * hit.point.extend(1.0);
                        let d = self.stored(c.z / c.w);
                        farthest = Some(match farthest {
                            None => d,
                            Some(f) if reversed => f.min(d),
                            Some(f) => f.max(d),
                        });
                    }
                    let Some(d) = farthest else { return -1.0 };
                    let reverse = if same {
                        if reversed {
                            d
                        } else {
                            1.0 - d
                        }
                    } else {
                        let pixel = corner + 0.5;
                        let ndc =
                            DVec2::new(pixel.x / size.x * 2.0 - 1.0, 1.0 - pixel.y / size.y * 2.0);
                        let p = unproject * DVec4::new(ndc.x, ndc.y, d, 1.0);
                        scene.depth.dot(p) / scene.clip.row(3).dot(p)
                    };
                    (reverse - edge_math::host_margin(reverse, quantum)).clamp(0.0, 1.0)
                })
            })
            .collect())
    }
}

/// The host's depth as the outline rules read it: per pixel its reverse depth (−1 where it
/// has no geometry) and whether the pixel shows the host (its surface at the centre nearer
/// than every object's, as [`Truth::sample`] decides).
pub(crate) struct HostMap {
    depth: Vec<f64>,
    shows_host: Vec<bool>,
    width: usize,
    height: usize,
}

impl HostMap {
    fn new(caster: &RayCaster<'_>, rays: &Rays, depth: Vec<f64>) -> HostMap {
        let width = rays.size().x as usize;
        let shows_host = depth
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

/// Renders `shot` by ray casting on the CPU in f64: the reference every GPU method is
/// measured against. Fills every map of the [`Rendering`].
pub fn draw_raycast(shot: &Shot<'_>) -> Result<Rendering> {
    draw_raycast_over(shot, None)
}

/// [`draw_raycast`] over the host's own geometry: where the host is nearer, a pixel shows
/// [`HOST`] and its lines are hidden; an outline point is hidden where the pixel containing
/// it shows the host and the host's depth there is nearer, and no outline is drawn into a
/// pixel that shows the host where the host is nearer than the outline's point.
pub fn draw_raycast_over(shot: &Shot<'_>, host: Option<&HostOccluders<'_>>) -> Result<Rendering> {
    let (width, height) = shot.size;
    if width == 0 || height == 0 {
        return Err(Error::InvalidSetting(format!(
            "image size {width}x{height} has a zero side"
        )));
    }
    shot.view.validate()?;
    shot.style.validate()?;
    let world = shot.world;
    world.validate()?;
    for (i, o) in world.objects.iter().enumerate() {
        crate::scene::check_transform(&o.transform, i)?;
        o.style.validate(i)?;
    }
    let caster = RayCaster::new(world);
    let rays = Rays::new(&shot.view, shot.size, world)?;
    let masks: Vec<Vec<u8>> = world
        .meshes
        .iter()
        .map(|m| m.mesh.edge_mask(m.edges))
        .collect();
    let styles = ObjectStyle::of(world, shot.style);
    let shading = Shading::new(shot);
    let host = match host {
        Some(h) => Some(h.depth_map(shot)?),
        None => None,
    };
    let host_map = host.clone().map(|h| HostMap::new(&caster, &rays, h));
    let patches: Vec<Patches> = world
        .meshes
        .iter()
        .zip(&masks)
        .map(|(m, mask)| Patches::new(m.mesh.edge_neighbours(), mask))
        .collect();
    let eyes: Vec<DVec4> = world
        .objects
        .iter()
        .map(|o| edge_math::local_eye(o.transform, shot.view.eye()))
        .collect();
    let outline = crate::truth::outline::outline_map(
        &caster,
        &rays,
        shot,
        &styles,
        &patches,
        host_map.as_ref(),
    );

    let pixels = u64::from(width) * u64::from(height);
    let bar = progress_bar(u64::from(height), pixels);
    let gt = Truth {
        caster: &caster,
        rays: &rays,
        masks: &masks,
        patches: &patches,
        eyes: &eyes,
        styles: &styles,
        shading: &shading,
    };
    let rows: Vec<Vec<Sample>> = (0..height)
        .into_par_iter()
        .map(|y| {
            let row = (0..width)
                .map(|x| {
                    let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                    let k = (y * width + x) as usize;
                    let host = host.as_ref().map_or(-1.0, |h| h[k]);
                    gt.sample(pixel, outline.line[k], host)
                })
                .collect();
            bar.inc(1);
            row
        })
        .collect();
    bar.finish_and_clear();

    let n = pixels as usize;
    let mut frame = Rendering {
        size: shot.size,
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
    eye: DVec4,
    fade_row: DVec4,
    light: DVec3,
    fill: [f64; 3],
    background: Color,
    ambient: f64,
    fade: [f64; 2],
}

impl Shading {
    fn new(shot: &Shot<'_>) -> Self {
        let s = shot.style;
        let rgb = |c: Color| [0, 1, 2].map(|i| f64::from(c.0[i]));
        Self {
            eye: shot.view.eye(),
            fade_row: shot.view.view_depth_row(),
            light: light_world_dir(&shot.view, s),
            fill: rgb(s.fill_color),
            background: s.background,
            ambient: f64::from(s.ambient),
            fade: s.fade_range().map(f64::from),
        }
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
}

/// The ground truth's inputs for sampling pixels.
struct Truth<'a> {
    caster: &'a RayCaster<'a>,
    rays: &'a Rays,
    masks: &'a [Vec<u8>],
    patches: &'a [Patches],
    /// Each object's eye in its mesh's coordinates.
    eyes: &'a [DVec4],
    styles: &'a [ObjectStyle],
    shading: &'a Shading,
}

impl Truth<'_> {
    /// The ground truth at one pixel centre; `outline` is the pixel's line from the outline
    /// map, `host` the host's reverse depth there (−1 for none).
    fn sample(&self, pixel: DVec2, outline: Option<Line>, host: f64) -> Sample {
        let sh = self.shading;
        let world = self.caster.world();
        let (from, to) = self.rays.segment(pixel);
        let hit = self.caster.cast(from, to).filter(|h| {
            let c = self.rays.clip(h.point);
            1.0 - c.z / c.w >= host
        });
        let Some(hit) = hit else {
            let bg = sh.background.0.map(f64::from);
            let (i, wire) = outline.map_or((0.0, [0.0; 4]), |l| {
                let w = self.styles[l.object as usize].wire;
                (l.intensity * w[3], w)
            });
            let mix = |k: usize| (bg[k] + (wire[k] - bg[k]) * i) as f32;
            return Sample {
                id: if host >= 0.0 { HOST } else { BACKGROUND },
                depth: if host >= 0.0 {
                    (1.0 - host) as f32
                } else {
                    1.0
                },
                distance: outline.map_or(f64::INFINITY, |l| l.distance) as f32,
                rgba: Color([mix(0), mix(1), mix(2), bg[3].max(i) as f32]).to_srgb8(),
            };
        };
        let object = &world.objects[hit.object as usize];
        let st = &self.styles[hit.object as usize];
        let wm = &world.meshes[object.mesh];
        let tri = wm.mesh.triangles()[hit.tri as usize];
        let corners = self.caster.corners(hit.id);
        let clip: [DVec4; 3] = corners.map(|p| self.rays.clip(p));
        let mask = if st.edges {
            self.masks[object.mesh][hit.tri as usize]
        } else {
            0
        };
        let size = self.rays.size();
        let e = edge_math::edge_eval(clip, mask, pixel, size);
        let mut own = e.min_distance();
        // Twin of `own_lines` (edge_pass.wgsl): where an undrawn edge of the triangle is
        // nearer than the line's reach and the drawn edges, the nearest line may lie beyond
        // it: in a small patch, the search finds it; a large patch's lines are in the outline
        // map.
        let undrawn = edge_math::edge_eval(clip, !mask & ALL_EDGES, pixel, size).min_distance();
        if st.edges && undrawn < style::line_reach(st.width).min(own) {
            own = if self.patches[object.mesh].large[hit.tri as usize] {
                edge_math::NO_EDGE
            } else {
                let first = self.caster.first_ids()[hit.object as usize];
                let mesh = &wm.mesh;
                let triangle = |t: u32| {
                    let local = mesh.triangles()[t as usize]
                        .map(|v| mesh.positions()[v as usize].as_dvec3());
                    edge_math::PatchTriangle {
                        local,
                        clip: self.caster.corners(first + t).map(|p| self.rays.clip(p)),
                        mask: self.masks[object.mesh][t as usize],
                        neighbours: mesh.edge_neighbours()[t as usize],
                    }
                };
                let eye = self.eyes[hit.object as usize];
                edge_math::patch_distance(hit.tri, eye, pixel, size, triangle)
            };
        }
        let c = self.rays.clip(hit.point);
        let depth = (c.z / c.w).clamp(0.0, 1.0);

        // Twin of `finish` in edge_pass.wgsl, in f64.
        let [b0, b1, b2] = e.bary;
        let point = corners[0] * b0 + corners[1] * b1 + corners[2] * b2;
        let view_depth = sh.fade_row.dot(point.extend(1.0));
        let own_line =
            style::line_intensity(own, st.width) * style::depth_fade(view_depth, sh.fade);
        let own_key = if own.is_finite() {
            style::line_key(own_line, own)
        } else {
            0
        };
        let surface = surface_color(sh, st, &wm.mesh, tri, e.bary, point);
        let (line, distance, wire) = match outline {
            Some(l) if l.key > own_key => {
                (l.intensity, l.distance, self.styles[l.object as usize].wire)
            }
            _ => (own_line, own, st.wire),
        };
        let i = line * wire[3];
        let mix = |k: usize| (surface[k] + (wire[k] - surface[k]) * i) as f32;
        Sample {
            id: hit.id,
            depth: depth as f32,
            distance: distance as f32,
            rgba: Color([mix(0), mix(1), mix(2), 1.0]).to_srgb8(),
        }
    }
}

/// Twin of `surface_color` in common.wgsl: the interpolated normal, the face normal where it
/// vanishes, taken to world axes; lit as if facing the light where neither exists.
fn surface_color(
    sh: &Shading,
    st: &ObjectStyle,
    mesh: &crate::Mesh,
    tri: [u32; 3],
    bary: [f64; 3],
    point: DVec3,
) -> [f64; 3] {
    let normals = tri.map(|v| mesh.normals()[v as usize].as_dvec3());
    let [b0, b1, b2] = bary;
    let mut n = normals[0] * b0 + normals[1] * b1 + normals[2] * b2;
    if !(n.dot(n) > 1e-12) {
        let p = tri.map(|v| mesh.positions()[v as usize].as_dvec3());
        n = (p[1] - p[0]).cross(p[2] - p[0]);
    }
    if !(n.dot(n) > 0.0) {
        return style::shade(sh.fill, sh.light, 1.0, sh.light, sh.ambient);
    }
    let normal = (st.normal * n).normalize_or_zero();
    let facing = normal.dot(edge_math::towards_eye(point, sh.eye));
    style::shade(sh.fill, normal, facing, sh.light, sh.ambient)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::EdgeSelection;
    use crate::{Camera, Mesh, Style};
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
        let world = World::single(mesh, EdgeSelection::All);
        let caster = RayCaster::new(&world);
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
        let world = World::single(quad(), EdgeSelection::All);
        let caster = RayCaster::new(&world);
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
    fn instances_are_cast_in_world_space() {
        // Two copies of the quad: one moved back and mirrored; rays see the nearer first,
        // and the farther one's ids follow the first's.
        let mut world = World::single(quad(), EdgeSelection::All);
        world.objects.push(crate::world::Object {
            mesh: 0,
            transform: DMat4::from_translation(DVec3::new(0.5, 0.0, -2.0))
                * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
            style: Default::default(),
        });
        let caster = RayCaster::new(&world);
        let down = |x: f64| caster.cast(DVec3::new(x, 0.1, 5.0), DVec3::new(x, 0.1, -5.0));
        assert!(down(0.0).unwrap().id < 2);
        let far = down(1.3).unwrap();
        assert!(far.id >= 2 && far.object == 1 && (far.point.z + 2.0).abs() < 1e-12);
        assert!(down(1.6).is_none());
    }

    #[test]
    fn renders_a_quad_like_the_definition_says() {
        let world = World::single(quad(), EdgeSelection::All);
        let camera = Camera {
            eye: Vec3::new(0.0, 0.0, 3.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 60.0,
            near: 0.5,
            far: 10.0,
        };
        let style = Style::default();
        let shot = Shot {
            world: &world,
            view: camera.to_view(64.0 / 48.0),
            style: &style,
            size: (64, 48),
        };
        let frame = draw_raycast(&shot).unwrap();
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

    #[test]
    fn orthographic_and_infinite_rays_see_the_same_quad() {
        let world = World::single(quad(), EdgeSelection::All);
        let style = Style::default();
        let eye = DVec3::new(0.0, 0.0, 3.0);
        let views = [
            View::orthographic((eye, DVec3::ZERO, DVec3::Y), 3.0, 1.0, (0.5, 10.0)),
            Camera {
                eye: eye.as_vec3(),
                target: Vec3::ZERO,
                up: Vec3::Y,
                fov_y_deg: 60.0,
                near: 0.5,
                far: f32::INFINITY,
            }
            .to_view(1.0),
        ];
        for view in views {
            let shot = Shot {
                world: &world,
                view,
                style: &style,
                size: (32, 32),
            };
            let frame = draw_raycast(&shot).unwrap();
            // The quad fills the middle of the image.
            assert!(frame.ids[16 * 32 + 16] < 2, "{view:?}");
            assert_eq!(frame.ids[0], BACKGROUND);
        }
    }
}
