//! Triangles that cross others of the same mesh: a mesh that passes through itself (a head's
//! eyes through it, a leg through a body, parts of an assembly modelled in one file). Where a
//! surface crosses a triangle, the triangle's own lines may be hidden right next to its visible
//! pixels with no outline between, so the passes draw the drawn edges of such triangles (and
//! of their patches) only where they are visible ([`super::patches::Patches::crossed`]).
//!
//! Two triangles cross when one passes through the other's plane (corners on both sides of
//! it), their intersection is more than a point, and they share no edge: triangles sharing
//! one vertex cross when they meet along a segment from it (a fan folded through itself).
//! Two that each lie on one side of the other's plane (touching only within the tolerance),
//! and coplanar ones, never cross. The test is in f64 with a tolerance of
//! 1e-9 of the mesh's size, so it errs towards "crossing" only for contacts far below a pixel,
//! which costs the exact (trace-pass) path, never a wrong line.
//!
//! Where two triangles cross, they meet along a segment: together, the segments are the
//! mesh's intersection lines ([`Style::intersection_lines`](crate::Style::intersection_lines)),
//! the curves where its surfaces pass through each other.

use glam::{DVec3, U64Vec3, Vec3};

use super::par::*;

/// Two triangles of a mesh that cross (`t < u`), and the segment along which they meet, in
/// the mesh's coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    /// The lower triangle id.
    pub t: u32,
    /// The higher.
    pub u: u32,
    /// The segment's ends.
    pub ends: [DVec3; 2],
}

/// Per triangle, whether it crosses another triangle of the mesh.
pub fn crossing_triangles(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<bool> {
    flag_crossing(triangles.len(), &crossings(positions, triangles))
}

/// Per triangle of `count`, whether one of `crossings` holds it.
pub fn flag_crossing(count: usize, crossings: &[Crossing]) -> Vec<bool> {
    let mut crossing = vec![false; count];
    for c in crossings {
        crossing[c.t as usize] = true;
        crossing[c.u as usize] = true;
    }
    crossing
}

/// Contacts closer than this fraction of the surfaces' size are not crossings.
pub const TOLERANCE: f64 = 1e-9;

/// The tolerance of the crossings between two placed surfaces of world bounds `a` and `b`:
/// [`TOLERANCE`] of the larger's size.
pub fn pair_tolerance(a: (DVec3, DVec3), b: (DVec3, DVec3)) -> f64 {
    TOLERANCE * (a.1 - a.0).max_element().max((b.1 - b.0).max_element())
}

/// The pairs of triangles of a mesh that cross, each once (`t < u`), sorted, with the
/// segments along which they meet.
pub fn crossings(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Crossing> {
    let corners = |t: usize| triangles[t].map(|v| positions[v as usize].as_dvec3());
    // The size of what the triangles span (not of vertices no triangle uses).
    let (lo, hi) =
        triangles
            .iter()
            .flatten()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
                let p = positions[v as usize].as_dvec3();
                (lo.min(p), hi.max(p))
            });
    let size = (hi - lo).max_element();
    let apart = |t: usize, u: usize| !shares_an_edge(triangles[t], triangles[u], positions);
    find(triangles.len(), &corners, &apart, TOLERANCE * size)
}

