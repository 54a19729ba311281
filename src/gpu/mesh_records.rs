//! How one mesh becomes the mesh store's records: positions relative to its centre and
//! scaled, packed normals, triangles in cluster order, each edge's neighbour word, and the
//! per-triangle info word (drawn edges, patches, quads) that the shaders decode. The store
//! (`mesh_store.rs`) places these records in its arena; `shaders/common.wgsl` and
//! `shaders/scene.wgsl` hold the decoding twins.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::mesh::par::join;
use crate::mesh::{adjacency::NO_NEIGHBOUR, patches::Patches, EdgeSelection, Mesh, ALL_EDGES};
use glam::{DVec3, Vec2, Vec3};
use std::sync::Arc;
use std::time::Duration;
use web_time::Instant;

/// What inserting a mesh into a [`MeshStore`](super::MeshStore) took, step by step
/// ([`MeshStore::upload_report`](super::MeshStore::upload_report)). A step the mesh had already done (its adjacency, say,
/// asked for before) takes no time here. The crossings are found beside the adjacency,
/// hints and clusters (on another core, with the `parallel` feature), so the steps' times
/// may add up to more than the insert's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UploadReport {
    /// Edge adjacency: the triangle across each edge, vertices welded by position.
    pub adjacency: Duration,
    /// The outline hints: how far each triangle's edges fold.
    pub outline_hints: Duration,
    /// The clusters of 64 triangles and their bounds.
    pub clusters: Duration,
    /// The triangles that cross others of the mesh, and their intersection lines.
    pub crossings: Duration,
    /// The edge selection's patches, chains and per-triangle edge data.
    pub edges: Duration,
    /// The store's records: packed vertices, triangles in cluster order, neighbour words.
    pub records: Duration,
    /// Writing the records into the store's buffers (queued, not yet on the GPU).
    pub upload: Duration,
    /// Bytes written to the GPU.
    pub gpu_bytes: u64,
}

impl UploadReport {
    /// The steps in the order an insert takes them, named as `wirepass render --timings`
    /// and the web element's timeline name them, with their times.
    pub fn steps(&self) -> [(&'static str, Duration); 7] {
        [
            ("adjacency", self.adjacency),
            ("outline hints", self.outline_hints),
            ("clusters", self.clusters),
            ("crossings", self.crossings),
            ("edges: patches, chains", self.edges),
            ("records", self.records),
            ("queue the upload", self.upload),
        ]
    }

    /// The steps' times added up.
    pub fn total(&self) -> Duration {
        self.steps().iter().map(|(_, d)| *d).sum()
    }
}

/// The packed normal of a vertex without one (a zero normal, next to degenerate triangles
/// only): both components at the snorm code that unpacking clamps, which no unit vector
/// packs to.
pub(crate) const NO_NORMAL: u32 = 0x8000_8000;

/// What a mesh's edge selection asks of the passes beyond each triangle's own edges.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct MeshLines {
    /// Some triangle of a small patch has an undrawn edge: pixels near one search their
    /// patch (`patch_distance`).
    pub small_patches: bool,
    /// Some drawn edge borders a large patch: the trace pass draws it.
    pub splat: bool,
    /// Some patch crosses another surface of the mesh ([`Patches::crossed`]).
    pub crossed: bool,
}

/// One mesh as the arena stores it.
pub(crate) struct MeshData {
    pub vertices: Vec<[f32; 4]>,
    pub indices: Arc<[[u32; 3]]>,
    /// The mesh's positions in its own coordinates.
    pub positions: Arc<[Vec3]>,
    pub neighbours: Vec<[u32; 3]>,
    pub info: Vec<u32>,
    pub clusters: Vec<[f32; 8]>,
    pub bounds_of_clusters: Arc<[[f32; 8]]>,
    pub lines: MeshLines,
    pub origin: DVec3,
    pub scale: f64,
    pub order: Arc<[u32]>,
    pub bounds: (DVec3, DVec3),
    pub chains: ChainRecords,
    pub intersections: Arc<[StoredCrossing]>,
}

