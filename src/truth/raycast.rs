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

use super::rays::{HostMap, HostOccluders, Line, ObjectStyle, RayCaster, Rays};
use crate::edge_math;
use crate::error::{Error, Result};
use crate::gpu::light_world_dir;
use crate::mesh::{patches::Patches, ALL_EDGES};
use crate::style::{self, Color};
use crate::world::{LineClass, Rendering, Shot, BACKGROUND, HOST};
use glam::{DVec2, DVec3, DVec4};
use rayon::prelude::*;

/// Everything the ground truth knows about one pixel.
#[derive(Clone, Copy, Debug)]
struct Sample {
    id: u32,
    depth: f32,
    distance: f32,
    hidden: Option<Line>,
    rgba: [u8; 4],
    class: LineClass,
}

/// The class of the line that colours a pixel most: the visible one (of class `visible`) at
/// intensity `i`, or the hidden one at `h` where it is stronger (twin of `store_pixel`'s
/// diagnostic in edge_pass.wgsl).
fn line_class(visible: LineClass, i: f64, h: f64) -> LineClass {
    if h > i {
        LineClass::Hidden
    } else if i > 0.0 {
        visible
    } else {
        LineClass::None
    }
}

/// The class of a line of the traced map.
fn class_of(l: &Line) -> LineClass {
    if l.outline {
        LineClass::Outline
    } else if l.cut {
        LineClass::Cut
    } else if l.intersection {
        LineClass::Intersection
    } else {
        LineClass::Edge
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
    shot.validate()?;
    let world = shot.world;
    let caster = RayCaster::new(world);
    let rays = Rays::new(&shot.view, shot.size, world)?;
    let masks: Vec<Vec<u8>> = world
        .meshes
        .iter()
        .map(|m| m.mesh.edge_mask(m.edges))
        .collect();
    let styles = ObjectStyle::of(world, shot.style);
    let shading = Shading::new(shot);
    // The host's depth for the line rules, and the depth that decides which pixels show it.
    let (host_map, host) = match host {
        Some(h) => {
            let (depth, seed): (Vec<f64>, Vec<f64>) = h.depth_map(shot)?.into_iter().unzip();
            (Some(HostMap::new(&caster, &rays, depth, &seed)), Some(seed))
        }
        None => (None, None),
    };
    let patches: Vec<Patches> = world
        .meshes
        .iter()
        .zip(&masks)
        .map(|(m, mask)| Patches::new(m.mesh.edge_neighbours(), mask, m.mesh.crossed_triangles()))
        .collect();
    let eyes: Vec<DVec4> = world
        .objects
        .iter()
        .map(|o| edge_math::local_eye(o.transform, shot.view.eye()))
        .collect();
    let outline = crate::truth::traced::traced_map(
        &caster,
        &rays,
        shot,
        &styles,
        (&patches, &masks),
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
                    gt.sample(pixel, (outline.line[k], outline.hidden[k]), host)
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
        hidden_distance: Vec::with_capacity(n),
        line_class: Vec::with_capacity(n),
    };
    for s in rows.iter().flatten() {
        frame.rgba.extend_from_slice(&s.rgba);
        frame.ids.push(s.id);
        frame.depth.push(s.depth);
        frame.edge_distance.push(s.distance);
        frame
            .hidden_distance
            .push(s.hidden.map_or(f32::INFINITY, |l| l.distance as f32));
        frame.line_class.push(s.class as u8);
    }
    Ok(frame)
}

/// A progress bar on stderr when it is a terminal and the job is more than a moment.
#[cfg(not(target_arch = "wasm32"))]
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

/// A browser has no terminal (and no clock `indicatif` could read): no progress bar.
#[cfg(target_arch = "wasm32")]
fn progress_bar(_rows: u64, _pixels: u64) -> NoProgress {
    NoProgress
}

#[cfg(target_arch = "wasm32")]
struct NoProgress;

#[cfg(target_arch = "wasm32")]
impl NoProgress {
    fn inc(&self, _: u64) {}
    fn finish_and_clear(&self) {}
}

/// The frame's shading inputs in f64, as the GPU's `Frame` uniforms carry them.
struct Shading {
    eye: DVec4,
    fade_row: DVec4,
    light: DVec3,
    background: Color,
    ambient: f64,
    fade: [f64; 2],
    fill_opacity: f64,
    /// The colour of back faces seen through a section's cut (linear RGB), and of the cut
    /// lines (linear RGBA).
    section_color: [f64; 3],
    section_line: [f64; 4],
    intersection_line: [f64; 4],
}

impl Shading {
    fn new(shot: &Shot<'_>) -> Self {
        let s = shot.style;
        Self {
            eye: shot.view.eye(),
            fade_row: shot.view.view_depth_row(),
            light: light_world_dir(&shot.view, s),
            background: s.background,
            ambient: f64::from(s.ambient),
            fade: s.fade_range().map(f64::from),
            fill_opacity: f64::from(s.fill_opacity),
            section_color: [0, 1, 2].map(|k| f64::from(s.section_color.0[k])),
            section_line: s.section_line_color.0.map(f64::from),
            intersection_line: s.intersection_line_color.0.map(f64::from),
        }
    }
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
    /// The colour of a line of the traced map: its object's outline or line colour.
    fn line_color(&self, l: &Line) -> [f64; 4] {
        let st = &self.styles[l.object as usize];
        if l.outline {
            st.outline
        } else if l.cut {
            self.shading.section_line
        } else if l.intersection {
            self.shading.intersection_line
        } else {
            st.wire
        }
    }

    /// The ground truth at one pixel centre; `outline` and `hidden` are the pixel's lines from
    /// the traced map, `host` the host's reverse depth there (−1 for none).
    fn sample(
        &self,
        pixel: DVec2,
        (outline, hidden): (Option<Line>, Option<Line>),
        host: f64,
    ) -> Sample {
        let sh = self.shading;
        // The hidden line goes over what is below, under the visible line (twin of
        // `store_pixel` in edge_pass.wgsl).
        let hidden_color = |l: &Line| self.styles[l.object as usize].hidden.map(|h| h.color.0);
        let (h, hidden_rgb) = match hidden.and_then(|l| Some((l, hidden_color(&l)?))) {
            Some((l, c)) => {
                let c = c.map(f64::from);
                (l.intensity * c[3], [c[0], c[1], c[2]])
            }
            None => (0.0, [0.0; 3]),
        };
        let under = |base: [f64; 3]| [0, 1, 2].map(|k| base[k] + (hidden_rgb[k] - base[k]) * h);
        let world = self.caster.world();
        let (from, to) = self.rays.segment(pixel);
        let hit = self.caster.cast(from, to).filter(|h| {
            let c = self.rays.clip(h.point);
            1.0 - c.z / c.w >= host
        });
        let Some(hit) = hit else {
            let bg4 = sh.background.0.map(f64::from);
            let bg = under([bg4[0], bg4[1], bg4[2]]);
            let (i, wire) = outline.map_or((0.0, [0.0; 4]), |l| {
                let w = self.line_color(&l);
                (l.intensity * w[3], w)
            });
            let visible = outline.as_ref().map_or(LineClass::None, class_of);
            let mix = |k: usize| (bg[k] + (wire[k] - bg[k]) * i) as f32;
            return Sample {
                id: if host >= 0.0 { HOST } else { BACKGROUND },
                depth: if host >= 0.0 {
                    (1.0 - host) as f32
                } else {
                    1.0
                },
                distance: outline.map_or(f64::INFINITY, |l| l.distance) as f32,
                hidden,
                rgba: Color([mix(0), mix(1), mix(2), bg4[3].max(h).max(i) as f32]).to_srgb8(),
                class: line_class(visible, i, h),
            };
        };
        let object = &world.objects[hit.object as usize];
        let st = &self.styles[hit.object as usize];
        let wm = &world.meshes[object.mesh];
        let tri = wm.mesh.triangles()[hit.tri as usize];
        let corners = self.caster.corners(hit.id);
        let clip: [DVec4; 3] = corners.map(|p| self.rays.clip(p));
        // Patterned edges and those of patches that cross another surface are in the outline
        // map, drawn where they are visible.
        let own_edges =
            st.edges && !st.listed_edges() && !self.patches[object.mesh].crossed[hit.tri as usize];
        let mask = if own_edges {
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
        if own_edges && undrawn < style::line_reach(st.width).min(own) {
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
        // The surface over the background at the fill opacity (twin of `see_through`).
        let (surface, alpha) = {
            // A back face seen through a section's cut is the section face (twin of
            // `surface_pixel`).
            let back = self.caster.faces_away(hit.id, point, sh.eye);
            let s = if st.sectioned && back {
                sh.section_color
            } else {
                surface_color(sh, st, &wm.mesh, tri, e.bary, point)
            };
            let k = sh.fill_opacity;
            if k < 1.0 {
                let bg = sh.background.0.map(f64::from);
                let a = k + bg[3] * (1.0 - k);
                let c = [0, 1, 2].map(|j| (s[j] * k + bg[j] * bg[3] * (1.0 - k)) / a.max(1e-30));
                (under(c), a.max(h))
            } else {
                (under(s), 1.0)
            }
        };
        let (line, distance, wire, visible) = match outline {
            Some(l) if l.key > own_key => {
                (l.intensity, l.distance, self.line_color(&l), class_of(&l))
            }
            _ => (own_line, own, st.wire, LineClass::Edge),
        };
        let i = line * wire[3];
        let mix = |k: usize| (surface[k] + (wire[k] - surface[k]) * i) as f32;
        Sample {
            id: hit.id,
            depth: depth as f32,
            distance: distance as f32,
            hidden,
            rgba: Color([mix(0), mix(1), mix(2), alpha.max(i) as f32]).to_srgb8(),
            class: line_class(visible, i, h),
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
        return style::shade(st.fill, sh.light, 1.0, sh.light, sh.ambient);
    }
    let normal = (st.normal * n).normalize_or_zero();
    let facing = normal.dot(edge_math::towards_eye(point, sh.eye));
    style::shade(st.fill, normal, facing, sh.light, sh.ambient)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::View;
    use crate::mesh::EdgeSelection;
    use crate::world::World;
    use crate::{Camera, Mesh, Style};
    use glam::DMat4;
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
