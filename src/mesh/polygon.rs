//! Polygon triangulation shared by the loaders (OBJ and PLY faces): concave faces stay
//! inside their outline, and the mask of polygon edges leaves out the diagonals that the
//! triangulation adds.
//!
//! Convex polygons, by far the most common faces, are fanned around their first corner in
//! linear time. Any other polygon is ear-clipped: each corner's ear status is kept, and
//! only the two neighbours of a clipped ear are tested again, against the reflex corners
//! that a uniform grid finds along the candidate triangle. That keeps a polygon of hundreds
//! of thousands of corners to about linear time where testing every reflex corner took
//! quadratic time.

use glam::{DVec2, DVec3, Vec3};
use std::collections::VecDeque;

/// Edge mask of a triangle whose corners are positions in an `n`-gon: edge `k` is a polygon
/// edge when it joins consecutive corners (last to first included).
pub(crate) fn polygon_edges(t: [usize; 3], n: usize) -> u8 {
    (0..3)
        .filter(|&k| t[(k + 1) % 3] == (t[k] + 1) % n)
        .fold(0, |mask, k| mask | 1 << k)
}

/// Triangulates a polygon that may be concave: appends `points.len() - 2` triangles to
/// `out` as indices into `points`, in the polygon's winding, each polygon edge an edge of
/// exactly one triangle. A degenerate remainder without ears (collinear or
/// self-intersecting) becomes a fan, so every input gives triangles and none panics.
pub(crate) fn triangulate(points: &[Vec3], out: &mut Vec<[usize; 3]>) {
    let n = points.len();
    if n < 3 {
        return;
    }
    if n == 3 {
        out.push([0, 1, 2]);
        return;
    }
    let pts = project(points);
    let area2: f64 = (0..n).map(|i| pts[i].perp_dot(pts[(i + 1) % n])).sum();
    // `turn > 0` means a left turn in the polygon's own orientation.
    let sign = if area2 < 0.0 { -1.0 } else { 1.0 };
    out.reserve(n - 2);
    if is_convex(&pts, sign) {
        out.extend((1..n - 1).map(|k| [0, k, k + 1]));
        return;
    }
    EarClipper::new(&pts, sign).run(out);
}

/// The polygon in 2D: projected onto the plane of its Newell normal by dropping the
/// normal's dominant axis, relative to the first corner. The cyclic choice of the other two
/// axes keeps the winding as seen from the normal.
fn project(points: &[Vec3]) -> Vec<DVec2> {
    let n = points.len();
    let origin = points[0].as_dvec3();
    let p3 = |i: usize| points[i].as_dvec3() - origin;
    let mut normal = DVec3::ZERO;
    for i in 0..n {
        let (a, b) = (p3(i), p3((i + 1) % n));
        normal += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let m = normal.abs();
    let (u, v) = if m.x >= m.y && m.x >= m.z {
        (1, 2)
    } else if m.y >= m.z {
        (2, 0)
    } else {
        (0, 1)
    };
    (0..n)
        .map(|i| {
            let p = p3(i);
            DVec2::new(p[u], p[v])
        })
        .collect()
}

/// Whether the polygon is strictly convex: every corner a left turn (in its orientation
/// `sign`) and the turns adding up to one full revolution, which rules out stars that wind
/// round more than once. Collinear or repeated corners fail the test, so the ear clipper,
/// which avoids zero-area triangles where it can, handles them.
fn is_convex(pts: &[DVec2], sign: f64) -> bool {
    let n = pts.len();
    let mut total = 0.0;
    for i in 0..n {
        let d0 = pts[i] - pts[(i + n - 1) % n];
        let d1 = pts[(i + 1) % n] - pts[i];
        let cross = sign * d0.perp_dot(d1);
        if cross <= 0.0 || cross.is_nan() {
            return false;
        }
        total += cross.atan2(d0.dot(d1));
    }
    // Each turn lies in (0, π), so the total is 2π times the winding number.
    (total - std::f64::consts::TAU).abs() < std::f64::consts::PI
}

/// Ear clipping over a doubly linked ring of corners. A corner is an ear when it is a
/// strict left turn and no reflex corner lies in or on its triangle; collinear corners
/// count as reflex, so they are no ears and they block ears they touch. Only reflex corners
/// need testing: in a simple polygon, a triangle that holds any corner holds a reflex one.
struct EarClipper<'a> {
    pts: &'a [DVec2],
    sign: f64,
    prev: Vec<usize>,
    next: Vec<usize>,
    reflex: Vec<bool>,
    reflex_count: usize,
    /// Whether a corner is in `grid` or `extra`.
    indexed: Vec<bool>,
    /// The corners that were reflex when the grid was built. Corners that stop being reflex
    /// stay in it and are skipped by their flag.
    grid: Grid,
    /// Corners that turned reflex later, which only a degenerate polygon does.
    extra: Vec<usize>,
}