/// Two triangles of a mesh that cross ([`Mesh::intersections`]) as the trace pass draws
/// their intersection line: their stored ids, and the segment's ends in stored coordinates.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StoredCrossing {
    pub t: u32,
    pub u: u32,
    pub ends: [[f32; 3]; 2],
}

impl MeshData {
    /// The records of `mesh` drawing the edges `edges`, and what each step of making them
    /// took (the upload's fields stay empty). The mesh's crossings are found while its
    /// adjacency, outline hints and clusters are made, one after the other, beside them;
    /// where the surface is star-shaped, the adjacency then shows in a moment whether it is
    /// closed, which proves that it crosses nowhere (`crossings::star_centre`).
    pub(crate) fn new(mesh: &Mesh, edges: EdgeSelection) -> (MeshData, UploadReport) {
        let timed = |f: &dyn Fn()| {
            let start = Instant::now();
            f();
            start.elapsed()
        };
        let ((adjacency, outline_hints, cluster_time), crossings) = join(
            || {
                (
                    timed(&|| {
                        mesh.edge_neighbours();
                    }),
                    timed(&|| {
                        mesh.outline_hints();
                    }),
                    timed(&|| {
                        mesh.traced_clusters();
                    }),
                )
            },
            || {
                timed(&|| {
                    // Not beside the adjacency where it would ask for it (computing it twice).
                    if mesh.star_centre().is_none() {
                        mesh.intersections();
                    }
                })
            },
        );
        let crossings = crossings
            + timed(&|| {
                mesh.intersections();
            });
        let start = Instant::now();
        let (lo, hi) = mesh.bounds_f64();
        let origin = (lo + hi) * 0.5;
        let extent = (hi - lo).max_element() * 0.5;
        // A power of two, so scaling is exact; 1 for a mesh of one point.
        let scale = if extent > 0.0 && extent.is_finite() {
            extent.log2().round().exp2()
        } else {
            1.0
        };
        let vertices = mesh
            .positions()
            .iter()
            .zip(mesh.normals())
            .map(|(p, n)| {
                let q = ((p.as_dvec3() - origin) / scale).as_vec3();
                [q.x, q.y, q.z, f32::from_bits(pack_normal(*n))]
            })
            .collect();
        let clusters = mesh.traced_clusters();
        let order: Arc<[u32]> = clusters.order.clone().into();
        let mut stored = vec![0u32; order.len()];
        for (s, &t) in order.iter().enumerate() {
            stored[t as usize] = s as u32;
        }
        let tris = mesh.triangles();
        let indices = order.iter().map(|&t| tris[t as usize]).collect();
        let across = Across::of(mesh);
        let neighbours = order
            .iter()
            .map(|&t| [0, 1, 2].map(|i| across.word(&stored, t as usize, i)))
            .collect();
        let bounds: Vec<[f32; 8]> = clusters
            .bounds
            .iter()
            .map(|c| {
                let center = (c.center - origin) / scale;
                let radius = c.radius / scale * (1.0 + 1e-6) + center.length() * 1e-6;
                let [x, y, z] = center.as_vec3().to_array();
                let [ax, ay, az] = c.axis.as_vec3().to_array();
                [x, y, z, radius as f32, ax, ay, az, c.spread as f32]
            })
            .collect();
        let bounds: Arc<[[f32; 8]]> = bounds.into();
        let mut records = start.elapsed();
        let start = Instant::now();
        let edges = EdgeData::new(mesh, edges, &order);
        let edge_time = start.elapsed();
        let start = Instant::now();
        let intersections = mesh
            .intersections()
            .iter()
            .map(|c| StoredCrossing {
                t: stored[c.t as usize],
                u: stored[c.u as usize],
                ends: c.ends.map(|p| ((p - origin) / scale).as_vec3().to_array()),
            })
            .collect();
        let data = MeshData {
            intersections,
            positions: mesh.positions().into(),
            vertices,
            indices,
            neighbours,
            clusters: cluster_records(&bounds, &edges.info),
            bounds_of_clusters: bounds,
            info: edges.info,
            lines: edges.lines,
            chains: edges.chains,
            origin,
            scale,
            order,
            bounds: (lo, hi),
        };
        records += start.elapsed();
        let report = UploadReport {
            adjacency,
            outline_hints,
            clusters: cluster_time,
            crossings,
            edges: edge_time,
            records,
            ..UploadReport::default()
        };
        (data, report)
    }
}