/// Whether a closed surface certainly passes nowhere through itself, by a test linear in
/// its size: a point `o` lies strictly on one side of every triangle's plane, all of them
/// facing it alike (all away, or all towards), and the triangles' solid angles seen from `o`
/// add up to one sphere (4π, not 8π or more). The caller adds that the surface is closed and
/// oriented ([`closed_and_oriented`]). Then the triangles, projected from `o` onto a sphere
/// around it, cover each direction exactly once (the cover's degree is the solid angle over
/// 4π, and no triangle counts negatively), whereas two triangles that meet beyond their
/// shared edges and vertices would cover the directions near where they meet twice. Spheres,
/// convex parts and other star-shaped surfaces pass, seen from their centre or their
/// vertices' mean; `None` says nothing about the rest. Returns the point it was seen from.
pub fn star_centre(positions: &[Vec3], triangles: &[[u32; 3]]) -> Option<DVec3> {
    if triangles.len() < 4 {
        return None;
    }
    let corners = |t: &[u32; 3]| t.map(|v| positions[v as usize].as_dvec3());
    // The corners' bounds and sum, chunk by chunk.
    let start = (DVec3::INFINITY, DVec3::NEG_INFINITY, DVec3::ZERO);
    let add = |(lo, hi, sum): (DVec3, DVec3, DVec3), t: &[u32; 3]| {
        let [a, b, c] = corners(t);
        (
            lo.min(a.min(b).min(c)),
            hi.max(a.max(b).max(c)),
            sum + a + b + c,
        )
    };
    let (lo, hi, sum) = triangles
        .par_chunks(CHUNK)
        .map(|chunk| chunk.iter().fold(start, add))
        .collect::<Vec<_>>()
        .into_iter()
        .fold(start, |x, y| (x.0.min(y.0), x.1.max(y.1), x.2 + y.2));
    let mean = sum / (3 * triangles.len()) as f64;
    [(lo + hi) / 2.0, mean]
        .into_iter()
        .find(|&o| covers_once_from(o, triangles, &corners))
}

/// Triangles a task of the linear test adds up.
const CHUNK: usize = 1 << 14;

/// Whether every triangle faces `o` alike, with `o` off its plane by more than rounding,
/// and their solid angles from `o` add up to 4π ([`star_centre`]).
fn covers_once_from(
    o: DVec3,
    triangles: &[[u32; 3]],
    corners: &(impl Fn(&[u32; 3]) -> [DVec3; 3] + Sync),
) -> bool {
    // The solid angle (NaN where the triangle's plane passes too near o) and which way it
    // faces, per triangle, added up chunk by chunk.
    let seen = |t: &[u32; 3]| {
        let [a, b, c] = corners(t).map(|p| p - o);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        // The triple product, 6 × the volume of the tetrahedron (o, a, b, c), and the
        // Van Oosterom–Strackee solid angle.
        let volume = a.dot(b.cross(c));
        let scale = la * lb * lc;
        // Off the plane by far more than f64 rounds the product (about 1e-15 of it);
        // false for NaN too.
        let off_the_plane = volume.abs() > 1e-12 * scale;
        if !off_the_plane {
            return (f64::NAN, [0u64, 0]);
        }
        let den = scale + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        let side = if volume > 0.0 { [1, 0] } else { [0, 1] };
        (2.0 * volume.atan2(den), side)
    };
    let add =
        |x: (f64, [u64; 2]), y: (f64, [u64; 2])| (x.0 + y.0, [x.1[0] + y.1[0], x.1[1] + y.1[1]]);
    let (angle, sides) = triangles
        .par_chunks(CHUNK)
        .map(|chunk| chunk.iter().map(seen).fold((0.0, [0, 0]), add))
        .collect::<Vec<_>>()
        .into_iter()
        .fold((0.0, [0, 0]), add);
    let alike = sides[0] == 0 || sides[1] == 0;
    let sphere = 4.0 * std::f64::consts::PI;
    alike && (angle.abs() - sphere).abs() < 0.5 * sphere
}

/// Whether every edge of the mesh (vertices welded by position: `welded`, `neighbours` as
/// [`Mesh::edge_neighbours`](crate::Mesh::edge_neighbours) finds them) is shared by exactly
/// two triangles that run it in opposite directions: a closed, oriented surface.
pub fn closed_and_oriented(
    triangles: &[[u32; 3]],
    welded: &[u32],
    neighbours: &[[u32; 3]],
) -> bool {
    let ends = |t: usize, i: usize| {
        let tri = triangles[t];
        (welded[tri[i] as usize], welded[tri[(i + 1) % 3] as usize])
    };
    (0..triangles.len()).into_par_iter().all(|t| {
        (0..3).all(|i| {
            let u = neighbours[t][i];
            if u == super::adjacency::NO_NEIGHBOUR {
                return false;
            }
            let (a, b) = ends(t, i);
            (0..3).any(|j| ends(u as usize, j) == (b, a))
        })
    })
}