impl<'a> EarClipper<'a> {
    fn new(pts: &'a [DVec2], sign: f64) -> Self {
        let n = pts.len();
        let prev: Vec<usize> = (0..n).map(|i| (i + n - 1) % n).collect();
        let next: Vec<usize> = (0..n).map(|i| (i + 1) % n).collect();
        let mut clipper = Self {
            pts,
            sign,
            prev,
            next,
            reflex: Vec::new(),
            reflex_count: 0,
            indexed: Vec::new(),
            grid: Grid::default(),
            extra: Vec::new(),
        };
        clipper.reflex = (0..n).map(|i| clipper.is_reflex(i)).collect();
        clipper.reflex_count = clipper.reflex.iter().filter(|&&r| r).count();
        clipper.rebuild_index();
        clipper
    }

    /// `> 0` when `a → b → c` turns left in the polygon's orientation.
    fn turn(&self, a: usize, b: usize, c: DVec2) -> f64 {
        let (pa, pb) = (self.pts[a], self.pts[b]);
        self.sign * (pb - pa).perp_dot(c - pb)
    }

    fn is_reflex(&self, i: usize) -> bool {
        self.turn(self.prev[i], i, self.pts[self.next[i]]) <= 0.0
    }

    /// Indexes the corners that are reflex now in a fresh grid.
    fn rebuild_index(&mut self) {
        let members: Vec<usize> = (0..self.pts.len()).filter(|&i| self.reflex[i]).collect();
        self.grid = Grid::new(self.pts, &members);
        self.indexed.clone_from(&self.reflex);
        self.extra.clear();
    }

    fn is_ear(&self, i: usize) -> bool {
        if self.reflex[i] {
            return false;
        }
        if self.reflex_count == 0 {
            return true;
        }
        let (a, c) = (self.prev[i], self.next[i]);
        let tri = [self.pts[a], self.pts[i], self.pts[c]];
        let blocks = |r: usize| {
            let p = self.pts[r];
            self.reflex[r]
                && r != a
                && r != i
                && r != c
                && !tri.contains(&p)
                && self.turn(a, i, p) >= 0.0
                && self.turn(i, c, p) >= 0.0
                && self.turn(c, a, p) >= 0.0
        };
        !(self.grid.any_in_triangle(tri, blocks) || self.extra.iter().any(|&r| blocks(r)))
    }

    /// Updates the reflex flag of a corner whose neighbours changed.
    fn update_reflex(&mut self, k: usize) {
        let now = self.is_reflex(k);
        if now == self.reflex[k] {
            return;
        }
        self.reflex[k] = now;
        if now {
            self.reflex_count += 1;
            if !self.indexed[k] {
                self.indexed[k] = true;
                self.extra.push(k);
            }
        } else {
            self.reflex_count -= 1;
        }
    }

    fn run(mut self, out: &mut Vec<[usize; 3]>) {
        let n = self.pts.len();
        // A queue of ears, each entry stamped with the corner's re-test count: a corner
        // re-tested after a neighbouring clip goes to the back with a new stamp, and its
        // older entry is skipped. In a convex stretch that clips every other corner per
        // round, as earcut does, rather than fanning long slivers around one corner.
        let mut stamp = vec![0u32; n];
        let mut alive = vec![true; n];
        let mut queue: VecDeque<(usize, u32)> =
            (0..n).filter(|&i| self.is_ear(i)).map(|i| (i, 0)).collect();
        let (mut left, mut some) = (n, 0);
        while left > 3 {
            let Some((i, s)) = queue.pop_front() else {
                break;
            };
            if !alive[i] || s != stamp[i] {
                continue;
            }
            let (a, c) = (self.prev[i], self.next[i]);
            out.push([a, i, c]);
            alive[i] = false;
            self.next[a] = c;
            self.prev[c] = a;
            left -= 1;
            some = c;
            self.update_reflex(a);
            self.update_reflex(c);
            if self.extra.len() > 64 && self.extra.len() * 8 > self.reflex_count {
                self.rebuild_index();
            }
            for k in [a, c] {
                stamp[k] = stamp[k].wrapping_add(1);
                if self.is_ear(k) {
                    queue.push_back((k, stamp[k]));
                }
            }
        }
        // The last triangle, or a fan over a remainder that has no ear.
        let mut k = self.next[some];
        while self.next[k] != some {
            out.push([some, k, self.next[k]]);
            k = self.next[k];
        }
    }
}