/// Most triangles in one mesh: a neighbour word holds the neighbour's index in 29 bits, and
/// the all-ones word means no neighbour.
pub(crate) const MAX_MESH_TRIANGLES: u32 = (1 << 29) - 1;
/// The neighbour word's bits below this hold the neighbour's stored index (relative to its
/// mesh); the next two its corner off the shared edge.
pub(crate) const NEIGHBOUR_CORNER_SHIFT: u32 = 29;
/// Bit of a neighbour word: the neighbour runs along the shared edge the same way as this
/// triangle (the two are wound oppositely); clear, the other way.
pub(crate) const NEIGHBOUR_SAME_WAY: u32 = 1 << 31;

/// What the passes read of the triangle across edge `i` of triangle `t` (`scene.wgsl`,
/// `neighbour_word`): its stored index, its corner k off the shared edge and whether its
/// corners k + 1 and k + 2 are that edge's start and end (the same way) or its end and start.
/// A step of a walk across the edge then reads one corner, not three; `u32::MAX` where there
/// is no neighbour. The shared corners are found by their welded vertices (equal
/// positions), as the adjacency pairs them.
#[cfg(test)]
fn neighbour_word(mesh: &Mesh, stored: &[u32], t: usize, i: usize) -> u32 {
    Across::of(mesh).word(stored, t, i)
}

/// What [`neighbour_word`] reads of a mesh, borrowed once for all its triangles.
struct Across<'a> {
    neighbours: &'a [[u32; 3]],
    triangles: &'a [[u32; 3]],
    weld: &'a [u32],
}

impl<'a> Across<'a> {
    fn of(mesh: &'a Mesh) -> Self {
        Across {
            neighbours: mesh.edge_neighbours(),
            triangles: mesh.triangles(),
            weld: mesh.welded(),
        }
    }

    fn word(&self, stored: &[u32], t: usize, i: usize) -> u32 {
        let n = self.neighbours[t][i];
        if n == NO_NEIGHBOUR {
            return u32::MAX;
        }
        let corner = |t: usize, i: usize| self.weld[self.triangles[t][i % 3] as usize];
        let (a, b) = (corner(t, i), corner(t, i + 1));
        let n = n as usize;
        let back = (0..3).find(|&j| {
            let (p, q) = (corner(n, j), corner(n, j + 1));
            self.neighbours[n][j] == t as u32 && ((p, q) == (a, b) || (p, q) == (b, a))
        });
        // The adjacency pairs the two sides of an edge with the same welded ends, so `back`
        // is always found; without it the edge reads as a boundary.
        let Some(j) = back else {
            return u32::MAX;
        };
        let k = (j as u32 + 2) % 3;
        let same_way = if corner(n, j) == a {
            NEIGHBOUR_SAME_WAY
        } else {
            0
        };
        stored[n] | k << NEIGHBOUR_CORNER_SHIFT | same_way
    }
}

/// Bit of [`EdgeData::info`]: the triangle's patch is large ([`Patches::large`]).
pub(crate) const INFO_LARGE_PATCH: u32 = 1 << 11;
/// First of the three bits of [`EdgeData::info`] that mark the edges the trace pass draws
/// for a large patch ([`Patches::splat`]).
pub(crate) const INFO_SPLAT_SHIFT: u32 = 12;
/// Bit of [`EdgeData::info`]: the triangle's patch crosses another surface of the mesh
/// ([`Patches::crossed`]): its pixels take their lines from the trace pass only.
pub(crate) const INFO_CROSSED: u32 = 1 << 29;
/// Bit of [`EdgeData::info`]: the triangle's patch is a quad (two triangles), which the edge
/// pass searches without a queue.
pub(crate) const INFO_QUAD: u32 = 1 << 15;