/// Where the triangles of one surface cross those of another (world corners `a` and `b`,
/// each a part of a surface, such as the triangles of two instances near where their bounds
/// meet): crossing `t` is an index into `a`, `u` into `b`, sorted. Triangles sharing two
/// corners (an edge where two surfaces join) do not cross, as in [`crossings`]; contacts
/// within `tolerance` are not crossings.
pub fn crossings_between(a: &[[DVec3; 3]], b: &[[DVec3; 3]], tolerance: f64) -> Vec<Crossing> {
    let split = a.len();
    let corners = |t: usize| if t < split { a[t] } else { b[t - split] };
    let apart = |t: usize, u: usize| {
        let (p, q) = (corners(t), corners(u));
        (t < split) != (u < split) && p.iter().filter(|c| q.contains(c)).count() < 2
    };
    let mut found = find(a.len() + b.len(), &corners, &apart, tolerance);
    for c in &mut found {
        c.u -= split as u32;
    }
    found
}

/// The pairs of a soup of `n` triangles (`corners`) that cross by more than `tolerance`,
/// among those `admits` (`t < u`) lets meet, each once (`t < u`), sorted.
fn find(
    n: usize,
    corners: &(impl Fn(usize) -> [DVec3; 3] + Sync),
    admits: &(impl Fn(usize, usize) -> bool + Sync),
    tolerance: f64,
) -> Vec<Crossing> {
    if n < 2 {
        return Vec::new();
    }
    let boxes: Vec<[DVec3; 2]> = (0..n)
        .map(|t| {
            let [a, b, c] = corners(t);
            [a.min(b).min(c), a.max(b).max(c)]
        })
        .collect();
    let (lo, hi) = boxes
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), b| {
            (lo.min(b[0]), hi.max(b[1]))
        });
    let size = (hi - lo).max_element();
    if !(size > 0.0 && size.is_finite()) {
        return Vec::new();
    }
    // A grid of cells about the size of a typical triangle (the median of their largest
    // extents), at most 2^20 cells a side, coarser where the triangles would fill more than
    // 16 cells each on average.
    let mut extents: Vec<f64> = boxes.iter().map(|b| (b[1] - b[0]).max_element()).collect();
    let middle = extents.len() / 2;
    let median = *extents
        .select_nth_unstable_by(middle, |a, b| a.total_cmp(b))
        .1;
    // A triangle spanning more than this many cells (a large one among small ones) is tested
    // against every other by its box instead.
    const MOST_CELLS: u64 = 512;
    let cells = |(a, b): (U64Vec3, U64Vec3)| (b - a + 1).element_product();
    let span_in = |cell: f64, b: &[DVec3; 2]| {
        // p - lo >= 0, so truncation is the floor (and no call to libm's floor).
        let at = |p: DVec3| ((p - lo) / cell).as_u64vec3();
        (at(b[0]), at(b[1]))
    };
    let mut cell = median
        .max(size / f64::from(1u32 << 20))
        .max(f64::MIN_POSITIVE);
    while cell < size
        && boxes
            .iter()
            .map(|b| cells(span_in(cell, b)))
            .filter(|&c| c <= MOST_CELLS)
            .sum::<u64>()
            > 16 * n as u64
    {
        cell *= 2.0;
    }
    let key = |c: U64Vec3| c.x | c.y << 21 | c.z << 42;
    let spans: Vec<(U64Vec3, U64Vec3)> = boxes.iter().map(|b| span_in(cell, b)).collect();
    let mut entries: Vec<(u64, u32)> = Vec::with_capacity(n);
    let mut large = Vec::new();
    for (t, &span) in spans.iter().enumerate() {
        if cells(span) > MOST_CELLS {
            large.push(t);
            continue;
        }
        for z in span.0.z..=span.1.z {
            for y in span.0.y..=span.1.y {
                for x in span.0.x..=span.1.x {
                    entries.push((key(U64Vec3::new(x, y, z)), t as u32));
                }
            }
        }
    }
    entries.par_sort_unstable();
    let overlap = |t: usize, u: usize| {
        let (a, b) = (boxes[t], boxes[u]);
        a[0].cmple(b[1] + tolerance).all() && b[0].cmple(a[1] + tolerance).all()
    };
    // Unit normals, none for a degenerate triangle: computed once, not for every pair.
    let normals: Vec<Option<DVec3>> = (0..n).into_par_iter().map(|t| plane(corners(t))).collect();
    let test = |t: usize, u: usize| -> Option<Crossing> {
        let (t, u) = (t.min(u), t.max(u));
        if !overlap(t, u) || !admits(t, u) {
            return None;
        }
        let (nt, nu) = (normals[t]?, normals[u]?);
        let ends = crossing_on_planes((corners(t), nt), (corners(u), nu), tolerance)?;
        let (t, u) = (t as u32, u as u32);
        Some(Crossing { t, u, ends })
    };
    // Runs of one cell; a pair is tested in the cell that holds the low corner of its boxes'
    // overlap, so once however many cells both span.
    let mut runs = Vec::new();
    let mut start = 0;
    for i in 1..=entries.len() {
        if i == entries.len() || entries[i].0 != entries[start].0 {
            runs.push(start..i);
            start = i;
        }
    }
    let found: Vec<Vec<Crossing>> = runs
        .par_iter()
        .map(|run| {
            let run = &entries[run.clone()];
            let here = run[0].0;
            let mut pairs = Vec::new();
            for (i, &(_, t)) in run.iter().enumerate() {
                for &(_, u) in &run[i + 1..] {
                    let (t, u) = (t as usize, u as usize);
                    // The cell of the overlap's low corner: the larger of the low cells.
                    let low = spans[t].0.max(spans[u].0);
                    if key(low.min(spans[t].1).min(spans[u].1)) == here {
                        pairs.extend(test(t, u));
                    }
                }
            }
            pairs
        })
        .collect();
    let mut is_large = vec![false; n];
    for &t in &large {
        is_large[t] = true;
    }
    let big: Vec<Vec<Crossing>> = large
        .par_iter()
        .map(|&t| {
            (0..n)
                .filter(|&u| u != t && (!is_large[u] || u > t))
                .filter_map(|u| test(t, u))
                .collect()
        })
        .collect();
    let mut all: Vec<Crossing> = found.into_iter().chain(big).flatten().collect();
    all.sort_unstable_by_key(|c| (c.t, c.u));
    all
}

