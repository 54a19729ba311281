//! Clusters of nearby triangles with bounds that let the GPU trace pass skip a whole cluster
//! at once, so that its cost follows the triangles near the outline rather than the triangle
//! count.
//!
//! Triangles are ordered along a Morton curve through their centroids and cut into runs of
//! [`CLUSTER_TRIANGLES`], so a cluster is a compact patch whatever order the file lists its
//! triangles in, and its normals spread little on a smooth surface. The two triangles of a
//! quad stay side by side in that order, so the edge pass finds a quad's other triangle
//! next to the one it holds, without reading the adjacency.
//!
//! A neighboured edge can be a silhouette only while the eye sees its triangle's plane within
//! the edge's fold of edge-on ([`super::adjacency::outline_hints`]). A cluster's bounds are a
//! sphere holding its triangles and a cone holding their normals, widened by the largest fold
//! among them: when every direction from the eye into the sphere makes an angle with every
//! normal in the cone that stays more than the fold away from 90°, no triangle of the cluster
//! has an outline edge.

use super::adjacency::{fold_bound, ANY_FOLD};
use crate::mesh::par::*;
use glam::DVec3;

/// Triangles per cluster (the last may have fewer); the trace pass's workgroup size.
pub const CLUSTER_TRIANGLES: usize = 64;

/// The spread of a cluster that may hold an outline edge from any view: over π/2 fails
/// both skip conditions of [`may_fold`] whatever the eye.
pub const ALWAYS: f64 = 4.0;

/// Added to each spread for the GPU's f32 rounding of centres, axes and the eye, in radians;
/// it also covers the angle within which a triangle counts as edge-on, so folded
/// (`edge_math::EDGE_ON`).
pub(crate) const SPREAD_MARGIN: f64 = 1e-4;

/// A cluster's bounds, in mesh coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterBounds {
    /// Centre of a sphere holding every corner of the cluster's triangles.
    pub center: DVec3,
    /// Radius of that sphere.
    pub radius: f64,
    /// Unit axis of the normal cone (zero when the spread is [`ALWAYS`]).
    pub axis: DVec3,
    /// The cone's half-angle plus the largest fold of the cluster's edges, in radians;
    /// [`ALWAYS`] when a triangle has a boundary edge, folds 90° or more, or is degenerate.
    pub spread: f64,
}

/// A mesh's triangles in clusters.
#[derive(Clone, Debug, PartialEq)]
pub struct Clusters {
    /// Triangle ids in Morton order; cluster `c` holds entries
    /// `CLUSTER_TRIANGLES × c ..` up to the next cluster's.
    pub order: Vec<u32>,
    /// Bounds of each cluster.
    pub bounds: Vec<ClusterBounds>,
}

/// Clusters the triangles; `hints` are [`super::Mesh::outline_hints`], `partners` the
/// other triangle of each triangle's quad ([`super::adjacency::NO_NEIGHBOUR`] for none),
/// which the order keeps next to it where the two name each other
/// ([`super::Mesh::quad_partners`]).
pub fn clusters(
    positions: &[glam::Vec3],
    triangles: &[[u32; 3]],
    hints: &[u8],
    partners: &[u32],
) -> Clusters {
    let corner = |t: u32, k: usize| positions[triangles[t as usize][k] as usize].as_dvec3();
    let centroid = |t: u32| (corner(t, 0) + corner(t, 1) + corner(t, 2)) / 3.0;
    let (lo, hi) = (0..triangles.len() as u32).map(centroid).fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), c| (lo.min(c), hi.max(c)),
    );
    let cells = ((1u64 << MORTON_BITS) - 1) as f64;
    let scale = cells / (hi - lo).max_element().max(f64::MIN_POSITIVE);
    // One key per quad, placed at its first triangle; its second follows it. Only pairs
    // that name each other count, so that every triangle is placed once whatever `partners`
    // holds.
    let partner = |t: u32| {
        Some(partners[t as usize])
            .filter(|&u| u != t && partners.get(u as usize).is_some_and(|&back| back == t))
    };
    let mut keyed: Vec<(u64, u32)> = (0..triangles.len() as u32)
        .into_par_iter()
        .filter(|&t| partner(t).is_none_or(|u| t < u))
        .map(|t| {
            let c = partner(t).map_or(centroid(t), |u| (centroid(t) + centroid(u)) * 0.5);
            let q = ((c - lo) * scale)
                .clamp(DVec3::ZERO, DVec3::splat(cells))
                .as_u64vec3();
            (morton(q.x) | morton(q.y) << 1 | morton(q.z) << 2, t)
        })
        .collect();
    keyed.par_sort_unstable();
    let order: Vec<u32> = keyed
        .into_iter()
        .flat_map(|(_, t)| std::iter::once(t).chain(partner(t)))
        .collect();
    let bounds = order
        .par_chunks(CLUSTER_TRIANGLES)
        .map(|ids| {
            bound(
                ids,
                |t| [0, 1, 2].map(|k| corner(t, k)),
                |t| hints[t as usize],
            )
        })
        .collect();
    Clusters { order, bounds }
}

