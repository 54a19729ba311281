//! Edge adjacency: which triangle lies across each triangle edge. Vertices are welded by
//! exact position first, so split normals or texture seams do not cut the surface apart.

use crate::mesh::par::*;

/// Marks an edge with no unique neighbour: a boundary, or an edge shared by three or more
/// triangles (non-manifold).
pub const NO_NEIGHBOUR: u32 = u32::MAX;

/// The fold bound code meaning "may be a silhouette from any view".
pub const ANY_FOLD: u8 = 15;

/// Added to every [`fold_bound`]: a triangle seen within `edge_math::EDGE_ON` of edge-on
/// counts as folded, so each of its edges is an outline however flat the surface.
pub const EDGE_ON_MARGIN: f64 = 2e-5;

/// The bound on sin(fold) that code `q` of [`outline_hints`] stands for: 0 for flat, then
/// powers of two from 2⁻¹³ to 1, and above 1 (never skip) for [`ANY_FOLD`]; with a 1 %
/// and 10⁻⁶ margin for f32 rounding, and [`EDGE_ON_MARGIN`]. Twin of the decoding in
/// trace.wgsl.
pub fn fold_bound(q: u8) -> f64 {
    match q {
        0 => 1e-6 + EDGE_ON_MARGIN,
        ANY_FOLD.. => 2.0,
        _ => (f64::from(q) - 14.0).exp2() * 1.01 + 1e-6 + EDGE_ON_MARGIN,
    }
}

/// Per triangle, `(q << 1) | boundary` (see `Mesh::outline_hints`). The fold of an edge is
/// how far its two triangles are from lying flat, π minus the angle between them around the
/// edge, whatever their winding. If a triangle's plane is seen at an angle α (from the eye)
/// greater than its edges' largest fold φ, every neighbour stays on the far side of the plane
/// through the eye and the shared edge, so no edge is a silhouette (`is_silhouette`). q is
/// the smallest code with 2^(q − 14) ≥ sin φ (0 when flat), or [`ANY_FOLD`] for folds of 90°
/// or more and for degenerate triangles. Powers of two keep the bound within 2× of the fold
/// on smooth meshes, where folds are tiny.
pub fn outline_hints(
    positions: &[glam::Vec3],
    triangles: &[[u32; 3]],
    neighbours: &[[u32; 3]],
) -> Vec<u8> {
    let corner = |t: u32, k: usize| positions[triangles[t as usize][k % 3] as usize].as_dvec3();
    (0..triangles.len() as u32)
        .into_par_iter()
        .map(|t| {
            let mut boundary = false;
            let mut sin_fold: f64 = 0.0;
            for (i, &n) in neighbours[t as usize].iter().enumerate() {
                if n == NO_NEIGHBOUR {
                    boundary = true;
                    continue;
                }
                let (a, b) = (corner(t, i), corner(t, i + 1));
                let centroid = (corner(n, 0) + corner(n, 1) + corner(n, 2)) / 3.0;
                let along = (b - a).normalize_or_zero();
                let across = |p: glam::DVec3| {
                    let v = p - a;
                    (v - along * v.dot(along)).normalize_or_zero()
                };
                let (own, other) = (across(corner(t, i + 2)), across(centroid));
                // Flat: the two point opposite ways (cos = -1, fold 0).
                let cos_fold = -own.dot(other);
                let degenerate = own == glam::DVec3::ZERO || other == glam::DVec3::ZERO;
                // Degenerate triangles, and folds of 90° or more, are never skipped.
                sin_fold = if degenerate || cos_fold <= 0.0 {
                    1.0
                } else {
                    sin_fold.max((1.0 - cos_fold * cos_fold).max(0.0).sqrt())
                };
                if sin_fold >= 1.0 {
                    break;
                }
            }
            let q = if sin_fold == 0.0 {
                0
            } else if sin_fold >= 1.0 {
                ANY_FOLD
            } else {
                (sin_fold.log2().ceil() + 14.0).clamp(1.0, 14.0) as u8
            };
            (q << 1) | u8::from(boundary)
        })
        .collect()
}

