//! Chains of drawn edges, along which a line pattern (the dashes of hidden lines) runs on
//! without restarting at each vertex: a crease or a circle made of many short edges dashes
//! evenly.
//!
//! A chain is a maximal run of drawn edges joined at vertices where exactly two drawn edge
//! ends meet (vertices welded by position, as the adjacency welds them); it ends at a vertex
//! where one, three or more meet, or closes on itself. Its direction and start depend on the
//! geometry alone, not on vertex or triangle numbering: an open chain starts at whichever end
//! comes first in (x, y, z) order; a closed one at its vertex that comes first, running
//! towards that vertex's neighbour that comes first. The pattern's position at a point is the
//! projected length of the chain before it (each edge's projection in front of the near
//! plane and not beyond the far one), so the GPU pass and the ground truth sum the same
//! lengths, each in its own precision.

use glam::Vec3;

/// One drawn edge of a chain: edge `i` of triangle `t` (from corner `i` to corner `i + 1`),
/// which the chain runs along from corner `i` (`forward`) or from corner `i + 1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChainEdge {
    pub t: u32,
    pub i: u8,
    pub forward: bool,
}

/// The chains of a set of drawn edges: chain `k` is `edges[starts[k]..starts[k + 1]]` (the
/// last one runs to the end), each in order from the chain's start.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Chains {
    pub edges: Vec<ChainEdge>,
    pub starts: Vec<u32>,
}

impl Chains {
    /// The chains, each a slice of edges in order.
    pub fn iter(&self) -> impl Iterator<Item = &[ChainEdge]> + '_ {
        let ends = self.starts.iter().skip(1).copied();
        let ends = ends.chain(std::iter::once(self.edges.len() as u32));
        self.starts
            .iter()
            .zip(ends)
            .map(|(&s, e)| &self.edges[s as usize..e as usize])
    }
}

/// Whether `a` comes before `b` in (x, y, z) order: the rule that picks the end of an edge,
/// or of a chain, its line pattern starts from.
pub fn comes_first(a: Vec3, b: Vec3) -> bool {
    a.x < b.x || (a.x == b.x && (a.y < b.y || (a.y == b.y && a.z < b.z)))
}

/// The chains of `listed`, each listed edge `(t, i)` of the triangles `triangles` over
/// `positions` drawn once (the caller lists each shared edge from one side); `weld` maps
/// each vertex to its welded one ([`weld_by_position`](super::adjacency::weld_by_position)).
pub fn chains(
    positions: &[Vec3],
    weld: &[u32],
    triangles: &[[u32; 3]],
    listed: &[(u32, u8)],
) -> Chains {
    let at = |v: u32| positions[v as usize];
    // Edge e's ends 2e (corner i) and 2e + 1 (corner i + 1), as welded vertices.
    let end_vertex = |end: usize| {
        let (t, i) = listed[end / 2];
        let corner = (usize::from(i) + end % 2) % 3;
        weld[triangles[t as usize][corner] as usize]
    };
    // The ends at each vertex, as compressed rows.
    let n = positions.len();
    let mut offsets = vec![0u32; n + 1];
    for end in 0..2 * listed.len() {
        offsets[end_vertex(end) as usize + 1] += 1;
    }
    for v in 0..n {
        offsets[v + 1] += offsets[v];
    }
    let mut fill = offsets.clone();
    let mut ends = vec![0u32; 2 * listed.len()];
    for end in 0..2 * listed.len() {
        let v = end_vertex(end) as usize;
        ends[fill[v] as usize] = end as u32;
        fill[v] += 1;
    }
    let degree = |v: u32| offsets[v as usize + 1] - offsets[v as usize];
    let incident = |v: u32| &ends[offsets[v as usize] as usize..offsets[v as usize + 1] as usize];

    let mut used = vec![false; listed.len()];
    // Walks from end `entry` (the end of its edge at the walk's start) while the far end's
    // vertex joins exactly two ends and the other is unused; the ends entered go to `path`.
    let walk = |entry: u32, used: &mut Vec<bool>, path: &mut Vec<u32>| {
        path.clear();
        let mut end = entry;
        loop {
            used[end as usize / 2] = true;
            path.push(end);
            let far = end ^ 1;
            let v = end_vertex(far as usize);
            if degree(v) != 2 {
                break;
            }
            let next = incident(v).iter().copied().find(|&e| e != far);
            match next {
                Some(e) if !used[e as usize / 2] => end = e,
                _ => break,
            }
        }
    };
    // A path as entered ends; reversed, each edge is entered at its other end.
    let first_vertex = |path: &[u32]| at(end_vertex(path[0] as usize));
    let second_vertex = |path: &[u32]| at(end_vertex(path[0] as usize ^ 1));
    let reverse = |path: &[u32], back: &mut Vec<u32>| {
        back.clear();
        back.extend(path.iter().rev().map(|&e| e ^ 1));
    };
    let mut out = Chains::default();
    let push = |path: &[u32], out: &mut Chains| {
        out.starts.push(out.edges.len() as u32);
        out.edges.extend(path.iter().map(|&end| {
            let (t, i) = listed[end as usize / 2];
            ChainEdge {
                t,
                i,
                forward: end % 2 == 0,
            }
        }));
    };
    // One pair of buffers for every walk: most chains of a dense mesh are one edge long.
    let (mut path, mut back) = (Vec::new(), Vec::new());

    // Open chains: from every vertex where other than two ends meet.
    for v in 0..n as u32 {
        if weld[v as usize] != v || degree(v) == 2 {
            continue;
        }
        for k in 0..degree(v) as usize {
            let end = incident(v)[k];
            if used[end as usize / 2] {
                continue;
            }
            walk(end, &mut used, &mut path);
            reverse(&path, &mut back);
            let (a, b) = (first_vertex(&path), first_vertex(&back));
            // From the end that comes first; a chain from a vertex back to it runs towards
            // the nearer neighbour that comes first.
            let flip = comes_first(b, a)
                || (a == b && comes_first(second_vertex(&back), second_vertex(&path)));
            push(if flip { &back } else { &path }, &mut out);
        }
    }
    // What is left is closed loops through vertices of two ends each.
    for e in 0..listed.len() {
        if used[e] {
            continue;
        }
        walk(2 * e as u32, &mut used, &mut path);
        // Start at the vertex that comes first, towards its neighbour that comes first.
        let start = (0..path.len())
            .min_by(|&j, &k| {
                let (a, b) = (first_vertex(&path[j..]), first_vertex(&path[k..]));
                if comes_first(a, b) {
                    std::cmp::Ordering::Less
                } else if comes_first(b, a) {
                    std::cmp::Ordering::Greater
                } else {
                    std::cmp::Ordering::Equal
                }
            })
            .unwrap_or(0);
        path.rotate_left(start);
        // The other way round from the same start.
        reverse(&path, &mut back);
        if comes_first(second_vertex(&back), second_vertex(&path)) {
            push(&back, &mut out);
        } else {
            push(&path, &mut out);
        }
    }
    out
}