/// Bits of each coordinate in a Morton key.
const MORTON_BITS: u32 = 21;

/// Spreads the low 21 bits of `v` to every third bit.
fn morton(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    (x | x << 2) & 0x1249_2492_4924_9249
}

/// The bounds of the triangles `ids`, with their corners and outline hints.
fn bound(
    ids: &[u32],
    corners: impl Fn(u32) -> [DVec3; 3],
    hint: impl Fn(u32) -> u8,
) -> ClusterBounds {
    let points = || ids.iter().flat_map(|&t| corners(t));
    let (lo, hi) = points().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    );
    let center = (lo + hi) * 0.5;
    let radius = points().map(|p| p.distance(center)).fold(0.0, f64::max);
    let always = ClusterBounds {
        center,
        radius,
        axis: DVec3::ZERO,
        spread: ALWAYS,
    };
    let mut normals = Vec::with_capacity(ids.len());
    // The largest fold code: `fold_bound` grows with the code, so its bound is the largest.
    let mut fold_code = 0;
    for &t in ids {
        let (q, boundary) = (hint(t) >> 1, hint(t) & 1 != 0);
        let [a, b, c] = corners(t);
        let n = (b - a).cross(c - a).normalize_or_zero();
        if boundary || q >= ANY_FOLD || n == DVec3::ZERO {
            return always;
        }
        normals.push(n);
        fold_code = fold_code.max(q);
    }
    let fold = fold_bound(fold_code).min(1.0).asin();
    let axis = normals.iter().sum::<DVec3>().normalize_or_zero();
    if axis == DVec3::ZERO {
        return always;
    }
    // The normal furthest from the axis, found by comparing angles in [0, π] through their
    // sines and cosines (the sine of their difference), then its angle: one atan2 a
    // cluster, not one a triangle (a software function in a browser's WebAssembly).
    let (sin, cos) = normals
        .iter()
        .map(|n| (n.cross(axis).length(), n.dot(axis)))
        .fold((0.0, 1.0), |(s, c), (si, ci)| {
            let wider = si * c - ci * s;
            if wider > 0.0 || (wider == 0.0 && ci < c) {
                (si, ci)
            } else {
                (s, c)
            }
        });
    let cone = sin.atan2(cos);
    ClusterBounds {
        center,
        radius,
        axis,
        spread: (cone + fold + SPREAD_MARGIN).min(ALWAYS),
    }
}