/// For each triangle, the triangle across each of its edges (edge `i` runs from corner `i`
/// to corner `i + 1`), or [`NO_NEIGHBOUR`].
pub fn edge_neighbours(positions: &[glam::Vec3], triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    welded_neighbours(&weld_by_position(positions), triangles)
}

/// [`edge_neighbours`] with the vertices already welded (`weld`, [`weld_by_position`]).
pub fn welded_neighbours(weld: &[u32], triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    // One entry per half-edge: (undirected welded edge key, triangle * 3 + edge). Sorting
    // by key groups the two sides of each edge; a sort scales to tens of millions of edges
    // with far less memory than a hash map. Made from an indexed range, the list is
    // allocated once at its size (a flat map's collect grows it by copying).
    let mut half_edges: Vec<(u64, u32)> = (0..triangles.len() * 3)
        .into_par_iter()
        .map(|h| {
            let tri = triangles[h / 3];
            let (a, b) = (weld[tri[h % 3] as usize], weld[tri[(h + 1) % 3] as usize]);
            let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
            (key, h as u32)
        })
        .collect();
    half_edges.par_sort_unstable();

    // The sides of an edge are paired where its key appears exactly twice; a degenerate
    // edge (both ends welded together) has no neighbour either.
    let mut neighbours = vec![[NO_NEIGHBOUR; 3]; triangles.len()];
    let key = |k: usize| half_edges.get(k).map(|h| h.0);
    in_blocks(half_edges.len(), |range| {
        for k in range {
            let (h, next) = (half_edges[k], key(k + 1));
            let first = k == 0 || key(k - 1) != Some(h.0);
            let degenerate = (h.0 >> 32) == (h.0 & 0xffff_ffff);
            if first && next == Some(h.0) && key(k + 2) != Some(h.0) && !degenerate {
                let (a, b) = (h.1, half_edges[k + 1].1);
                neighbours[(a / 3) as usize][(a % 3) as usize] = b / 3;
                neighbours[(b / 3) as usize][(b % 3) as usize] = a / 3;
            }
        }
    });
    neighbours
}

/// Maps every vertex to the first vertex with bit-identical coordinates (−0.0 equals 0.0).
pub fn weld_by_position(positions: &[glam::Vec3]) -> Vec<u32> {
    // Sorted by coordinates' bits, then by index, each run of one position points at its
    // first vertex: a parallel sort, where a hash map of a million positions is serial.
    let key = |i: usize| {
        (positions[i] + glam::Vec3::ZERO)
            .to_array()
            .map(f32::to_bits)
    };
    let mut order: Vec<u32> = (0..positions.len() as u32).collect();
    order.par_sort_unstable_by_key(|&i| (key(i as usize), i));
    let mut weld = vec![0u32; positions.len()];
    let mut first = 0;
    in_blocks(order.len(), |range| {
        for k in range {
            let i = order[k];
            if k == 0 || key(i as usize) != key(order[k - 1] as usize) {
                first = i;
            }
            weld[i as usize] = first;
        }
    });
    weld
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn quad_with_split_vertices_is_connected() {
        // Two triangles sharing the diagonal, with the shared corners duplicated.
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let n = edge_neighbours(&p, &[[0, 1, 2], [3, 4, 5]]);
        assert_eq!(n[0], [NO_NEIGHBOUR, NO_NEIGHBOUR, 1]);
        assert_eq!(n[1], [0, NO_NEIGHBOUR, NO_NEIGHBOUR]);
    }

    #[test]
    fn non_manifold_edges_have_no_neighbour() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z];
        let n = edge_neighbours(&p, &[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        assert!(n.iter().all(|t| t[0] == NO_NEIGHBOUR));
    }

    #[test]
    fn closed_sphere_has_every_edge_paired() {
        let m = crate::mesh::sphere(500).unwrap();
        let n = edge_neighbours(m.positions(), m.triangles());
        for (t, across) in n.iter().enumerate() {
            for &u in across {
                assert_ne!(u, NO_NEIGHBOUR, "triangle {t} has a boundary edge");
                assert!(n[u as usize].contains(&(t as u32)));
            }
        }
    }
}
