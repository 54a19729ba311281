//! Edge adjacency: which triangle lies across each triangle edge. Vertices are welded by
//! exact position first, so split normals or texture seams do not cut the surface apart.

use rayon::prelude::*;
use std::collections::HashMap;

/// Marks an edge with no unique neighbour: a boundary, or an edge shared by three or more
/// triangles (non-manifold).
pub const NO_NEIGHBOUR: u32 = u32::MAX;

/// For each triangle, the triangle across each of its edges (edge `i` runs from corner `i`
/// to corner `i + 1`), or [`NO_NEIGHBOUR`].
pub fn edge_neighbours(positions: &[glam::Vec3], triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let weld = weld_by_position(positions);
    // One entry per half-edge: (undirected welded edge key, triangle * 3 + edge). Sorting
    // by key groups the two sides of each edge; a sort scales to tens of millions of edges
    // with far less memory than a hash map.
    let mut half_edges: Vec<(u64, u32)> = triangles
        .par_iter()
        .enumerate()
        .flat_map_iter(|(t, tri)| {
            let w = tri.map(|v| weld[v as usize]);
            (0..3).map(move |i| {
                let (a, b) = (w[i], w[(i + 1) % 3]);
                let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
                (key, (t * 3 + i) as u32)
            })
        })
        .collect();
    half_edges.par_sort_unstable();

    let mut neighbours = vec![[NO_NEIGHBOUR; 3]; triangles.len()];
    let mut start = 0;
    while start < half_edges.len() {
        let key = half_edges[start].0;
        let mut end = start + 1;
        while end < half_edges.len() && half_edges[end].0 == key {
            end += 1;
        }
        // A degenerate edge (both ends welded together) has no neighbour either.
        let degenerate = (key >> 32) == (key & 0xffff_ffff);
        if end - start == 2 && !degenerate {
            let (a, b) = (half_edges[start].1, half_edges[start + 1].1);
            neighbours[(a / 3) as usize][(a % 3) as usize] = b / 3;
            neighbours[(b / 3) as usize][(b % 3) as usize] = a / 3;
        }
        start = end;
    }
    neighbours
}

/// Maps every vertex to the first vertex with bit-identical coordinates (−0.0 equals 0.0).
pub fn weld_by_position(positions: &[glam::Vec3]) -> Vec<u32> {
    let mut first: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len());
    positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let key = (*p + glam::Vec3::ZERO).to_array().map(f32::to_bits);
            *first.entry(key).or_insert(i as u32)
        })
        .collect()
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