/// Twin of `cluster_may_fold` in common.wgsl: false when, seen from `eye` (homogeneous: a
/// point with w = 1, or a direction towards the viewer with w = 0), no triangle of the
/// cluster can have an outline edge. The directions from the eye into the sphere lie within
/// β = asin(r / D) of its centre's (β = 0 for an orthographic eye); the angle γ between that
/// and the axis then bounds every direction-to-normal angle within γ ± (β + spread), and the
/// cluster may fold when that interval reaches 90°. An eye inside the sphere sees every
/// direction.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // as in WGSL: a NaN distance may fold
pub fn may_fold(bounds: &ClusterBounds, eye: glam::DVec4) -> bool {
    let (d, beta) = if eye.w != 0.0 {
        let d = bounds.center - eye.truncate() / eye.w;
        let distance = d.length();
        if !(distance > bounds.radius) {
            return true;
        }
        (d, (bounds.radius / distance).asin())
    } else {
        (-eye.truncate(), 0.0)
    };
    let gamma = d.cross(bounds.axis).length().atan2(d.dot(bounds.axis));
    let reach = beta + bounds.spread;
    let quarter = std::f64::consts::FRAC_PI_2;
    !(gamma + reach < quarter || gamma - reach > quarter)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::adjacency::NO_NEIGHBOUR;

    #[test]
    fn a_quad_s_triangles_are_stored_side_by_side() {
        for mesh in [crate::mesh::sphere(5000), crate::mesh::cube(3000)] {
            let mesh = mesh.unwrap();
            let partners = mesh.quad_partners();
            let paired = partners.iter().filter(|&&p| p != NO_NEIGHBOUR).count();
            assert!(paired > mesh.triangle_count() / 2, "{paired} paired");
            let order = &mesh.traced_clusters().order;
            let mut stored = vec![usize::MAX; order.len()];
            for (s, &t) in order.iter().enumerate() {
                assert_eq!(stored[t as usize], usize::MAX, "triangle {t} stored twice");
                stored[t as usize] = s;
            }
            assert_eq!(order.len(), mesh.triangle_count());
            for (t, &p) in partners.iter().enumerate() {
                if p != NO_NEIGHBOUR {
                    assert_eq!(partners[p as usize], t as u32);
                    assert_eq!(stored[t].abs_diff(stored[p as usize]), 1, "quad {t}, {p}");
                }
            }
        }
    }

    /// Every triangle's normal lies within its cluster's cone: the angle from the axis, as
    /// atan2 gives it, is at most the spread (which adds the fold and the margin).
    #[test]
    fn the_normal_cone_holds_every_normal_of_its_cluster() {
        // Facing +z, +z and -z: the axis +z, the widest normal π away.
        let tris = [
            [DVec3::ZERO, DVec3::X, DVec3::Y],
            [DVec3::ZERO, DVec3::X, DVec3::Y],
            [DVec3::ZERO, DVec3::Y, DVec3::X],
        ];
        let b = bound(&[0, 1, 2], |t| tris[t as usize], |_| 0);
        assert!(b.spread >= std::f64::consts::PI, "{}", b.spread);
        for mesh in [crate::mesh::sphere(20_000), crate::mesh::torus(20_000)] {
            let mesh = mesh.unwrap();
            let c = mesh.traced_clusters();
            let corner = |t: u32, k: usize| {
                mesh.positions()[mesh.triangles()[t as usize][k] as usize].as_dvec3()
            };
            for (ids, b) in c.order.chunks(CLUSTER_TRIANGLES).zip(&c.bounds) {
                if b.spread >= ALWAYS {
                    continue;
                }
                for &t in ids {
                    let (a, e, f) = (corner(t, 0), corner(t, 1), corner(t, 2));
                    let n = (e - a).cross(f - a).normalize();
                    let angle = n.cross(b.axis).length().atan2(n.dot(b.axis));
                    assert!(angle <= b.spread - SPREAD_MARGIN, "{angle} > {}", b.spread);
                }
            }
        }
    }

    #[test]
    fn partners_that_do_not_name_each_other_leave_the_order_a_permutation() {
        let mesh = crate::mesh::grid(200).unwrap();
        let n = mesh.triangle_count() as u32;
        // Each triangle names the next: no two name each other, and the last names none.
        let partners: Vec<u32> = (0..n)
            .map(|t| if t + 1 < n { t + 1 } else { NO_NEIGHBOUR })
            .collect();
        let c = clusters(
            mesh.positions(),
            mesh.triangles(),
            mesh.outline_hints(),
            &partners,
        );
        let mut order = c.order.clone();
        order.sort_unstable();
        assert_eq!(order, (0..n).collect::<Vec<_>>());
    }
}
