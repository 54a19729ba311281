//! Polygon triangulation shared by the loaders (OBJ and PLY faces): concave faces stay
//! inside their outline, and the mask of polygon edges leaves out the diagonals that the
//! triangulation adds.
//!
//! Convex polygons, by far the most common faces, are fanned around their first corner in
//! linear time. Any other polygon is ear-clipped: each corner's ear status is kept, and
//! only the two neighbours of a clipped ear are tested again, against the reflex corners
//! that a 2D tree finds near the candidate triangle. That keeps a polygon of a million
//! corners to about n log n where testing every reflex corner took quadratic time.

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

/// `> 0` when `a → b → c` turns left in the orientation `sign`.
fn turn(sign: f64, a: DVec2, b: DVec2, c: DVec2) -> f64 {
    sign * (b - a).perp_dot(c - b)
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
    /// Whether a corner is in `tree` or `extra`.
    indexed: Vec<bool>,
    /// The corners that were reflex when the tree was built; those that stop being reflex
    /// leave it as queries meet them.
    tree: Tree,
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
            tree: Tree::default(),
            extra: Vec::new(),
        };
        clipper.reflex = (0..n).map(|i| clipper.is_reflex(i)).collect();
        clipper.reflex_count = clipper.reflex.iter().filter(|&&r| r).count();
        clipper.rebuild_index();
        clipper
    }

    fn is_reflex(&self, i: usize) -> bool {
        let p = |k: usize| self.pts[k];
        turn(self.sign, p(self.prev[i]), p(i), p(self.next[i])) <= 0.0
    }

    /// Indexes the corners that are reflex now in a fresh tree.
    fn rebuild_index(&mut self) {
        let members: Vec<usize> = (0..self.pts.len()).filter(|&i| self.reflex[i]).collect();
        self.tree = Tree::new(self.pts, &members);
        self.indexed.clone_from(&self.reflex);
        self.extra.clear();
    }

    fn is_ear(&mut self, i: usize) -> bool {
        if self.reflex[i] {
            return false;
        }
        if self.reflex_count == 0 {
            return true;
        }
        let (a, c) = (self.prev[i], self.next[i]);
        let (pts, sign) = (self.pts, self.sign);
        let tri = [pts[a], pts[i], pts[c]];
        let inside = |p: DVec2| {
            !tri.contains(&p)
                && turn(sign, tri[0], tri[1], p) >= 0.0
                && turn(sign, tri[1], tri[2], p) >= 0.0
                && turn(sign, tri[2], tri[0], p) >= 0.0
        };
        let (reflex, indexed) = (&self.reflex, &mut self.indexed);
        // A corner no longer reflex leaves the tree as it is met, so later queries skip
        // neither it nor the clipped corners again; should it turn reflex once more, it
        // goes to `extra`.
        let mut live = |r: usize| {
            indexed[r] = reflex[r];
            reflex[r]
        };
        let mut blocks = |r: usize| r != a && r != i && r != c && inside(pts[r]);
        let blocked = self.tree.any_in_triangle(tri, sign, &mut live, &mut blocks)
            || self.extra.iter().any(|&r| reflex[r] && blocks(r));
        !blocked
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

/// Corners per leaf of [`Tree`].
const LEAF: usize = 8;

/// A static 2D tree of corners (median splits on the wider axis, down to [`LEAF`]
/// corners), each node with its bounds and a count of members still live. A query visits
/// only nodes whose box meets the triangle and that hold live members, so its cost follows
/// how many corners lie near the triangle, whether they cover an area or, as polygon corners
/// do, lie along curves; members that died are dropped from the counts as they are met.
#[derive(Default)]
struct Tree {
    /// Member ids, permuted so that each node's members are one slice.
    items: Vec<u32>,
    /// The nodes in heap order: the children of node `k` are `2k + 1` and `2k + 2`.
    nodes: Vec<Node>,
    /// Size of the whole point set, for a rounding margin in the box tests.
    scale: f64,
}

#[derive(Clone, Copy)]
struct Node {
    lo: DVec2,
    hi: DVec2,
    start: u32,
    /// Live members: for a leaf, the first `live` of its slice.
    live: u32,
}

impl Tree {
    fn new(pts: &[DVec2], members: &[usize]) -> Self {
        let m = members.len();
        if m == 0 {
            return Self::default();
        }
        let depth = m.div_ceil(LEAF).next_power_of_two().trailing_zeros();
        let empty = Node {
            lo: DVec2::INFINITY,
            hi: DVec2::NEG_INFINITY,
            start: 0,
            live: 0,
        };
        let mut tree = Self {
            items: members.iter().map(|&i| i as u32).collect(),
            nodes: vec![empty; (2usize << depth) - 1],
            scale: 0.0,
        };
        tree.build(pts, 0, 0, m, depth);
        let root = tree.nodes[0];
        tree.scale = (root.hi - root.lo).max_element().max(1e-300);
        tree
    }

    fn build(&mut self, pts: &[DVec2], k: usize, start: usize, end: usize, depth: u32) {
        let slice = &mut self.items[start..end];
        let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
        for &i in slice.iter() {
            lo = lo.min(pts[i as usize]);
            hi = hi.max(pts[i as usize]);
        }
        self.nodes[k] = Node {
            lo,
            hi,
            start: start as u32,
            live: (end - start) as u32,
        };
        if depth == 0 {
            return;
        }
        let axis = usize::from(hi.y - lo.y > hi.x - lo.x);
        let mid = (end - start) / 2;
        if end > start {
            slice.select_nth_unstable_by(mid.min(slice.len() - 1), |&a, &b| {
                pts[a as usize][axis].total_cmp(&pts[b as usize][axis])
            });
        }
        self.build(pts, 2 * k + 1, start, start + mid, depth - 1);
        self.build(pts, 2 * k + 2, start + mid, end, depth - 1);
    }

    /// Whether `hit` holds for a live member in or near the closed triangle `tri`
    /// (orientation `sign`). Members for which `live` is false are dropped on the way.
    fn any_in_triangle(
        &mut self,
        tri: [DVec2; 3],
        sign: f64,
        live: &mut dyn FnMut(usize) -> bool,
        hit: &mut dyn FnMut(usize) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let query = Query {
            lo: tri[0].min(tri[1]).min(tri[2]),
            hi: tri[0].max(tri[1]).max(tri[2]),
            tri,
            sign,
            // Far above the rounding of a turn, far below any turn that matters.
            margin: [0, 1, 2].map(|e| 1e-9 * self.scale * (tri[(e + 1) % 3] - tri[e]).length()),
        };
        self.visit(0, &query, live, hit).0
    }

    /// Visits node `k`: whether a member was hit, and how many members died there.
    fn visit(
        &mut self,
        k: usize,
        q: &Query,
        live: &mut dyn FnMut(usize) -> bool,
        hit: &mut dyn FnMut(usize) -> bool,
    ) -> (bool, u32) {
        let node = self.nodes[k];
        if node.live == 0 || !q.meets(node.lo, node.hi) {
            return (false, 0);
        }
        if 2 * k + 1 >= self.nodes.len() {
            let first = node.start as usize;
            let mut count = node.live as usize;
            let (mut j, mut found) = (0, false);
            while j < count {
                let r = self.items[first + j] as usize;
                if !live(r) {
                    count -= 1;
                    self.items.swap(first + j, first + count);
                } else if hit(r) {
                    found = true;
                    break;
                } else {
                    j += 1;
                }
            }
            let died = node.live - count as u32;
            self.nodes[k].live = count as u32;
            return (found, died);
        }
        let (found, mut died) = self.visit(2 * k + 1, q, live, hit);
        if !found {
            let (right, more) = self.visit(2 * k + 2, q, live, hit);
            died += more;
            self.nodes[k].live -= died;
            return (right, died);
        }
        self.nodes[k].live -= died;
        (true, died)
    }
}

/// A triangle to search [`Tree`] with.
struct Query {
    lo: DVec2,
    hi: DVec2,
    tri: [DVec2; 3],
    sign: f64,
    margin: [f64; 3],
}

impl Query {
    /// Whether the box may hold a point of the closed triangle: the boxes overlap, and no
    /// edge's line has the whole box beyond it (the separating axes of a box and a triangle).
    fn meets(&self, lo: DVec2, hi: DVec2) -> bool {
        if lo.x > self.hi.x || hi.x < self.lo.x || lo.y > self.hi.y || hi.y < self.lo.y {
            return false;
        }
        let corners = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
        (0..3).all(|e| {
            let (a, b) = (self.tri[e], self.tri[(e + 1) % 3]);
            // `turn` is affine in the point, so its largest value on the box is at a corner.
            corners
                .iter()
                .any(|&p| turn(self.sign, a, b, p) >= -self.margin[e])
        })
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

    /// A polygon of 10 000 corners triangulates fully, every boundary edge marked. (Its speed
    /// is the benchmarks' business: tests assert no times.)
    #[test]
    fn ear_clipping_a_10k_gon() {
        let n = 10_000;
        let pts: Vec<Vec3> = (0..n)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / n as f32;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let mut tris = Vec::new();
        triangulate(&pts, &mut tris);
        assert_eq!(tris.len(), 9_998);
        let marked: u32 = tris.iter().map(|&t| polygon_edges(t, n).count_ones()).sum();
        assert_eq!(marked, n as u32);
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
        // And a star with random radii, reflex corners everywhere.
        let mut seed = 0x5eed_0f57_a7c3_u64;
        let mut rand = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let n = 50_000;
        let random_star: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / n as f64;
                let r = 0.1 + rand();
                [r * a.cos(), r * a.sin()]
            })
            .collect();
        for poly in [star(200_000), comb(100_000), random_star] {
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