/// First bit of [`EdgeData::info`] of a quad: its diagonal (edge 0–2, two bits), then the
/// other triangle's corner off the diagonal (two bits), whether that triangle's next corner
/// is the diagonal's start (one bit) and its drawn edges (three bits): `quad_of` in
/// edge_pass.wgsl reads the other triangle from these, its id and one corner's position.
pub(crate) const QUAD_SHIFT: u32 = 16;
/// The quad's fields after [`QUAD_SHIFT`]: the other triangle's corner, whether its next
/// corner is the diagonal's start (a bit, `QUAD_SAME`), its drawn edges.
pub(crate) const QUAD_CORNER_SHIFT: u32 = QUAD_SHIFT + 2;
pub(crate) const QUAD_SAME: u32 = 1 << (QUAD_SHIFT + 4);
pub(crate) const QUAD_MASK_SHIFT: u32 = QUAD_SHIFT + 5;

/// Bits of [`EdgeData::info`] of a quad: its other triangle is stored right after this one
/// ([`QUAD_NEXT`]) or right before it ([`QUAD_PREVIOUS`]), as the cluster order keeps the
/// halves of a source quad ([`Mesh::quad_partners`]); with neither, `quad_of` reads it from
/// the adjacency.
pub(crate) const QUAD_NEXT: u32 = 1 << 24;
pub(crate) const QUAD_PREVIOUS: u32 = 1 << 25;

/// [`INFO_QUAD`] and the bits after [`QUAD_SHIFT`] for triangle `t` of a two-triangle patch
/// under edge mask `mask` (`stored` maps triangles to their stored places), or 0 (the
/// triangle is then searched as any small patch is) where the other triangle does not meet
/// it across the diagonal at bit-identical positions (so that the diagonal's ends read from
/// either triangle are the same numbers) or draws the diagonal from its side.
fn quad_bits(mesh: &Mesh, mask: &[u8], stored: &[u32], t: usize) -> u32 {
    let neighbours = mesh.edge_neighbours();
    let (tris, positions) = (mesh.triangles(), mesh.positions());
    let at = |v: u32| positions[v as usize].to_array().map(f32::to_bits);
    // The last undrawn edge with a neighbour, as the search would take it.
    let Some(e) = (0..3)
        .rev()
        .find(|&e| mask[t] & (1 << e) == 0 && neighbours[t][e] != NO_NEIGHBOUR)
    else {
        return 0;
    };
    let n = neighbours[t][e] as usize;
    let (a, b) = (at(tris[t][e]), at(tris[t][(e + 1) % 3]));
    let shared = (0..3).find_map(|j| {
        let (p, q) = (at(tris[n][j]), at(tris[n][(j + 1) % 3]));
        let back = neighbours[n][j] as usize == t && mask[n] & (1 << j) == 0;
        (back && ((p, q) == (a, b) || (p, q) == (b, a))).then_some((j, p == a))
    });
    let Some((j, same)) = shared else {
        return 0;
    };
    let k = (j + 2) % 3;
    let place = if stored[n] == stored[t] + 1 {
        QUAD_NEXT
    } else if stored[n] + 1 == stored[t] {
        QUAD_PREVIOUS
    } else {
        0
    };
    INFO_QUAD
        | place
        | (e as u32) << QUAD_SHIFT
        | (k as u32) << QUAD_CORNER_SHIFT
        | if same { QUAD_SAME } else { 0 }
        | u32::from(mask[n] & ALL_EDGES) << QUAD_MASK_SHIFT
}

/// First of the three bits of [`EdgeData::info`] that mark the drawn edges in a chain of more
/// than one edge, whose pattern position the trace pass looks up ([`ChainRecords`]); an
/// edge alone starts its pattern at its end that comes first, as its chain would.
pub(crate) const INFO_CHAINED_SHIFT: u32 = 26;