/// Whether two triangles share two corners by position (an edge, welded or not).
fn shares_an_edge(t: [u32; 3], u: [u32; 3], positions: &[Vec3]) -> bool {
    let at = |v: u32| positions[v as usize].to_array().map(f32::to_bits);
    t.iter()
        .filter(|&&a| u.iter().any(|&b| a == b || at(a) == at(b)))
        .count()
        >= 2
}

/// Whether triangles `t` and `u` meet in more than a point (by more than `tolerance`),
/// coplanar ones never.
pub fn cross(t: [DVec3; 3], u: [DVec3; 3], tolerance: f64) -> bool {
    crossing_segment(t, u, tolerance).is_some()
}

/// The segment along which triangles `t` and `u` meet, where one passes through the other's
/// plane and they meet in more than a point (by more than `tolerance`); coplanar ones never. Its ends are where one triangle's edges
/// pass through the other's plane, or the other's edges through the first's.
pub fn crossing_segment(t: [DVec3; 3], u: [DVec3; 3], tolerance: f64) -> Option<[DVec3; 2]> {
    crossing_on_planes((t, plane(t)?), (u, plane(u)?), tolerance)
}

/// [`crossing_segment`] of triangles `t` and `u` with unit normals `nt` and `nu`.
fn crossing_on_planes(
    (t, nt): ([DVec3; 3], DVec3),
    (u, nu): ([DVec3; 3], DVec3),
    tolerance: f64,
) -> Option<[DVec3; 2]> {
    let side = |n: DVec3, origin: DVec3, p: [DVec3; 3]| {
        p.map(|q| {
            let d = n.dot(q - origin);
            if d.abs() <= tolerance {
                0.0
            } else {
                d
            }
        })
    };
    let du = side(nt, t[0], u);
    let dt = side(nu, u[0], t);
    // One passes through the other's plane: corners on both sides of it, beyond the
    // tolerance. Two that each lie on one side of the other's plane and meet only within
    // the tolerance (a fan round a vertex, its f32 corners a hair from flat) do not cross.
    let straddles = |d: [f64; 3]| d.iter().any(|&x| x > 0.0) && d.iter().any(|&x| x < 0.0);
    let flat = |d: [f64; 3]| d.iter().all(|&x| x == 0.0);
    if !straddles(du) && !straddles(dt) || flat(du) || flat(dt) {
        return None;
    }
    let along = nt.cross(nu).try_normalize()?;
    let (a, b) = (span(t, dt, along)?, span(u, du, along)?);
    // The overlap of the two intervals, each end taken from the triangle that bounds it.
    let start = if a.0 .0 >= b.0 .0 { a.0 } else { b.0 };
    let end = if a.1 .0 <= b.1 .0 { a.1 } else { b.1 };
    (end.0 - start.0 > tolerance).then_some([start.1, end.1])
}