/// A uniform grid of corners over their bounding box, about one corner per cell, stored
/// as one sorted array with per-cell offsets.
#[derive(Default)]
struct Grid {
    origin: DVec2,
    cell: f64,
    columns: usize,
    rows: usize,
    /// Offsets into `items`, one per cell plus the end.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    fn new(pts: &[DVec2], members: &[usize]) -> Self {
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &i in members {
            lo = lo.min(pts[i]);
            hi = hi.max(pts[i]);
        }
        if members.is_empty() || !(lo.is_finite() && hi.is_finite()) {
            lo = DVec2::ZERO;
            hi = DVec2::ZERO;
        }
        let extent = hi - lo;
        let count = members.len().max(1) as f64;
        let mut cell = (extent.x * extent.y / count)
            .sqrt()
            .max(extent.max_element() / count);
        if !cell.is_finite() || cell <= 0.0 {
            cell = 1.0;
        }
        let columns = ((extent.x / cell) as usize).saturating_add(1);
        let rows = ((extent.y / cell) as usize).saturating_add(1);
        let mut grid = Self {
            origin: lo,
            cell,
            columns,
            rows,
            start: Vec::new(),
            items: Vec::new(),
        };
        // Counting sort of the members by cell.
        let cells: Vec<usize> = members.iter().map(|&i| grid.cell_of(pts[i])).collect();
        let mut start = vec![0u32; columns * rows + 1];
        for &c in &cells {
            start[c + 1] += 1;
        }
        for c in 1..start.len() {
            start[c] += start[c - 1];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; members.len()];
        for (&i, &c) in members.iter().zip(&cells) {
            items[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        grid.start = start;
        grid.items = items;
        grid
    }

    fn column(&self, x: f64) -> usize {
        (((x - self.origin.x) / self.cell).floor().max(0.0) as usize).min(self.columns - 1)
    }

    fn row(&self, y: f64) -> usize {
        (((y - self.origin.y) / self.cell).floor().max(0.0) as usize).min(self.rows - 1)
    }

    fn cell_of(&self, p: DVec2) -> usize {
        self.row(p.y) * self.columns + self.column(p.x)
    }

    /// Whether `hit` holds for a member in a cell that the closed triangle `tri` touches.
    /// Row by row, only the cells under the triangle's cross-section are visited, so a long
    /// thin diagonal triangle visits cells along its length, not its whole bounding box.
    fn any_in_triangle(&self, tri: [DVec2; 3], mut hit: impl FnMut(usize) -> bool) -> bool {
        if self.items.is_empty() {
            return false;
        }
        // Margins far above rounding, so a corner on the triangle's boundary is never missed.
        let margin = self.cell * 0.01;
        let y_min = tri[0].y.min(tri[1].y).min(tri[2].y);
        let y_max = tri[0].y.max(tri[1].y).max(tri[2].y);
        for row in self.row(y_min - margin)..=self.row(y_max + margin) {
            let band = self.origin.y + row as f64 * self.cell;
            let lo = (band - margin).max(y_min);
            let hi = (band + self.cell + margin).min(y_max);
            let (mut x0, mut x1) = (f64::INFINITY, f64::NEG_INFINITY);
            for k in 0..3 {
                let (p, q) = (tri[k], tri[(k + 1) % 3]);
                if (lo..=hi).contains(&p.y) {
                    x0 = x0.min(p.x);
                    x1 = x1.max(p.x);
                }
                if p.y != q.y {
                    for y in [lo, hi] {
                        if (p.y.min(q.y)..=p.y.max(q.y)).contains(&y) {
                            let x = p.x + (y - p.y) / (q.y - p.y) * (q.x - p.x);
                            x0 = x0.min(x);
                            x1 = x1.max(x);
                        }
                    }
                }
            }
            if x0.is_nan() || x1.is_nan() || x0 > x1 {
                continue;
            }
            let base = row * self.columns;
            let cells = base + self.column(x0 - margin)..=base + self.column(x1 + margin);
            let (first, last) = (self.start[*cells.start()], self.start[*cells.end() + 1]);
            if self.items[first as usize..last as usize]
                .iter()
                .any(|&i| hit(i as usize))
            {
                return true;
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Checks a triangulation of the 2D polygon `poly` (in the XY plane): `n - 2` triangles
    /// in the polygon's winding that add up to its area, and an exact edge mask, each
    /// polygon edge in exactly one triangle.
    fn check_triangulation(poly: &[[f64; 2]]) {
        let n = poly.len();
        let pts: Vec<Vec3> = poly
            .iter()
            .map(|p| Vec3::new(p[0] as f32, p[1] as f32, 0.0))
            .collect();
        let mut tris = Vec::new();
        triangulate(&pts, &mut tris);
        assert_eq!(tris.len(), n - 2);
        // The f32 corners, as the triangulation saw them.
        let poly: Vec<[f64; 2]> = pts.iter().map(|p| [p.x.into(), p.y.into()]).collect();
        let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        };
        let area: f64 = (0..n)
            .map(|i| cross([0.0, 0.0], poly[i], poly[(i + 1) % n]))
            .sum();
        let mut sum = 0.0;
        let mut boundary = vec![0; n];
        for &t in &tris {
            let a = cross(poly[t[0]], poly[t[1]], poly[t[2]]);
            assert!(a * area >= 0.0, "triangle {t:?} flips the winding");
            sum += a;
            let mask = polygon_edges(t, n);
            for k in 0..3 {
                let (p, q) = (t[k], t[(k + 1) % 3]);
                if q == (p + 1) % n {
                    assert!(mask & 1 << k != 0);
                    boundary[p] += 1;
                } else {
                    assert!(mask & 1 << k == 0, "diagonal {p}-{q} is marked");
                }
            }
        }
        assert!((sum - area).abs() < 1e-6 * area.abs(), "{sum} != {area}");
        assert!(boundary.iter().all(|&c| c == 1), "{boundary:?}");
    }

    #[test]
    fn ear_clipping_handles_concave_polygons_both_ways_round() {
        let l_shape = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        let star: Vec<[f64; 2]> = (0..10)
            .map(|i| {
                let r = if i % 2 == 0 { 1.0 } else { 0.4 };
                let a = i as f64 * std::f64::consts::PI / 5.0;
                [r * a.cos(), r * a.sin()]
            })
            .collect();
        let comb: Vec<[f64; 2]> = (0..8)
            .flat_map(|i| [[i as f64, 3.0], [i as f64 + 0.5, 0.5]])
            .chain([[8.0, 3.0], [8.0, 0.0], [0.0, 0.0]])
            .rev()
            .collect();
        for poly in [l_shape.to_vec(), star, comb] {
            check_triangulation(&poly);
            let reversed: Vec<_> = poly.iter().rev().copied().collect();
            check_triangulation(&reversed);
        }
    }

    #[test]
    fn ear_clipping_handles_random_and_collinear_polygons() {
        // Star-shaped polygons with random radii are simple, and mostly very concave.
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut rand = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..300 {
            let n = 4 + (rand() * 60.0) as usize;
            let poly: Vec<[f64; 2]> = (0..n)
                .map(|i| {
                    let a = i as f64 * std::f64::consts::TAU / n as f64;
                    let r = 0.1 + rand();
                    [r * a.cos(), r * a.sin()]
                })
                .collect();
            check_triangulation(&poly);
        }
        // A square with extra corners along its sides.
        let square = [
            [0.0, 0.0],
            [1.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [2.0, 2.0],
            [1.0, 2.0],
        ]
        .into_iter()
        .chain([[0.0, 2.0], [0.0, 1.0]])
        .collect::<Vec<_>>();
        check_triangulation(&square);
    }

    #[test]
    fn ear_clipping_works_in_any_plane() {
        // The L shape (area 3) standing in the YZ plane and in a tilted plane.
        let l_shape = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        let tilt = glam::Quat::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 1.2);
        let upright: Vec<Vec3> = l_shape.iter().map(|p| Vec3::new(7.0, p[0], p[1])).collect();
        let tilted: Vec<Vec3> = l_shape
            .iter()
            .map(|p| tilt * Vec3::new(p[0], p[1], 0.0))
            .collect();
        for pts in [upright, tilted] {
            let mut tris = Vec::new();
            triangulate(&pts, &mut tris);
            let area: f32 = tris
                .iter()
                .map(|t| {
                    (pts[t[1]] - pts[t[0]])
                        .cross(pts[t[2]] - pts[t[0]])
                        .length()
                        / 2.0
                })
                .sum();
            assert!((area - 3.0).abs() < 1e-4, "{area}");
        }
    }

    #[test]
    fn degenerate_polygons_do_not_panic() {
        let line: Vec<Vec3> = (0..7).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
        let same = vec![Vec3::ONE; 5];
        let bowtie = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)].to_vec();
        for poly in [line, same, bowtie] {
            let mut tris = Vec::new();
            triangulate(&poly, &mut tris);
            assert_eq!(tris.len(), poly.len() - 2);
        }
    }

    #[test]
    fn ear_clipping_a_10k_gon_is_fast() {
        let n = 10_000;
        let pts: Vec<Vec3> = (0..n)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / n as f32;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let start = std::time::Instant::now();
        let mut tris = Vec::new();
        triangulate(&pts, &mut tris);
        assert_eq!(tris.len(), 9_998);
        let marked: u32 = tris.iter().map(|&t| polygon_edges(t, n).count_ones()).sum();
        assert_eq!(marked, n as u32);
        assert!(start.elapsed().as_secs_f64() < 2.0, "{:?}", start.elapsed());
    }

    /// A star of `n` corners alternating between radius 1 and 0.4.
    fn star(n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let r = if i % 2 == 0 { 1.0 } else { 0.4 };
                let a = i as f64 * std::f64::consts::TAU / n as f64;
                [r * a.cos(), r * a.sin()]
            })
            .collect()
    }

    /// A comb of `teeth` teeth (2 corners each) on a base: `2 × teeth + 2` corners.
    fn comb(teeth: usize) -> Vec<[f64; 2]> {
        (0..teeth)
            .flat_map(|i| [[i as f64, 3.0], [i as f64 + 0.5, 0.5]])
            .chain([[teeth as f64, 3.0], [teeth as f64, 0.0], [0.0, 0.0]])
            .collect()
    }

    #[test]
    fn large_concave_polygons_triangulate_exactly() {
        // 200,000 corners each: quadratic ear clipping took about a minute on one of them.
        for poly in [star(200_000), comb(100_000)] {
            check_triangulation(&poly);
            let reversed: Vec<_> = poly.iter().rev().copied().collect();
            check_triangulation(&reversed);
        }
    }

    #[test]
    fn spirals_and_bridged_holes_triangulate_exactly() {
        // A spiral arm has ears only near its ends.
        let arm = |r0: f64| {
            (0..20_000).map(move |t| {
                let a = t as f64 * 0.01;
                let r = r0 + 0.3 * a;
                [r * a.cos(), r * a.sin()]
            })
        };
        let spiral: Vec<_> = arm(1.0)
            .chain(arm(1.1).collect::<Vec<_>>().into_iter().rev())
            .collect();
        check_triangulation(&spiral);
        // A square with a square hole, joined by a bridge whose two corners repeat.
        let holed = [
            [0.0, 0.0],
            [4.0, 0.0],
            [4.0, 4.0],
            [0.0, 4.0],
            [0.0, 0.0],
            [1.0, 1.0],
            [1.0, 3.0],
            [3.0, 3.0],
            [3.0, 1.0],
            [1.0, 1.0],
        ];
        check_triangulation(&holed);
    }

    #[test]
    fn a_million_corner_circle_triangulates_exactly() {
        // In f32 a regular million-gon is not strictly convex (rounding dents it), so this
        // takes the ear clipper; one that is convex is a fan around corner 0.
        let n = 1_000_000;
        let circle: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / n as f64;
                [a.cos(), a.sin()]
            })
            .collect();
        check_triangulation(&circle);
        let hexagon: Vec<Vec3> = (0..6)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / 6.0;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let mut tris = Vec::new();
        triangulate(&hexagon, &mut tris);
        assert_eq!(tris, [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]]);
    }

    #[test]
    fn self_intersecting_polygons_give_triangles_without_panic() {
        // Random corners make a tangle of crossing edges; a pentagram winds round twice.
        let mut seed = 0x0bad_5eed_u64;
        let mut rand = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f32 / (1u64 << 53) as f32
        };
        for n in [4, 5, 17, 300, 5000] {
            let poly: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(rand(), rand(), rand() * 0.01))
                .collect();
            let mut tris = Vec::new();
            triangulate(&poly, &mut tris);
            assert_eq!(tris.len(), n - 2);
            assert!(tris.iter().flatten().all(|&k| k < n));
        }
        let pentagram: Vec<Vec3> = (0..5)
            .map(|i| {
                let a = (i * 2) as f32 * std::f32::consts::TAU / 5.0;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let mut tris = Vec::new();
        triangulate(&pentagram, &mut tris);
        assert_eq!(tris.len(), 3);
    }
}