/// A mesh's edge data under one edge selection, in stored order.
pub(crate) struct EdgeData {
    /// Per stored triangle, the 4 bytes the passes read (`triangle_info` in common.wgsl):
    /// bits 0–2 the drawn edges, bit 3 a boundary edge, bits 4–7 the fold code of
    /// [`Mesh::outline_hints`], bits 8–10 the edges that may be drawn as outlines, bit 11
    /// a large patch, bits 12–14 the drawn edges the trace pass draws, bit 15 a patch of
    /// two triangles, bits 16–25 that quad's other triangle ([`quad_bits`]), bits 26–28 the
    /// drawn edges in chains ([`INFO_CHAINED_SHIFT`]), bit 29 a patch that crosses another
    /// surface ([`INFO_CROSSED`]).
    pub info: Vec<u32>,
    pub lines: MeshLines,
    /// The drawn edges' chains, as the trace pass's chain records.
    pub chains: ChainRecords,
}

impl EdgeData {
    pub fn new(mesh: &Mesh, edges: EdgeSelection, order: &[u32]) -> EdgeData {
        let mask = mesh.edge_mask(edges);
        let neighbours = mesh.edge_neighbours();
        // Each edge splatted from the side with the lower stored id, the side the trace
        // pass draws a silhouette from.
        let mut stored = vec![0u32; order.len()];
        for (s, &t) in order.iter().enumerate() {
            stored[t as usize] = s as u32;
        }
        let patches = Patches::ordered(neighbours, &mask, mesh.crossed_triangles(), |t, u| {
            stored[t] < stored[u]
        });
        let hints = mesh.outline_hints();
        let outline = mesh.outline_mask();
        let (chains, chained) = ChainRecords::new(mesh, &mask, &stored);
        let info = order
            .iter()
            .map(|&t| {
                let t = t as usize;
                let large = if patches.large[t] {
                    INFO_LARGE_PATCH
                } else {
                    0
                };
                let crossed = if patches.crossed[t] { INFO_CROSSED } else { 0 };
                let quad = if patches.size[t] == 2 && !patches.crossed[t] {
                    quad_bits(mesh, &mask, &stored, t)
                } else {
                    0
                };
                u32::from(mask[t])
                    | u32::from(hints[t]) << 3
                    | u32::from(outline[t]) << 8
                    | large
                    | u32::from(patches.splat[t]) << INFO_SPLAT_SHIFT
                    | quad
                    | u32::from(chained[t]) << INFO_CHAINED_SHIFT
                    | crossed
            })
            .collect();
        let lines = MeshLines {
            small_patches: mask
                .iter()
                .zip(&patches.large)
                .any(|(&m, &large)| m != ALL_EDGES && !large),
            splat: patches.splat.iter().any(|&b| b != 0),
            crossed: patches.crossed.iter().any(|&c| c),
        };
        EdgeData {
            info,
            lines,
            chains,
        }
    }
}

/// A mesh's chains of more than one drawn edge ([`crate::mesh::chains`]) as the trace
/// pass's `chain_phases` reads them, in 16-byte records: one per chain (its first edge
/// record, relative to the first record, and its edge count), then one per edge in chain order (its
/// start and end vertex as the triangle listing it runs, and [`phase_key`] | forward << 31,
/// and its place in the phase table). Each frame, `chain_phases` writes every edge's key and
/// pattern position into its instance's phase table, an open-addressed hash table (linear
/// probing from [`phase_slot`]) whose layout is fixed here: the trace pass finds an edge's
/// position by its key, probing only slots written in the same frame.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct ChainRecords {
    pub records: Vec<[u32; 4]>,
    pub chains: u32,
    /// log2 of the phase table's slots (at least twice the edges, so probes stay short).
    pub table_log2: u32,
}

/// The key of edge `i` of stored triangle `t` (mesh-relative) in a phase table.
pub(crate) fn phase_key(t: u32, i: u32) -> u32 {
    t << 2 | i
}

/// The slot a phase table of 2^`log2` slots probes first for `key` (twin of `phase_slot` in
/// trace.wgsl): Fibonacci hashing.
pub(crate) fn phase_slot(key: u32, log2: u32) -> u32 {
    key.wrapping_mul(0x9e37_79b1) >> (32 - log2)
}

