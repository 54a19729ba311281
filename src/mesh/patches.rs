//! Patches: the regions of a surface that its undrawn edges join. A pixel's nearest line may
//! belong to another triangle of its patch (the far side of a quad across its diagonal, a
//! crease a few sub-pixel triangles away), never to a triangle beyond a drawn edge of it, so
//! the patch bounds the search for it. Small patches (polygons: a quad is two triangles) are
//! searched per pixel by the edge pass; the drawn edges of large ones (the faces of a
//! tessellated CAD part in feature mode) are drawn by the trace pass into every pixel in
//! reach, like outlines, and so are those of patches that cross another surface
//! ([`super::crossings`]), whose lines may be hidden next to their visible pixels.

use super::adjacency::NO_NEIGHBOUR;

/// Most triangles in a patch that the edge pass searches per pixel: a polygon of up to 18
/// sides. Larger patches have their drawn edges drawn by the trace pass. Twin of
/// `PATCH_TRIANGLES` in edge_pass.wgsl.
pub const PATCH_TRIANGLES: usize = 16;

/// A mesh's patches under one edge mask, as the passes use them.
#[derive(Clone, Debug, Default)]
pub struct Patches {
    /// Per triangle, whether its patch has more than [`PATCH_TRIANGLES`] triangles or is
    /// [`Patches::crossed`]: its drawn edges are drawn by the trace pass.
    pub large: Vec<bool>,
    /// Per triangle, whether a triangle of its patch crosses another surface of the mesh: its
    /// pixels take no line of their own, only the trace pass's, drawn where visible.
    pub crossed: Vec<bool>,
    /// Per triangle, how many triangles its patch has (the triangles joined to it across
    /// undrawn edges, an edge counting as undrawn when either side leaves it out), counted
    /// up to [`PATCH_TRIANGLES`] + 1.
    pub size: Vec<u8>,
    /// Per triangle, the drawn edges the trace pass draws ([`splat_edges`]).
    pub splat: Vec<u8>,
}

impl Patches {
    /// The patches of a mesh with edge neighbours `neighbours` under `mask`, `crossing` its
    /// triangles that cross others ([`super::crossings::crossing_triangles`]); an edge both
    /// sides draw is splatted from the side with the lower id.
    pub fn new(neighbours: &[[u32; 3]], mask: &[u8], crossing: &[bool]) -> Patches {
        Patches::ordered(neighbours, mask, crossing, |t, u| t < u)
    }

    /// [`Patches::new`], splatting an edge both sides draw from side `t` where `before(t, u)`
    /// (see [`splat_edges`]).
    pub fn ordered(
        neighbours: &[[u32; 3]],
        mask: &[u8],
        crossing: &[bool],
        before: impl Fn(usize, usize) -> bool,
    ) -> Patches {
        let roots = patch_roots(neighbours, mask);
        let mut count = vec![0u32; roots.len()];
        let mut crossed_root = vec![false; roots.len()];
        for (t, &r) in roots.iter().enumerate() {
            count[r as usize] += 1;
            crossed_root[r as usize] |= crossing[t];
        }
        let size: Vec<u8> = roots
            .iter()
            .map(|&r| count[r as usize].min(PATCH_TRIANGLES as u32 + 1) as u8)
            .collect();
        let crossed: Vec<bool> = roots.iter().map(|&r| crossed_root[r as usize]).collect();
        let large: Vec<bool> = size
            .iter()
            .zip(&crossed)
            .map(|(&n, &c)| usize::from(n) > PATCH_TRIANGLES || c)
            .collect();
        let splat = splat_edges(neighbours, mask, &large, before);
        Patches {
            large,
            crossed,
            size,
            splat,
        }
    }
}