/// A triangle's unit normal, none for a degenerate one.
fn plane(p: [DVec3; 3]) -> Option<DVec3> {
    (p[1] - p[0]).cross(p[2] - p[0]).try_normalize()
}

/// Where triangle `p`, its corners at signed distances `d` from another plane, meets that
/// plane: the interval of positions along `along`, each end with its point (none when it
/// does not meet it).
#[allow(clippy::type_complexity)]
fn span(p: [DVec3; 3], d: [f64; 3], along: DVec3) -> Option<((f64, DVec3), (f64, DVec3))> {
    let mut lo = (f64::INFINITY, DVec3::ZERO);
    let mut hi = (f64::NEG_INFINITY, DVec3::ZERO);
    let mut take = |q: DVec3| {
        let s = along.dot(q);
        if s < lo.0 {
            lo = (s, q);
        }
        if s > hi.0 {
            hi = (s, q);
        }
    };
    for i in 0..3 {
        let j = (i + 1) % 3;
        if d[i] == 0.0 {
            take(p[i]);
        }
        if d[i] * d[j] < 0.0 {
            take(p[i] + (p[j] - p[i]) * (d[i] / (d[i] - d[j])));
        }
    }
    (lo.0 <= hi.0).then_some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube's 12 triangles (`procedural::cube`) at `centre`, `half` its half size.
    fn box_mesh(centre: Vec3, half: f32, positions: &mut Vec<Vec3>, triangles: &mut Vec<[u32; 3]>) {
        let cube = crate::mesh::cube(12).unwrap();
        let base = positions.len() as u32;
        positions.extend(cube.positions().iter().map(|&p| centre + half * p));
        triangles.extend(cube.triangles().iter().map(|t| t.map(|v| v + base)));
    }

    /// Whether the linear test proves `mesh` free of crossings.
    fn proved_apart(mesh: &crate::Mesh) -> bool {
        mesh.star_centre().is_some()
            && closed_and_oriented(mesh.triangles(), mesh.welded(), mesh.edge_neighbours())
    }

    /// `mesh` with its positions moved by `f` (same triangles).
    fn moved(mesh: &crate::Mesh, f: impl Fn(usize, Vec3) -> Vec3) -> crate::Mesh {
        let positions = mesh
            .positions()
            .iter()
            .enumerate()
            .map(|(i, &p)| f(i, p))
            .collect();
        crate::Mesh::new(positions, None, mesh.triangles().to_vec(), None).unwrap()
    }

    #[test]
    fn closed_star_shaped_surfaces_are_proved_not_to_cross_themselves() {
        let sphere = crate::mesh::sphere(2000).unwrap();
        // Lumpy: every vertex's radius changed, still seen whole from the centre.
        let lumpy = moved(&sphere, |i, p| {
            p * (1.0 + 0.3 * ((i * 7919 % 101) as f32 / 101.0))
        });
        // Inside out: every triangle wound the other way.
        let flipped = crate::Mesh::new(
            sphere.positions().to_vec(),
            None,
            sphere
                .triangles()
                .iter()
                .map(|&[a, b, c]| [a, c, b])
                .collect(),
            None,
        )
        .unwrap();
        let cube = crate::mesh::cube(1200).unwrap();
        // Stretched far off the origin: seen from its own centre.
        let far = moved(&cube, |_, p| {
            p * Vec3::new(3.0, 0.2, 1.0) + Vec3::splat(1e3)
        });
        for (name, mesh) in [
            ("sphere", &sphere),
            ("lumpy", &lumpy),
            ("flipped", &flipped),
            ("cube", &cube),
            ("far", &far),
        ] {
            assert!(proved_apart(mesh), "{name}");
            // The pairwise search agrees.
            assert!(
                crossings(mesh.positions(), mesh.triangles()).is_empty(),
                "{name}"
            );
            assert!(mesh.intersections().is_empty(), "{name}");
        }
    }

    #[test]
    fn the_linear_test_proves_nothing_it_cannot() {
        let sphere = crate::mesh::sphere(2000).unwrap();
        // Two spheres, one inside the other: apart, but each direction is covered twice.
        let (mut positions, mut triangles) =
            (sphere.positions().to_vec(), sphere.triangles().to_vec());
        let base = positions.len() as u32;
        positions.extend(sphere.positions().iter().map(|&p| 0.5 * p));
        triangles.extend(sphere.triangles().iter().map(|t| t.map(|v| v + base)));
        let nested = crate::Mesh::new(positions, None, triangles, None).unwrap();
        assert!(nested.star_centre().is_none());
        assert!(nested.intersections().is_empty());
        // A pole pushed through the far side: the surface crosses itself, and the faces
        // around the pole turn to face the centre.
        let top = (0..sphere.positions().len())
            .max_by(|&a, &b| sphere.positions()[a].y.total_cmp(&sphere.positions()[b].y))
            .unwrap();
        let pushed = moved(&sphere, |i, p| {
            if i == top {
                Vec3::new(0.0, -1.5, 0.0)
            } else {
                p
            }
        });
        assert!(!proved_apart(&pushed));
        assert!(!pushed.intersections().is_empty());
        // Open (a triangle taken out): not closed, whatever it is seen from.
        let open = crate::Mesh::new(
            sphere.positions().to_vec(),
            None,
            sphere.triangles()[1..].to_vec(),
            None,
        )
        .unwrap();
        assert!(open.star_centre().is_some() && !proved_apart(&open));
        // A torus: no point sees every face alike.
        assert!(crate::mesh::torus(2000).unwrap().star_centre().is_none());
    }

    #[test]
    fn a_closed_box_does_not_cross_itself() {
        let (mut p, mut t) = (Vec::new(), Vec::new());
        box_mesh(Vec3::ZERO, 1.0, &mut p, &mut t);
        assert!(crossing_triangles(&p, &t).iter().all(|&c| !c));
    }

    #[test]
    fn boxes_through_each_other_cross_where_their_faces_meet() {
        let (mut p, mut t) = (Vec::new(), Vec::new());
        box_mesh(Vec3::ZERO, 1.0, &mut p, &mut t);
        box_mesh(Vec3::new(1.5, 0.3, 0.2), 1.0, &mut p, &mut t);
        let crossing = crossing_triangles(&p, &t);
        // The first box's +x face (triangles 2, 3) is crossed by the second's faces, and the
        // second's -x face (its 0, 1: triangles 12, 13) by the first's.
        assert!(crossing[2] || crossing[3]);
        assert!(crossing[12] || crossing[13]);
        // The first's -x face is far from the second box.
        assert!(!crossing[0] && !crossing[1]);
        // Disjoint boxes: nothing.
        let (mut p, mut t) = (Vec::new(), Vec::new());
        box_mesh(Vec3::ZERO, 1.0, &mut p, &mut t);
        box_mesh(Vec3::new(2.5, 0.3, 0.2), 1.0, &mut p, &mut t);
        assert!(crossing_triangles(&p, &t).iter().all(|&c| !c));
    }

    /// Two boxes through each other meet along six straight pieces of their faces, 8.0
    /// long in all (worked out by hand from the boxes' faces); every segment lies on both
    /// surfaces.
    #[test]
    fn boxes_through_each_other_meet_along_their_intersection_curve() {
        let (mut p, mut t) = (Vec::new(), Vec::new());
        box_mesh(Vec3::ZERO, 1.0, &mut p, &mut t);
        // (Its corners are f32: within 1e-6 of the f64 box.)
        let (c, h) = (DVec3::new(1.5, 0.3, 0.2), 1.0);
        box_mesh(c.as_vec3(), h as f32, &mut p, &mut t);
        let found = crossings(&p, &t);
        let length: f64 = found.iter().map(|c| c.ends[0].distance(c.ends[1])).sum();
        assert!((length - 8.0).abs() < 1e-6, "{length}");
        // On a box's surface: inside or on it, and on one of its faces.
        let on_box = |q: DVec3, centre: DVec3, half: f64| {
            let r = (q - centre).abs();
            (r.max_element() - half).abs() < 1e-6
        };
        for k in &found {
            assert!(k.t < 12 && k.u >= 12, "{k:?}");
            for q in k.ends {
                assert!(on_box(q, DVec3::ZERO, 1.0) && on_box(q, c, h), "{q}");
            }
        }
    }

    /// Two surfaces' crossings are the crossings between the triangles of one and the other
    /// in the mesh of both.
    #[test]
    fn crossings_between_two_surfaces_are_those_of_the_mesh_of_both() {
        let (mut p, mut t) = (Vec::new(), Vec::new());
        box_mesh(Vec3::ZERO, 1.0, &mut p, &mut t);
        box_mesh(Vec3::new(1.5, 0.3, 0.2), 0.8, &mut p, &mut t);
        let soup = |range: std::ops::Range<usize>| -> Vec<[DVec3; 3]> {
            t[range]
                .iter()
                .map(|c| c.map(|v| p[v as usize].as_dvec3()))
                .collect()
        };
        let between = crossings_between(&soup(0..12), &soup(12..24), 1e-9);
        let mut both = crossings(&p, &t);
        for c in &mut both {
            c.u -= 12;
        }
        assert!(!between.is_empty());
        assert_eq!(between, both);
    }

    /// The grid finds what testing every pair finds, on a soup of small triangles and large
    /// ones of several sizes (some spanning more cells than the grid takes, most of them
    /// coarsening it).
    #[test]
    fn the_grid_finds_what_every_pair_finds() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f32 / (1u64 << 53) as f32
        };
        let (mut positions, mut triangles) = (Vec::new(), Vec::new());
        for k in 0..2000 {
            let scale = match k % 10 {
                0 => 0.5,
                1 => 0.1,
                2 | 3 => 0.04,
                _ => 0.01,
            };
            let centre = Vec3::new(next(), next(), next());
            let base = positions.len() as u32;
            for _ in 0..3 {
                positions.push(centre + scale * Vec3::new(next(), next(), next()));
            }
            triangles.push([base, base + 1, base + 2]);
        }
        let found = crossing_triangles(&positions, &triangles);
        let corners = |t: usize| triangles[t].map(|v| positions[v as usize].as_dvec3());
        let mut expected = vec![false; triangles.len()];
        for t in 0..triangles.len() {
            for u in t + 1..triangles.len() {
                if cross(corners(t), corners(u), 1e-9) {
                    expected[t] = true;
                    expected[u] = true;
                }
            }
        }
        let count = expected.iter().filter(|&&c| c).count();
        assert!(count > 50, "{count}");
        assert_eq!(found, expected);
    }

    /// The fan round the pole of a fine UV sphere (2 M triangles: 1,414 slices, the first
    /// ring 1e-5 below the pole), its corners rounded to f32: each triangle lies below the
    /// others' planes by less than a 1e-9 tolerance, and none passes through another.
    #[test]
    fn a_fine_fan_that_rounds_to_nearly_flat_does_not_cross_itself() {
        let slices = 1414;
        let (sin_p, cos_p) = (std::f64::consts::PI / 708.0).sin_cos();
        let mut positions = vec![Vec3::Y];
        positions.extend((0..slices).map(|j| {
            let (sin_a, cos_a) = (std::f64::consts::TAU * j as f64 / slices as f64).sin_cos();
            Vec3::new((sin_p * sin_a) as f32, cos_p as f32, (sin_p * cos_a) as f32)
        }));
        let mut triangles: Vec<[u32; 3]> = (0..slices as u32)
            .map(|j| [0, 1 + j, 1 + (j + 1) % slices as u32])
            .collect();
        // The sphere's size sets the tolerance: a triangle at its other pole.
        let south = positions.len() as u32;
        positions.extend([
            Vec3::NEG_Y,
            Vec3::new(0.01, -1.0, 0.0),
            Vec3::new(0.0, -1.0, 0.01),
        ]);
        triangles.push([south, south + 1, south + 2]);
        let corners = |t: usize| triangles[t].map(|v| positions[v as usize].as_dvec3());
        // Within the tolerance of touching: the old test took that for meeting.
        let n = (corners(0)[1] - corners(0)[0]).cross(corners(0)[2] - corners(0)[0]);
        let below = n.normalize().dot(corners(5)[1] - corners(0)[0]);
        assert!(below < 0.0 && below > -2e-9, "{below}");
        assert!(crossings(&positions, &triangles).is_empty());
    }

    /// A triangle standing on another (its edge in the other's interior) meets it along
    /// that edge, which the other passes through the plane of: a line where surfaces meet.
    /// Lifted off by more than the tolerance it meets nothing.
    #[test]
    fn a_triangle_standing_on_another_meets_it_along_its_edge() {
        let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let standing = [
            DVec3::new(0.2, 0.1, 0.0),
            DVec3::new(0.2, 0.6, 0.0),
            DVec3::new(0.3, 0.3, 1.0),
        ];
        let ends = crossing_segment(t, standing, 1e-9).unwrap();
        assert!(ends[0].distance(ends[1]) > 0.5 - 1e-12);
        assert!(cross(standing, t, 1e-9));
        assert!(!cross(t, standing.map(|p| p + DVec3::Z * 1e-6), 1e-9));
        assert!(cross(t, standing.map(|p| p - DVec3::Z * 1e-6), 1e-9));
    }

    #[test]
    fn triangles_sharing_a_corner_cross_only_when_they_pass_through_each_other() {
        let o = DVec3::ZERO;
        let t = [o, DVec3::X, DVec3::Y];
        // Touching at the corner only.
        assert!(!cross(
            t,
            [o, DVec3::new(-1.0, 0.0, 1.0), DVec3::new(0.0, -1.0, 1.0)],
            1e-9
        ));
        // Through it, from the shared corner.
        assert!(cross(
            t,
            [o, DVec3::new(1.0, 1.0, 1.0), DVec3::new(1.0, 1.0, -1.0)],
            1e-9
        ));
        // Coplanar and overlapping: not a crossing.
        assert!(!cross(
            t,
            [o, DVec3::new(0.5, 0.0, 0.0), DVec3::new(0.0, 0.5, 0.0)],
            1e-9
        ));
        // A triangle piercing another's middle.
        let pierce = [
            DVec3::new(0.2, 0.2, -1.0),
            DVec3::new(0.3, 0.2, 1.0),
            DVec3::new(0.2, 0.3, 1.0),
        ];
        assert!(cross(t, pierce, 1e-9));
        assert!(cross(pierce, t, 1e-9));
    }
}
