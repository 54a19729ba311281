//! Which parts of a line the world's surfaces hide, found exactly rather than sampled.
//!
//! A point P of a line is hidden where a triangle lies between it and the eye by more than
//! the pass's margin ([`edge_math::nearer`]): the ray from P towards the eye meets the
//! triangle, cut to its part in front of the near plane, not beyond the far one and on the
//! kept side of every section plane, at a point whose near row is below P's by
//! [`edge_math::HIDDEN_MARGIN`] of |near| + w. Along a segment P(s) = a + s (b − a) each of
//! these conditions is a polynomial inequality in s:
//!
//! * the ray meets the cut triangle's polygon where P's projection lies inside the
//!   polygon's projection (by [`OUTLINE_MARGIN`]): for each of its sides, a 2D orientation
//!   affine in the projected segment's parameter σ, which maps to s perspectively;
//! * the meeting point is nearer by the margin where sign(D)·(N·H + M·D) < 0, with D, N, H
//!   and M affine in s (see [`Frame::hidden_by`]): a quadratic.
//!
//! So each triangle hides one interval of s or two, found in closed form in f64, and a
//! line's hidden parts are their union. Which triangles to ask comes from a grid over the
//! image of the cut triangles' screen boxes. A triangle seen edge-on (within the
//! silhouettes' [`EDGE_ON`](crate::edge_math::EDGE_ON)) hides nothing: no pixel's ray meets it.

// `!(a > b)` is deliberate: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::camera::ClipRows;
use crate::edge_math::{is_edge_on, is_silhouette, towards_eye, HIDDEN_MARGIN};
use crate::mesh::adjacency::NO_NEIGHBOUR;
use crate::mesh::par::*;
use crate::world::{keep_positive, World};
use glam::{DVec2, DVec3, DVec4};

/// The most corners a triangle has once cut by the near and far planes and every section
/// plane.
const MAX_CORNERS: usize = 5 + crate::scene::MAX_SECTIONS;

/// Pixels inside a surface's outline on screen (its boundary and silhouette edges) where it
/// starts to hide: a line lying on another surface's outline (a back edge behind a front
/// one in an axis-aligned view, where the side between them is seen edge-on) is not behind
/// it. Far below what a drawing shows, far above the rounding of a projection.
pub(crate) const OUTLINE_MARGIN: f64 = 1e-6;

/// The most grid cells along a side of the image.
const MAX_CELLS: f64 = 2048.0;

/// The most (cell, triangle) entries the grid holds.
const MAX_ENTRIES: f64 = 64e6;

/// Hidden intervals closer than this (in the segment's parameter) join: two triangles
/// sharing a side hide a line up to it from either side, meeting there only to rounding.
pub(crate) const JOIN: f64 = 1e-9;

/// A convex polygon: a triangle cut by half-spaces.
#[derive(Clone, Copy)]
pub(crate) struct Polygon {
    corners: [DVec3; MAX_CORNERS],
    /// What side k (from corner k to k + 1) lies on: the triangle's edge 0, 1 or 2, or
    /// [`CUT`] for a half-space's plane.
    sides: [u8; MAX_CORNERS],
    len: usize,
}

/// The label of a polygon side that a clip plane made.
const CUT: u8 = 3;

impl Polygon {
    fn corners(&self) -> &[DVec3] {
        &self.corners[..self.len]
    }
}

/// The world of a drawing in world coordinates, seen through one view: what decides where
/// a line is visible.
pub(crate) struct Frame<'a> {
    pub world: &'a World,
    pub rows: ClipRows,
    /// The eye, homogeneous world (a direction towards the viewer for orthographic views).
    pub eye: DVec4,
    /// The image, pixels.
    pub size: DVec2,
    /// Each object's vertices, world coordinates.
    positions: Vec<Vec<DVec3>>,
    firsts: Vec<u32>,
    /// Each object's transform mirrors (its triangles' outside turned).
    mirrored: Vec<bool>,
    /// The half-spaces h · (X, 1) ≥ 0 every surface and line is cut to: in front of the
    /// near plane, before the far plane, then each section plane's kept side.
    keep: Vec<DVec4>,
    grid: Grid,
}

/// The cut triangles' screen boxes, binned in square cells over the image.
struct Grid {
    cell: f64,
    columns: usize,
    rows: usize,
    /// Cell k's triangles are `ids[starts[k]..starts[k + 1]]`, global ids.
    starts: Vec<u32>,
    ids: Vec<u32>,
}