/// Per triangle, the lowest triangle of its patch (the triangles joined to it across undrawn
/// edges, an edge counting as undrawn when either side leaves it out).
fn patch_roots(neighbours: &[[u32; 3]], mask: &[u8]) -> Vec<u32> {
    let n = neighbours.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut t: u32) -> u32 {
        while parent[t as usize] != t {
            let up = parent[parent[t as usize] as usize];
            parent[t as usize] = up;
            t = up;
        }
        t
    }
    for (t, across) in neighbours.iter().enumerate() {
        for (i, &u) in across.iter().enumerate() {
            if mask[t] & (1 << i) == 0 && u != NO_NEIGHBOUR {
                let (a, b) = (root(&mut parent, t as u32), root(&mut parent, u));
                if a != b {
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
    }
    (0..n as u32).map(|t| root(&mut parent, t)).collect()
}

/// Per triangle, the drawn edges (bit `i` for edge `i`) that the trace pass draws because a
/// large patch lies on one side: each such edge once, from side `t` where `before(t, u)`
/// when both sides draw it. The GPU's trace pass orders triangles as it stores them, so
/// that an edge that is also a silhouette is drawn once, by the side that draws the
/// silhouette.
pub fn splat_edges(
    neighbours: &[[u32; 3]],
    mask: &[u8],
    large: &[bool],
    before: impl Fn(usize, usize) -> bool,
) -> Vec<u8> {
    neighbours
        .iter()
        .enumerate()
        .map(|(t, across)| {
            let mut bits = 0;
            for (i, &u) in across.iter().enumerate() {
                if mask[t] & (1 << i) == 0 {
                    continue;
                }
                let other = (u != NO_NEIGHBOUR).then_some(u as usize);
                if !large[t] && !other.is_some_and(|u| large[u]) {
                    continue;
                }
                let drawn_there = other.is_some_and(|u| {
                    neighbours[u]
                        .iter()
                        .enumerate()
                        .any(|(j, &back)| back == t as u32 && mask[u] & (1 << j) != 0)
                });
                if !drawn_there || other.is_some_and(|u| before(t, u)) {
                    bits |= 1 << i;
                }
            }
            bits
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of `n` triangles, each joined to the next across edge 1 (and from it across
    /// edge 2); `cut` says which joins are drawn.
    fn strip(n: usize) -> Vec<[u32; 3]> {
        (0..n)
            .map(|t| {
                let next = if t + 1 < n {
                    t as u32 + 1
                } else {
                    NO_NEIGHBOUR
                };
                let prev = if t > 0 { t as u32 - 1 } else { NO_NEIGHBOUR };
                [NO_NEIGHBOUR, next, prev]
            })
            .collect()
    }

    #[test]
    fn patches_join_across_undrawn_edges_only() {
        let n = 2 * PATCH_TRIANGLES + 4;
        let neighbours = strip(n);
        // Joins undrawn everywhere but between triangles 3 and 4.
        let mut mask = vec![0b001u8; n];
        mask[3] |= 0b010;
        mask[4] |= 0b100;
        let Patches {
            large,
            crossed,
            size,
            splat,
        } = Patches::new(&neighbours, &mask, &vec![false; n]);
        assert!(crossed.iter().all(|&c| !c));
        assert!(size[..4].iter().all(|&n| n == 4));
        assert!(size[4..]
            .iter()
            .all(|&n| usize::from(n) == PATCH_TRIANGLES + 1));
        assert!(large[..4].iter().all(|&l| !l));
        assert!(large[4..].iter().all(|&l| l));
        // The drawn join once, from the lower id; the outer sides of the large patch's
        // triangles; nothing of the small patch beyond the join.
        assert_eq!(splat[3], 0b010);
        assert_eq!(splat[4], 0b001);
        assert!(splat[..3].iter().all(|&b| b == 0));
        assert!(splat[5..].iter().all(|&b| b == 0b001));
    }

    #[test]
    fn a_side_that_leaves_an_edge_out_joins_it() {
        let neighbours = strip(PATCH_TRIANGLES + 1);
        let mut mask = vec![0b111u8; PATCH_TRIANGLES + 1];
        let none = vec![false; PATCH_TRIANGLES + 1];
        assert!(Patches::new(&neighbours, &mask, &none)
            .large
            .iter()
            .all(|&l| !l));
        for m in &mut mask[..PATCH_TRIANGLES] {
            *m &= !0b010;
        }
        assert!(Patches::new(&neighbours, &mask, &none)
            .large
            .iter()
            .all(|&l| l));
    }

    #[test]
    fn a_crossing_triangle_marks_its_whole_patch() {
        let n = 8;
        let neighbours = strip(n);
        // Two patches, 0..4 and 4..8, joined by the drawn edge between 3 and 4.
        let mut mask = vec![0b001u8; n];
        mask[3] |= 0b010;
        mask[4] |= 0b100;
        let mut crossing = vec![false; n];
        crossing[1] = true;
        let p = Patches::new(&neighbours, &mask, &crossing);
        assert_eq!(
            p.crossed,
            [true, true, true, true, false, false, false, false]
        );
        assert_eq!(p.large, p.crossed);
        // The crossed patch's drawn edges go to the trace pass, the drawn join once.
        assert!(p.splat[..4].iter().all(|&b| b & 0b001 != 0));
        assert_eq!(p.splat[3], 0b011);
        assert_eq!(p.splat[4], 0b000);
    }
}