impl ChainRecords {
    /// The chain records of `mesh`'s drawn edges (`mask`), each shared edge listed from the
    /// side with the lower stored index (`stored`), as the trace pass lists it; and per
    /// triangle, the edges in those chains.
    fn new(mesh: &Mesh, mask: &[u8], stored: &[u32]) -> (ChainRecords, Vec<u8>) {
        let neighbours = mesh.edge_neighbours();
        let mut listed = Vec::new();
        for (t, n) in neighbours.iter().enumerate() {
            for i in 0..3u8 {
                let n = n[usize::from(i)];
                let mine = n == NO_NEIGHBOUR || stored[t] < stored[n as usize];
                if mask[t] & (1 << i) != 0 && mine {
                    listed.push((t as u32, i));
                }
            }
        }
        let tris = mesh.triangles();
        let all = crate::mesh::chains::chains(mesh.positions(), mesh.welded(), tris, &listed);
        let mut chains = crate::mesh::chains::Chains::default();
        let mut chained = vec![0u8; tris.len()];
        for chain in all.iter().filter(|c| c.len() > 1) {
            chains.starts.push(chains.edges.len() as u32);
            chains.edges.extend_from_slice(chain);
            for e in chain {
                chained[e.t as usize] |= 1 << e.i;
            }
        }
        let edges = chains.edges.len() as u32;
        let table_log2 = (2 * edges).max(2).next_power_of_two().trailing_zeros();
        let mask = (1u32 << table_log2) - 1;
        let mut taken = vec![false; 1 << table_log2];
        let first = chains.starts.len() as u32;
        let mut records: Vec<[u32; 4]> = chains.iter().map(|_| [0; 4]).collect();
        for (k, chain) in chains.iter().enumerate() {
            records[k] = [first + chains.starts[k], chain.len() as u32, 0, 0];
        }
        for e in &chains.edges {
            let key = phase_key(stored[e.t as usize], u32::from(e.i));
            let mut slot = phase_slot(key, table_log2);
            while taken[slot as usize] {
                slot = (slot + 1) & mask;
            }
            taken[slot as usize] = true;
            let tri = tris[e.t as usize];
            let (a, b) = (tri[usize::from(e.i)], tri[(usize::from(e.i) + 1) % 3]);
            records.push([a, b, key | u32::from(e.forward) << 31, slot]);
        }
        let records = ChainRecords {
            records,
            chains: first,
            table_log2,
        };
        (records, chained)
    }
}

/// The cluster records the trace pass reads: `bounds` with the spread of each cluster
/// holding an edge to splat (`info`, stored order) stored as −1 − spread, so the trace
/// pass visits it whatever the eye (`cluster_splats` in common.wgsl), and the radius of each
/// cluster holding no drawn edge stored as −1 − radius, so that hidden lines skip it
/// (`cluster_draws`).
pub(crate) fn cluster_records(bounds: &[[f32; 8]], info: &[u32]) -> Vec<[f32; 8]> {
    bounds
        .iter()
        .zip(info.chunks(crate::mesh::clusters::CLUSTER_TRIANGLES))
        .map(|(b, tris)| {
            let mut b = *b;
            if tris.iter().any(|i| i >> INFO_SPLAT_SHIFT & 7 != 0) {
                b[7] = -1.0 - b[7];
            }
            if tris.iter().all(|i| i & 7 == 0) {
                b[3] = -1.0 - b[3];
            }
            b
        })
        .collect()
}