impl<'a> Frame<'a> {
    /// The frame of `world` through `rows` (of the identity model), seen from `eye`, for an
    /// image of `size` pixels.
    pub fn new(world: &'a World, rows: ClipRows, eye: DVec4, size: (u32, u32)) -> Frame<'a> {
        let positions: Vec<Vec<DVec3>> = world
            .objects
            .par_iter()
            .map(|o| {
                let mesh = &world.meshes[o.mesh].mesh;
                mesh.positions()
                    .iter()
                    .map(|p| o.transform.transform_point3(p.as_dvec3()))
                    .collect()
            })
            .collect();
        let mut keep = vec![rows.clip.row(2), rows.depth];
        keep.extend(world.sections.iter().map(|s| s.coefficients()));
        let mut frame = Frame {
            world,
            rows,
            eye,
            size: DVec2::new(f64::from(size.0), f64::from(size.1)),
            positions,
            firsts: world.first_ids(),
            mirrored: world
                .objects
                .iter()
                .map(|o| o.transform.determinant() < 0.0)
                .collect(),
            keep,
            grid: Grid {
                cell: 1.0,
                columns: 0,
                rows: 0,
                starts: vec![0],
                ids: Vec::new(),
            },
        };
        frame.grid = frame.bin();
        frame
    }

    /// The global id of object `o`'s first triangle.
    pub fn first(&self, o: usize) -> u32 {
        self.firsts[o]
    }

    /// Object `o`'s vertices, world coordinates.
    pub fn positions(&self, o: usize) -> &[DVec3] {
        &self.positions[o]
    }

    /// The world corners of global triangle `id`.
    pub fn corners(&self, id: u32) -> [DVec3; 3] {
        let (o, t) = self.world.locate(&self.firsts, id);
        let mesh = &self.world.meshes[self.world.objects[o].mesh].mesh;
        mesh.triangles()[t as usize].map(|v| self.positions[o][v as usize])
    }

    /// The outward normal of global triangle `id` (not unit): its world winding, turned
    /// where its object's transform mirrors.
    pub fn outward(&self, id: u32) -> DVec3 {
        let (o, _) = self.world.locate(&self.firsts, id);
        let c = self.corners(id);
        let n = (c[1] - c[0]).cross(c[2] - c[0]);
        if self.mirrored[o] {
            -n
        } else {
            n
        }
    }

    /// Whether global triangle `id` faces away from the eye.
    pub fn faces_away(&self, id: u32) -> bool {
        let c = self.corners(id);
        self.outward(id).dot(towards_eye(c[0], self.eye)) < 0.0
    }

    /// Pixel coordinates of world point `p` (in front of the near plane).
    pub fn project(&self, p: DVec3) -> DVec2 {
        let c = self.rows.clip * p.extend(1.0);
        let ndc = DVec2::new(c.x, c.y) / c.w;
        DVec2::new(0.5 * (ndc.x + 1.0), 0.5 * (1.0 - ndc.y)) * self.size
    }

    /// The parameters s of the segment a → b (world) in front of the near plane, before
    /// the far one and on the kept side of every section plane but `on_plane` (a cut line
    /// lies on its own plane); `None` where no part is.
    pub fn span(&self, (a, b): (DVec3, DVec3), on_plane: Option<usize>) -> Option<(f64, f64)> {
        let (ha, hb) = (a.extend(1.0), b.extend(1.0));
        let mut s = (0.0, 1.0);
        for (k, h) in self.keep.iter().enumerate() {
            if k >= 2 && Some(k - 2) == on_plane {
                continue;
            }
            keep_positive(&mut s, h.dot(ha), h.dot(hb));
        }
        (s.0 < s.1).then_some(s)
    }

    /// `span` cut to the image.
    pub fn in_image(&self, (a, b): (DVec3, DVec3), span: (f64, f64)) -> Option<(f64, f64)> {
        let (ca, cb) = (
            self.rows.clip * a.extend(1.0),
            self.rows.clip * b.extend(1.0),
        );
        let mut s = span;
        keep_positive(&mut s, ca.w + ca.x, cb.w + cb.x);
        keep_positive(&mut s, ca.w - ca.x, cb.w - cb.x);
        keep_positive(&mut s, ca.w + ca.y, cb.w + cb.y);
        keep_positive(&mut s, ca.w - ca.y, cb.w - cb.y);
        (s.0 < s.1).then_some(s)
    }

    /// The edges of global triangle `id` that are part of its surface's outline from the
    /// eye (bit i for edge i): boundaries and silhouettes.
    fn outline_sides(&self, id: u32) -> u8 {
        let (o, t) = self.world.locate(&self.firsts, id);
        let mesh = &self.world.meshes[self.world.objects[o].mesh].mesh;
        let neighbours = mesh.edge_neighbours()[t as usize];
        let c = self.corners(id);
        let mut bits = 0;
        for i in 0..3 {
            let n = neighbours[i];
            let outline = n == NO_NEIGHBOUR || {
                let d = self.corners(self.firsts[o] + n);
                let centre = (d[0] + d[1] + d[2]) / 3.0;
                is_silhouette(c[i], c[(i + 1) % 3], c[(i + 2) % 3], centre, self.eye)
            };
            if outline {
                bits |= 1 << i;
            }
        }
        bits
    }

    /// Bins every cut triangle's screen box.
    fn bin(&self) -> Grid {
        let total = self.world.triangle_count() as u32;
        let boxes: Vec<Option<[f64; 4]>> = (0..total)
            .into_par_iter()
            .map(|id| {
                // Seen edge-on (within the silhouettes' EDGE_ON), a surface hides nothing:
                // no pixel's ray meets it, and a line lying in its plane is not behind it.
                let c = self.corners(id);
                if is_edge_on(c, self.eye) {
                    return None;
                }
                let polygon = clip(c, &self.keep)?;
                let mut lo = DVec2::INFINITY;
                let mut hi = DVec2::NEG_INFINITY;
                let mut area = 0.0;
                let corners = polygon.corners();
                let mut last = self.project(corners[corners.len() - 1]);
                for &corner in corners {
                    let p = self.project(corner);
                    lo = lo.min(p);
                    hi = hi.max(p);
                    area += last.perp_dot(p);
                    last = p;
                }
                // Edge-on (no area on screen) hides nothing; nor does what misses the image.
                let lo = lo.max(DVec2::ZERO);
                let hi = hi.min(self.size);
                (area != 0.0 && lo.x <= hi.x && lo.y <= hi.y).then_some([lo.x, lo.y, hi.x, hi.y])
            })
            .collect();
        let count = boxes.iter().flatten().count().max(1) as f64;
        // About one triangle's size on screen, were they spread over the image.
        // At most MAX_CELLS a side, whatever the image's size.
        let mut cell = (self.size.x * self.size.y / count)
            .sqrt()
            .clamp(1.0, 64.0)
            .max(self.size.max_element() / MAX_CELLS);
        // Many large triangles over one another (depth complexity) would bin each into many
        // cells: coarser cells keep the grid within MAX_ENTRIES.
        let entries = |cell: f64| -> f64 {
            boxes
                .iter()
                .flatten()
                .map(|b| {
                    let n = |lo: f64, hi: f64| (hi / cell).floor() - (lo / cell).floor() + 1.0;
                    n(b[0], b[2]) * n(b[1], b[3])
                })
                .sum()
        };
        while entries(cell) > MAX_ENTRIES && cell < self.size.max_element() {
            cell *= 2.0;
        }
        let columns = (self.size.x / cell).ceil().max(1.0) as usize;
        let rows = (self.size.y / cell).ceil().max(1.0) as usize;
        let range = |b: &[f64; 4]| {
            let c = |v: f64, n: usize| ((v / cell).floor().max(0.0) as usize).min(n - 1);
            (
                c(b[0], columns),
                c(b[1], rows),
                c(b[2], columns),
                c(b[3], rows),
            )
        };
        let mut starts = vec![0u32; columns * rows + 1];
        for b in boxes.iter().flatten() {
            let (x0, y0, x1, y1) = range(b);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    starts[y * columns + x + 1] += 1;
                }
            }
        }
        for k in 0..columns * rows {
            starts[k + 1] += starts[k];
        }
        let mut fill = starts.clone();
        let mut ids = vec![0u32; starts[columns * rows] as usize];
        for (id, b) in boxes.iter().enumerate() {
            let Some(b) = b else { continue };
            let (x0, y0, x1, y1) = range(b);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let k = y * columns + x;
                    ids[fill[k] as usize] = id as u32;
                    fill[k] += 1;
                }
            }
        }
        Grid {
            cell,
            columns,
            rows,
            starts,
            ids,
        }
    }

    /// The triangles whose screen boxes the screen segment p0 → p1 passes, sorted, into
    /// `out`.
    fn candidates(&self, p0: DVec2, p1: DVec2, out: &mut Vec<u32>) {
        out.clear();
        let g = &self.grid;
        if g.columns == 0 {
            return;
        }
        // Pieces no longer than a cell, each taking the cells of its box.
        let steps = ((p1 - p0).length() / g.cell).ceil().clamp(1.0, 1e6) as usize;
        let cell = |v: f64, n: usize| ((v / g.cell).floor().max(0.0) as usize).min(n - 1);
        let mut last = None;
        for k in 0..steps {
            let q0 = p0.lerp(p1, k as f64 / steps as f64);
            let q1 = p0.lerp(p1, (k + 1) as f64 / steps as f64);
            let (lo, hi) = (q0.min(q1), q0.max(q1));
            let cells = (
                cell(lo.x, g.columns),
                cell(lo.y, g.rows),
                cell(hi.x, g.columns),
                cell(hi.y, g.rows),
            );
            if last == Some(cells) {
                continue;
            }
            last = Some(cells);
            for y in cells.1..=cells.3 {
                for x in cells.0..=cells.2 {
                    let k = y * g.columns + x;
                    out.extend_from_slice(&g.ids[g.starts[k] as usize..g.starts[k + 1] as usize]);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
    }

    /// The parts of `range` (parameters of the segment a → b, world) that triangles other
    /// than `own` (global ids) hide, in order, disjoint, each longer than [`JOIN`].
    /// `scratch` is reused between calls.
    pub fn hidden_parts(
        &self,
        (a, b): (DVec3, DVec3),
        range: (f64, f64),
        own: [u32; 2],
        scratch: &mut Vec<u32>,
    ) -> Vec<(f64, f64)> {
        let (pa, pb) = (
            self.project(a.lerp(b, range.0)),
            self.project(a.lerp(b, range.1)),
        );
        self.candidates(pa, pb, scratch);
        let near = self.rows.clip.row(2);
        let near_of = |p: DVec3| near.dot(p.extend(1.0));
        let farthest = near_of(a.lerp(b, range.0)).max(near_of(a.lerp(b, range.1)));
        let mut parts = Vec::new();
        for &id in scratch.iter() {
            if own.contains(&id) {
                continue;
            }
            // A triangle wholly at or beyond the line's farthest point hides none of it.
            let corners = self.corners(id);
            if corners.iter().all(|&c| near_of(c) >= farthest) {
                continue;
            }
            let Some(polygon) = clip(corners, &self.keep) else {
                continue;
            };
            self.hidden_by(&polygon, (corners, id), (a, b), range, &mut parts);
        }
        merge(parts)
    }

    /// Pushes to `out` the parts of `range` of the segment a → b that `polygon` (a cut part
    /// of global triangle `id`, with corners `triangle`) hides.
    ///
    /// With G(P) = eye.xyz − eye.w·P the direction from P towards the eye, the ray P + u·G
    /// meets the triangle's plane n · X = k at u = N / D, N = k − n · P, D = n · G; the near
    /// row there is P's plus u·H, H = near.xyz · G. The plane is nearer by the margin M =
    /// HIDDEN_MARGIN·(near(P) + w(P)) where N·H / D < −M, that is sign(D)·(N·H + M·D) < 0.
    /// (H < 0: the near row falls towards the eye, so such a u is positive.)
    fn hidden_by(
        &self,
        polygon: &Polygon,
        (triangle, id): ([DVec3; 3], u32),
        (a, b): (DVec3, DVec3),
        range: (f64, f64),
        out: &mut Vec<(f64, f64)>,
    ) {
        let eye = self.eye;
        let g = |p: DVec3| eye.truncate() - p * eye.w;
        // Where the ray through P meets the polygon, shrunk by OUTLINE_MARGIN: on screen,
        // along the projection of the range, whose parameter σ maps to s perspectively.
        let (a0, b0) = (a.lerp(b, range.0), a.lerp(b, range.1));
        let (pa, pb) = (self.project(a0), self.project(b0));
        let w = self.rows.clip.row(3);
        let (wa, wb) = (w.dot(a0.extend(1.0)), w.dot(b0.extend(1.0)));
        let mut projected = [DVec2::ZERO; MAX_CORNERS];
        let corners = polygon.corners();
        let mut area = 0.0;
        for (k, &c) in corners.iter().enumerate() {
            projected[k] = self.project(c);
        }
        let projected = &projected[..corners.len()];
        for k in 0..projected.len() {
            area += projected[k].perp_dot(projected[(k + 1) % projected.len()]);
        }
        if !(area.abs() > 0.0) {
            return;
        }
        let turn = area.signum();
        // The parameters σ inside, each side pulled in by `margin(its label)`.
        let inside = |margin: &dyn Fn(u8) -> f64| {
            let mut sigma = (0.0, 1.0);
            for k in 0..projected.len() {
                let (u, v) = (projected[k], projected[(k + 1) % projected.len()]);
                let side = v - u;
                let length = side.length();
                if !(length > 0.0) {
                    continue;
                }
                let m = margin(polygon.sides[k]);
                let f = |p: DVec2| turn * side.perp_dot(p - u) / length - m;
                keep_positive(&mut sigma, f(pa), f(pb));
                if sigma.0 >= sigma.1 || sigma.0.is_nan() {
                    return None;
                }
            }
            Some(sigma)
        };
        // Most candidates miss: the outline sides are only worth finding for those that do.
        if inside(&|_| 0.0).is_none() {
            return;
        }
        let outline = self.outline_sides(id);
        let Some(sigma) = inside(&|label| {
            if label < CUT && outline & (1 << label) != 0 {
                OUTLINE_MARGIN
            } else {
                0.0
            }
        }) else {
            return;
        };
        let to_s = |t: f64| range.0 + (range.1 - range.0) * (t * wa / (t * wa + (1.0 - t) * wb));
        let s = (to_s(sigma.0), to_s(sigma.1));
        if !(s.0 < s.1) {
            return;
        }
        // Nearer by the margin: a quadratic in s, from affine parts known at s = 0 and 1.
        let n = (triangle[1] - triangle[0]).cross(triangle[2] - triangle[0]);
        let k = n.dot(triangle[0]);
        let near = self.rows.clip.row(2);
        let w = self.rows.clip.row(3);
        let affine = |f: &dyn Fn(DVec3) -> f64| {
            let f0 = f(a);
            (f0, f(b) - f0)
        };
        let d = affine(&|p| n.dot(g(p)));
        // D keeps its sign where the ray meets the polygon.
        let sign = if d.0 + 0.5 * (s.0 + s.1) * d.1 >= 0.0 {
            1.0
        } else {
            -1.0
        };
        let nn = affine(&|p| k - n.dot(p));
        let h = affine(&|p| near.truncate().dot(g(p)));
        let m = affine(&|p| {
            let q = p.extend(1.0);
            // |near| = near: the range lies in front of the near plane.
            HIDDEN_MARGIN * (near.dot(q) + w.dot(q))
        });
        let product = |x: (f64, f64), y: (f64, f64)| [x.0 * y.0, x.0 * y.1 + x.1 * y.0, x.1 * y.1];
        let (p1, p2) = (product(nn, h), product(m, d));
        let q = [0, 1, 2].map(|i| sign * (p1[i] + p2[i]));
        negative_parts(q, s, out);
    }
}

/// Pushes the parts of `(lo, hi)` where q₀ + q₁ s + q₂ s² < 0.
fn negative_parts(q: [f64; 3], (lo, hi): (f64, f64), out: &mut Vec<(f64, f64)>) {
    let value = |s: f64| q[0] + s * (q[1] + s * q[2]);
    let mut cuts = vec![lo];
    let scale = q[0].abs().max(q[1].abs()).max(q[2].abs());
    if scale == 0.0 || !scale.is_finite() {
        return;
    }
    if q[2].abs() <= 1e-12 * scale {
        if q[1] != 0.0 {
            cuts.push(-q[0] / q[1]);
        }
    } else {
        let disc = q[1] * q[1] - 4.0 * q[2] * q[0];
        if disc >= 0.0 {
            // The root of larger magnitude first, then the other from their product.
            let t = -0.5 * (q[1] + q[1].signum() * disc.sqrt());
            if t != 0.0 {
                cuts.push(t / q[2]);
                cuts.push(q[0] / t);
            } else {
                cuts.push(0.0);
            }
        }
    }
    cuts.retain(|&c| c >= lo && c <= hi);
    cuts.push(hi);
    cuts.sort_by(f64::total_cmp);
    for pair in cuts.windows(2) {
        let (s0, s1) = (pair[0], pair[1]);
        if s1 > s0 && value(0.5 * (s0 + s1)) < 0.0 {
            out.push((s0, s1));
        }
    }
}

/// Sorted, disjoint intervals: `parts` joined where they overlap or meet within [`JOIN`],
/// those no longer than it dropped.
pub(crate) fn merge(mut parts: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    parts.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(parts.len());
    for (s0, s1) in parts {
        match out.last_mut() {
            Some(last) if s0 <= last.1 + JOIN => last.1 = last.1.max(s1),
            _ => out.push((s0, s1)),
        }
    }
    out.retain(|p| p.1 - p.0 > JOIN);
    out
}

/// `triangle` cut to the half-spaces h · (X, 1) ≥ 0 of `keep` (Sutherland–Hodgman);
/// `None` where less than a triangle's corners are left.
fn clip(triangle: [DVec3; 3], keep: &[DVec4]) -> Option<Polygon> {
    let mut polygon = Polygon {
        corners: [DVec3::ZERO; MAX_CORNERS],
        sides: [CUT; MAX_CORNERS],
        len: 3,
    };
    polygon.corners[..3].copy_from_slice(&triangle);
    polygon.sides[..3].copy_from_slice(&[0, 1, 2]);
    for h in keep {
        let side = |p: DVec3| h.dot(p.extend(1.0));
        let corners = polygon.corners();
        if corners.iter().all(|&p| side(p) >= 0.0) {
            continue;
        }
        let mut next = Polygon {
            corners: [DVec3::ZERO; MAX_CORNERS],
            sides: [CUT; MAX_CORNERS],
            len: 0,
        };
        let mut push = |p: DVec3, label: u8| {
            if next.len < MAX_CORNERS {
                next.corners[next.len] = p;
                next.sides[next.len] = label;
                next.len += 1;
            }
        };
        for k in 0..corners.len() {
            let (p, q) = (corners[k], corners[(k + 1) % corners.len()]);
            let (fp, fq) = (side(p), side(q));
            let label = polygon.sides[k];
            let crossing = || p.lerp(q, fp / (fp - fq));
            match (fp >= 0.0, fq >= 0.0) {
                (true, true) => push(p, label),
                // Leaving: the side from where it leaves lies on the plane.
                (true, false) => {
                    push(p, label);
                    push(crossing(), CUT);
                }
                (false, true) => push(crossing(), label),
                (false, false) => {}
            }
        }
        if next.len < 3 {
            return None;
        }
        polygon = next;
    }
    Some(polygon)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quadratic_is_negative_between_its_roots() {
        // (s − 0.25)(s − 0.75) < 0 on (0.25, 0.75).
        let mut out = Vec::new();
        negative_parts([0.1875, -1.0, 1.0], (0.0, 1.0), &mut out);
        assert_eq!(out.len(), 1);
        assert!((out[0].0 - 0.25).abs() < 1e-15 && (out[0].1 - 0.75).abs() < 1e-15);
        // Linear: 0.5 − s < 0 past 0.5.
        out.clear();
        negative_parts([0.5, -1.0, 0.0], (0.0, 1.0), &mut out);
        assert_eq!(out, vec![(0.5, 1.0)]);
    }

    #[test]
    fn touching_parts_join_and_specks_go() {
        let parts = vec![
            (0.5, 0.6),
            (0.1, 0.3),
            (0.3 + 1e-12, 0.4),
            (0.9, 0.9 + 1e-12),
        ];
        assert_eq!(merge(parts), vec![(0.1, 0.4), (0.5, 0.6)]);
    }

    #[test]
    fn a_triangle_cut_by_a_plane_keeps_its_side() {
        let h = DVec4::new(1.0, 0.0, 0.0, -0.5); // x ≥ 0.5
        let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let p = clip(t, &[h]).unwrap();
        assert_eq!(p.len, 3);
        assert!(p.corners().iter().all(|c| c.x >= 0.5 - 1e-15));
        assert!(clip(t, &[DVec4::new(1.0, 0.0, 0.0, -2.0)]).is_none());
    }
}