#[cfg(any(feature = "truth", feature = "drawing"))]
/// The chains of directed edges `ends` (each `(start, end)`, welded vertices), as lists of
/// edge indices in order: an edge runs on into the edge that starts where it ends when
/// exactly one edge starts there and exactly one ends there. An open chain starts at its
/// first edge; a closed one at its edge with the least key (`keys`, unique within a chain). The outline
/// chains, along which an outline's hidden-line pattern runs (`outline_chain_ends` in
/// trace.wgsl finds the same on the GPU each frame, as the outline depends on the view).
pub fn directed_chains(ends: &[(u32, u32)], keys: &[u32]) -> Vec<Vec<usize>> {
    use std::collections::HashMap;
    // Per vertex: edges ending there, edges starting there, the first of each.
    let mut at: HashMap<u32, (u32, u32, usize, usize)> = HashMap::new();
    for (e, &(start, end)) in ends.iter().enumerate() {
        let s = at.entry(start).or_insert((0, 0, e, e));
        if s.1 == 0 {
            s.3 = e;
        }
        s.1 += 1;
        let v = at.entry(end).or_insert((0, 0, e, e));
        if v.0 == 0 {
            v.2 = e;
        }
        v.0 += 1;
    }
    let next = |e: usize| -> Option<usize> {
        let &(ins, outs, _, out) = at.get(&ends[e].1)?;
        (ins == 1 && outs == 1 && out != e).then_some(out)
    };
    let has_before = |e: usize| {
        let (ins, outs, first_in, _) = at[&ends[e].0];
        ins == 1 && outs == 1 && first_in != e
    };
    let mut used = vec![false; ends.len()];
    let mut out = Vec::new();
    let walk = |first: usize, used: &mut Vec<bool>| {
        let mut chain = vec![first];
        used[first] = true;
        let mut e = first;
        while let Some(n) = next(e).filter(|&n| !used[n]) {
            used[n] = true;
            chain.push(n);
            e = n;
        }
        chain
    };
    for e in 0..ends.len() {
        if !has_before(e) {
            let chain = walk(e, &mut used);
            out.push(chain);
        }
    }
    for e in 0..ends.len() {
        if !used[e] {
            let mut chain = walk(e, &mut used);
            let head = (0..chain.len())
                .min_by_key(|&k| keys[chain[k]])
                .unwrap_or(0);
            chain.rotate_left(head);
            out.push(chain);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{EdgeSelection, Mesh};

    /// The listed edges of `mesh` under `edges`, each shared one from its lower triangle.
    fn listed(mesh: &Mesh, edges: EdgeSelection) -> Vec<(u32, u8)> {
        let mask = mesh.edge_mask(edges);
        let neighbours = mesh.edge_neighbours();
        let mut out = Vec::new();
        for t in 0..mesh.triangle_count() {
            for i in 0..3u8 {
                let n = neighbours[t][i as usize];
                let mine = n == crate::mesh::adjacency::NO_NEIGHBOUR || (t as u32) < n;
                if mask[t] & (1 << i) != 0 && mine {
                    out.push((t as u32, i));
                }
            }
        }
        out
    }

    fn weld_of(mesh: &Mesh) -> Vec<u32> {
        crate::mesh::adjacency::weld_by_position(mesh.positions())
    }

    /// The chain's vertices in order, by position.
    fn walk_of(mesh: &Mesh, chain: &[ChainEdge]) -> Vec<Vec3> {
        let p = |e: &ChainEdge, end: usize| {
            let corner = (usize::from(e.i) + end) % 3;
            mesh.positions()[mesh.triangles()[e.t as usize][corner] as usize]
        };
        let mut out = vec![p(&chain[0], usize::from(!chain[0].forward))];
        for e in chain {
            let (from, to) = (p(e, usize::from(!e.forward)), p(e, usize::from(e.forward)));
            assert_eq!(from, *out.last().unwrap(), "the chain is connected");
            out.push(to);
        }
        out
    }

    /// A flat disc of `n` rim vertices around a centre, fanned.
    fn disc(n: u32, first: u32) -> Mesh {
        let mut p = vec![Vec3::ZERO];
        p.extend((0..n).map(|k| {
            let a = (k + first) as f32 / n as f32 * std::f32::consts::TAU;
            Vec3::new(a.cos(), a.sin(), 0.0)
        }));
        let tris = (0..n).map(|k| [0, 1 + k, 1 + (k + 1) % n]).collect();
        Mesh::new(p, None, tris, None).unwrap()
    }

    #[cfg(any(feature = "truth", feature = "drawing"))]
    #[test]
    fn directed_chains_close_at_their_least_key_and_break_where_ends_do_not_pair() {
        // A loop 0 -> 1 -> 2 -> 0 (keys 5, 3, 9) and a path 3 -> 4 -> 5 -> 6 whose middle
        // vertex 5 has a second edge starting there (5 -> 7).
        let ends = [(0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 6), (5, 7)];
        let keys = [5, 3, 9, 10, 11, 12, 13];
        let mut chains = directed_chains(&ends, &keys);
        chains.sort();
        assert_eq!(chains, vec![vec![1, 2, 0], vec![3, 4], vec![5], vec![6]]);
    }

    #[test]
    fn a_circle_of_short_edges_is_one_closed_chain() {
        for first in [0, 7] {
            let mesh = disc(48, first);
            let c = chains(
                mesh.positions(),
                &weld_of(&mesh),
                mesh.triangles(),
                &listed(&mesh, EdgeSelection::Feature(30.0)),
            );
            assert_eq!(c.starts, vec![0]);
            assert_eq!(c.edges.len(), 48);
            let walk = walk_of(&mesh, &c.edges);
            assert_eq!(walk[0], walk[48], "closed");
            // Starts at the vertex that comes first, towards its neighbour that comes first.
            assert!(mesh.positions().iter().all(|&q| !comes_first(q, walk[0])));
            assert!(comes_first(walk[1], walk[47]));
            // The same chain whatever the numbering.
            let other = disc(48, 0);
            let o = chains(
                other.positions(),
                &weld_of(&other),
                other.triangles(),
                &listed(&other, EdgeSelection::Feature(30.0)),
            );
            let w: Vec<Vec3> = walk_of(&other, &o.edges);
            for (a, b) in walk.iter().zip(&w) {
                assert!(a.distance(*b) < 1e-6, "{a} {b}");
            }
        }
    }

    #[test]
    fn chains_end_where_three_edges_meet() {
        // A cube's feature edges: twelve chains of one edge, each from its end that comes
        // first.
        let mesh = crate::mesh::cube(12).unwrap();
        let c = chains(
            mesh.positions(),
            &weld_of(&mesh),
            mesh.triangles(),
            &listed(&mesh, EdgeSelection::Feature(30.0)),
        );
        assert_eq!(c.edges.len(), 12);
        assert_eq!(c.starts.len(), 12);
        for chain in c.iter() {
            let w = walk_of(&mesh, chain);
            assert!(comes_first(w[0], w[1]), "{w:?}");
        }
    }

    #[test]
    fn an_open_polyline_starts_at_its_end_that_comes_first() {
        // The far side of a fan: five edges in a row.
        let mut p = vec![Vec3::ZERO];
        p.extend((0..6).map(|k| Vec3::new(k as f32 * 0.2 - 0.5, 1.0, 0.0)));
        let tris: Vec<[u32; 3]> = (0..5).map(|k| [0, k + 1, k + 2]).collect();
        let mesh = Mesh::new(p, None, tris, None).unwrap();
        // Only the far side: edge 1 of every triangle.
        let far: Vec<(u32, u8)> = (0..5).map(|t| (t, 1)).collect();
        // Listed in any order, the chain is the same.
        for order in [far.clone(), far.iter().rev().copied().collect()] {
            let c = chains(mesh.positions(), &weld_of(&mesh), mesh.triangles(), &order);
            assert_eq!(c.starts, vec![0]);
            let w = walk_of(&mesh, &c.edges);
            assert_eq!(w.len(), 6);
            assert!(w.windows(2).all(|s| s[0].x < s[1].x), "{w:?}");
        }
    }
}