/// A unit normal packed octahedrally into two 16-bit snorms (`unpack_normal` in
/// common.wgsl is the inverse); a zero normal packs to `NO_NORMAL`.
pub(crate) fn pack_normal(n: Vec3) -> u32 {
    let sum = n.x.abs() + n.y.abs() + n.z.abs();
    if !(sum > 0.0) {
        return NO_NORMAL;
    }
    let mut p = Vec2::new(n.x, n.y) / sum;
    if n.z < 0.0 {
        let sign = Vec2::new(p.x.signum(), p.y.signum());
        p = (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * sign;
    }
    let q = |v: f32| (v.clamp(-1.0, 1.0) * 32767.0).round() as i16 as u16 as u32;
    q(p.x) | q(p.y) << 16
}

/// Twin of `unpack_normal` in common.wgsl: the unit normal of a packed one (zero for
/// `NO_NORMAL`).
#[cfg(test)]
pub(crate) fn unpack_normal(packed: u32) -> Vec3 {
    if packed == NO_NORMAL {
        return Vec3::ZERO;
    }
    let s = |v: u32| (f32::from(v as u16 as i16) / 32767.0).max(-1.0);
    let (x, y) = (s(packed & 0xffff), s(packed >> 16));
    let mut n = Vec3::new(x, y, 1.0 - x.abs() - y.abs());
    let t = (-n.z).max(0.0);
    n.x += if n.x >= 0.0 { -t } else { t };
    n.y += if n.y >= 0.0 { -t } else { t };
    n.normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quad (0,0)-(1,0)-(1,1)-(0,1) split along 0-2, the second triangle's corners
    /// given by `second` over positions `p`, with the diagonal undrawn on both sides.
    fn quad_info(p: Vec<Vec3>, second: [u32; 3]) -> [u32; 2] {
        let shared = (0..3)
            .find(|&j| {
                let e = [second[j], second[(j + 1) % 3]].map(|v| p[v as usize]);
                e.contains(&p[0]) && e.contains(&p[2])
            })
            .unwrap();
        let mask = vec![0b011, ALL_EDGES & !(1 << shared)];
        let mesh = Mesh::new(p, None, vec![[0, 1, 2], second], Some(mask)).unwrap();
        let mask = mesh.edge_mask(EdgeSelection::Polygon);
        [0, 1].map(|t| quad_bits(&mesh, &mask, &[0, 1], t))
    }

    fn square() -> Vec<Vec3> {
        [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .map(|(x, y)| Vec3::new(x, y, 0.0))
            .to_vec()
    }

    /// Decodes quad_bits as quad_distance does: the diagonal, the other triangle's corner
    /// off it, whether its next corner is the diagonal's start, its drawn edges.
    fn decode(bits: u32) -> (u32, u32, bool, u32) {
        assert_ne!(bits & INFO_QUAD, 0);
        let b = bits >> QUAD_SHIFT;
        (b & 3, b >> 2 & 3, b >> 4 & 1 == 1, b >> 5 & 7)
    }

    #[test]
    fn quad_bits_name_the_other_triangle_s_fourth_corner() {
        // Consistently wound: the diagonal is edge 2 (2 -> 0) of the first triangle and
        // edge 0 (0 -> 2) of the second, whose corner off it is 3 (corner 2).
        let [first, second] = quad_info(square(), [0, 2, 3]);
        assert_eq!(decode(first), (2, 2, false, 0b110));
        assert_eq!(decode(second), (0, 1, false, 0b011));
        // Stored side by side, each says where the other is.
        assert_eq!(first & (QUAD_NEXT | QUAD_PREVIOUS), QUAD_NEXT);
        assert_eq!(second & (QUAD_NEXT | QUAD_PREVIOUS), QUAD_PREVIOUS);
        // The second triangle wound the other way (its next corner after 3 is the first
        // triangle's diagonal start, 2), and with split vertices at the same positions.
        let mut p = square();
        p.extend([p[0], p[2]]);
        let [first, second] = quad_info(p, [3, 5, 4]);
        assert_eq!(decode(first), (2, 0, true, 0b101));
        assert_eq!(decode(second), (1, 1, true, 0b011));
    }

    #[test]
    fn neighbour_words_give_the_corner_off_the_edge_and_the_way_round() {
        let mut split = square();
        split.extend([split[0], split[2]]);
        // The second triangle wound against the first, with it, and on split vertices.
        for (p, second) in [
            (square(), [0, 2, 3]),
            (square(), [0, 3, 2]),
            (split, [3, 5, 4]),
        ] {
            let mesh = Mesh::new(p.clone(), None, vec![[0, 1, 2], second], None).unwrap();
            let tris = mesh.triangles();
            for (t, i) in (0..2).flat_map(|t| (0..3).map(move |i| (t, i))) {
                let word = neighbour_word(&mesh, &[0, 1], t, i);
                let n = mesh.edge_neighbours()[t][i];
                if n == NO_NEIGHBOUR {
                    assert_eq!(word, u32::MAX);
                    continue;
                }
                assert_eq!(word & MAX_MESH_TRIANGLES, n);
                // The neighbour's corners as beyond_edge (scene.wgsl) rebuilds them: corner k
                // read, the next two the edge's ends.
                let k = (word >> NEIGHBOUR_CORNER_SHIFT & 3) as usize;
                let (a, b) = (p[tris[t][i] as usize], p[tris[t][(i + 1) % 3] as usize]);
                let same = word & NEIGHBOUR_SAME_WAY != 0;
                let mut q = [p[tris[n as usize][k] as usize]; 3];
                q[(k + 1) % 3] = if same { a } else { b };
                q[(k + 2) % 3] = if same { b } else { a };
                assert_eq!(q, tris[n as usize].map(|v| p[v as usize]), "{t} {i}");
            }
        }
    }

    #[test]
    fn chain_records_place_every_chained_edge_where_its_probe_finds_it() {
        // A cube split 5 times a side: each of its 12 feature edges a chain of 5 edges.
        let mesh = crate::mesh::cube(300).unwrap();
        let order: Vec<u32> = (0..mesh.triangle_count() as u32).rev().collect();
        let data = EdgeData::new(&mesh, EdgeSelection::Feature(30.0), &order);
        let c = &data.chains;
        assert_eq!(c.chains, 12);
        let heads = &c.records[..12];
        let edges = &c.records[12..];
        assert_eq!(edges.len(), 60);
        assert!(heads.iter().all(|h| h[1] == 5));
        let slots = 1u32 << c.table_log2;
        assert!(slots >= 2 * edges.len() as u32);
        let mut taken = vec![None; slots as usize];
        for e in edges {
            assert!(taken[e[3] as usize].replace(e[2] & 0x7fff_ffff).is_none());
        }
        for e in edges {
            // Probing from the key's slot meets only taken slots before the key's own.
            let key = e[2] & 0x7fff_ffff;
            let mut at = phase_slot(key, c.table_log2);
            while taken[at as usize] != Some(key) {
                assert!(taken[at as usize].is_some());
                at = (at + 1) % slots;
            }
            // The key's triangle marks the edge as chained.
            let (t, i) = (key >> 2, key & 3);
            assert_ne!(data.info[t as usize] >> (INFO_CHAINED_SHIFT + i) & 1, 0);
        }
        let chained: u32 = data
            .info
            .iter()
            .map(|w| (w >> INFO_CHAINED_SHIFT & 7).count_ones())
            .sum();
        assert_eq!(chained, 60);
    }

    #[test]
    fn quads_joined_at_unequal_bits_are_searched_instead() {
        // 0.0 and -0.0 weld into one edge, but read from the two triangles they would be
        // different numbers: the triangles are left to the patch search.
        let mut p = square();
        p.extend([Vec3::new(-0.0, 0.0, 0.0), p[2]]);
        assert_eq!(quad_info(p, [4, 5, 3]), [0, 0]);
    }

    #[test]
    fn normals_survive_packing() {
        let mut worst: f64 = 0.0;
        for i in 0..2000 {
            let a = i as f32 * 0.731;
            let b = (i as f32 * 0.377).sin() * 1.5;
            let n = Vec3::new(a.cos() * b.cos(), b.sin(), a.sin() * b.cos()).normalize();
            let m = unpack_normal(pack_normal(n));
            let cos = n.as_dvec3().dot(m.as_dvec3());
            let sin = n.as_dvec3().cross(m.as_dvec3()).length();
            worst = worst.max(sin.atan2(cos));
        }
        assert!(worst < 1e-4, "{worst}");
        for n in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            assert!(unpack_normal(pack_normal(n)).distance(n) < 1e-6, "{n}");
        }
        assert_eq!(pack_normal(Vec3::ZERO), NO_NORMAL);
        assert_eq!(unpack_normal(NO_NORMAL), Vec3::ZERO);
        // No unit normal packs to the marker.
        assert_ne!(
            pack_normal(Vec3::new(-1.0, -1.0, 0.0).normalize()),
            NO_NORMAL
        );
    }
}
