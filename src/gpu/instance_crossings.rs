//! Intersection lines between instances ([`Style::intersection_lines`](crate::Style)): where
//! the surfaces of two instances pass through each other (parts of an assembly with an
//! interference fit, a body through a wall).
//!
//! A mesh's own crossings depend on its shape alone and are found once, at upload
//! ([`Mesh::intersections`](crate::Mesh::intersections)). Those between two instances depend
//! on where both are placed, so they are found as a frame is prepared, for each pair of
//! instances whose placed bounds meet ([`crate::scene::meeting_pairs`]), from the positions
//! and triangles the store keeps: the triangles of the clusters that reach the overlap of the
//! two bounds are tested in world coordinates, in f64, by the test a mesh's own crossings
//! take ([`crossings_between`]). A pair's segments are kept (in the store) while both
//! instances keep their mesh and transform, so a still scene seen from a moving camera finds
//! them once.

use super::loop_budget::WINDOW_RADII;
use super::mesh_store::{MeshId, MeshRecord};
use crate::mesh::clusters::CLUSTER_TRIANGLES;
use crate::mesh::crossings::{crossings_between, pair_tolerance};
use crate::scene::world_box;
use glam::{DMat4, DVec3};
use std::collections::HashMap;
use std::sync::Arc;

/// Where triangle `t` of one instance crosses triangle `u` of another (stored ids), the
/// segment's ends in the first instance's stored coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PairCrossing {
    pub t: u32,
    pub u: u32,
    pub ends: [[f32; 3]; 2],
}

/// One placed instance: its mesh and model → world transform.
pub(crate) type Placed = (MeshId, DMat4);

/// The crossings of instance pairs found for recent frames.
#[derive(Debug, Default)]
pub(crate) struct PairCache {
    /// Frames prepared so far.
    frames: u64,
    /// By the pair's placements, the frame that last asked for it and its crossings.
    entries: HashMap<PairKey, (u64, Arc<[PairCrossing]>)>,
}

/// A pair's meshes and the bits of their transforms.
type PairKey = (MeshId, MeshId, [u64; 16], [u64; 16]);

/// Pairs no frame has asked for in this many frames are forgotten.
const KEEP_FRAMES: u64 = 8;

impl PairCache {
    /// Starts a frame: forgets the pairs that recent frames did not ask for.
    pub fn begin_frame(&mut self) {
        self.frames += 1;
        let now = self.frames;
        self.entries
            .retain(|_, (used, _)| now - *used < KEEP_FRAMES);
    }

    /// The crossings between instances `a` and `b` (of meshes `records`), found or kept.
    pub fn between(
        &mut self,
        (a, b): (Placed, Placed),
        records: (&MeshRecord, &MeshRecord),
    ) -> Arc<[PairCrossing]> {
        let bits = |m: DMat4| m.to_cols_array().map(f64::to_bits);
        let key = (a.0, b.0, bits(a.1), bits(b.1));
        let now = self.frames;
        let entry = self.entries.entry(key).or_insert_with(|| {
            (
                now,
                crossings_of_pair(records.0, a.1, records.1, b.1).into(),
            )
        });
        entry.0 = now;
        entry.1.clone()
    }
}

/// Pixels the guard band grows by in a frame where surfaces may cross: the trace pass
/// tests the visibility of their lines against the ids up to four pixels around each point
/// (the surface that a line passes into may be visible only a few pixels away, where the
/// surfaces in front of it end), not one.
pub(crate) const CROSSING_BAND: u32 = 3;

/// A box of image pixels (min x, min y, max x, max y) that holds none.
pub(crate) const NO_BOX: [f32; 4] = [f32::MAX, f32::MAX, f32::MIN, f32::MIN];
/// A box that holds every pixel.
pub(crate) const WHOLE_IMAGE: [f32; 4] = [f32::MIN, f32::MIN, f32::MAX, f32::MAX];

/// Pixels round the image of the crossings within which the trace pass draws a crossed
/// instance's lines the crossing way: where a line passes into another surface, that
/// surface may show no nearer than the widest window's radius to the point
/// (`WINDOW_RADII`), in targets grown by `CROSSING_BAND`; a pixel more for rounding.
pub(crate) const CROSSING_MARGIN: f32 = (WINDOW_RADII[2] + CROSSING_BAND + 1) as f32;

/// The smallest box holding both.
pub(crate) fn union_box(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [
        a[0].min(b[0]),
        a[1].min(b[1]),
        a[2].max(b[2]),
        a[3].max(b[3]),
    ]
}

/// The image pixels (of an image `image` pixels in size) within [`CROSSING_MARGIN`] of the
/// image of `crossings` (in the stored coordinates that `model` places in the world), as a
/// box; the whole image where one of them reaches behind the near plane, whose image is
/// unbounded.
pub(crate) fn crossing_box(
    view: &crate::View,
    image: (u32, u32),
    model: DMat4,
    crossings: &[PairCrossing],
) -> [f32; 4] {
    let clip = view.clip_rows(model).clip;
    let size = glam::DVec2::new(f64::from(image.0), f64::from(image.1));
    let mut lo = glam::DVec2::splat(f64::INFINITY);
    let mut hi = -lo;
    for p in crossings.iter().flat_map(|c| c.ends) {
        // Clip rows x, y, near, w: in front of the near plane exactly where near >= 0.
        let c = clip * DVec3::from_array(p.map(f64::from)).extend(1.0);
        if !(c.z >= 0.0 && c.w > 0.0) {
            return WHOLE_IMAGE;
        }
        let ndc = c.truncate().truncate() / c.w;
        let px = glam::DVec2::new(0.5 * (ndc.x + 1.0), 0.5 * (1.0 - ndc.y)) * size;
        lo = lo.min(px);
        hi = hi.max(px);
    }
    if !(lo.cmple(hi).all() && hi.is_finite() && lo.is_finite()) {
        return if crossings.is_empty() {
            NO_BOX
        } else {
            WHOLE_IMAGE
        };
    }
    let m = f64::from(CROSSING_MARGIN);
    let (lo, hi) = ((lo - m).floor(), (hi + m).ceil());
    [lo.x as f32, lo.y as f32, hi.x as f32, hi.y as f32]
}

/// Where mesh `a` placed by `ta` and mesh `b` placed by `tb` cross, sorted by triangle.
pub(crate) fn crossings_of_pair(
    a: &MeshRecord,
    ta: DMat4,
    b: &MeshRecord,
    tb: DMat4,
) -> Vec<PairCrossing> {
    let (box_a, box_b) = (world_box(a.bounds, ta), world_box(b.bounds, tb));
    let tolerance = pair_tolerance(box_a, box_b);
    let overlap = (
        box_a.0.max(box_b.0) - tolerance,
        box_a.1.min(box_b.1) + tolerance,
    );
    if !overlap.0.cmple(overlap.1).all() {
        return Vec::new();
    }
    let (ids_a, corners_a) = near(a, ta, overlap, tolerance);
    let (ids_b, corners_b) = near(b, tb, overlap, tolerance);
    if ids_a.is_empty() || ids_b.is_empty() {
        return Vec::new();
    }
    // World → the first instance's stored coordinates.
    let to_stored = (ta * a.local_to_mesh()).inverse();
    crossings_between(&corners_a, &corners_b, tolerance)
        .into_iter()
        .map(|c| PairCrossing {
            t: ids_a[c.t as usize],
            u: ids_b[c.u as usize],
            ends: c
                .ends
                .map(|p| to_stored.transform_point3(p).as_vec3().to_array()),
        })
        .collect()
}

/// The triangles of `mesh` placed by `transform` whose world bounds reach `region` (within
/// `tolerance`): their stored ids and world corners. Whole clusters whose bounding spheres
/// miss the region are passed over.
fn near(
    mesh: &MeshRecord,
    transform: DMat4,
    region: (DVec3, DVec3),
    tolerance: f64,
) -> (Vec<u32>, Vec<[DVec3; 3]>) {
    let stored_to_world = transform * mesh.local_to_mesh();
    // A sphere of radius r maps into one of radius r times the largest column length.
    let stretch = [
        stored_to_world.x_axis,
        stored_to_world.y_axis,
        stored_to_world.z_axis,
    ]
    .map(|c| c.truncate().length())
    .into_iter()
    .fold(0.0, f64::max);
    let reaches = |lo: DVec3, hi: DVec3| {
        lo.cmple(region.1 + tolerance).all() && hi.cmpge(region.0 - tolerance).all()
    };
    let (mut ids, mut corners) = (Vec::new(), Vec::new());
    let per_cluster = CLUSTER_TRIANGLES;
    for (c, bound) in mesh.bounds_of_clusters.iter().enumerate() {
        let centre = stored_to_world.transform_point3(DVec3::new(
            f64::from(bound[0]),
            f64::from(bound[1]),
            f64::from(bound[2]),
        ));
        let r = f64::from(bound[3]) * stretch * (1.0 + 1e-9) + tolerance;
        if !reaches(centre - r, centre + r) {
            continue;
        }
        let first = c * per_cluster;
        let last = (first + per_cluster).min(mesh.indices.len());
        for t in first..last {
            let p = mesh.indices[t]
                .map(|v| transform.transform_point3(mesh.positions[v as usize].as_dvec3()));
            if reaches(p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2])) {
                ids.push(t as u32);
                corners.push(p);
            }
        }
    }
    (ids, corners)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::crossings::crossings_between;

    fn world_ends(record: &MeshRecord, transform: DMat4, c: &PairCrossing) -> [DVec3; 2] {
        let m = transform * record.local_to_mesh();
        c.ends
            .map(|p| m.transform_point3(glam::Vec3::from(p).as_dvec3()))
    }

    /// Two unit boxes through each other (the second moved by (1.5, 0.3, 0.2), and mirrored:
    /// the same box) meet along six straight pieces, 8.0 long in all (worked out by hand from
    /// the boxes' faces), every end on both boxes.
    #[test]
    fn placed_boxes_meet_along_their_intersection_curve() {
        let cube = MeshRecord::unstored(&crate::mesh::cube(12).unwrap());
        let shift = DVec3::new(1.5, 0.3, 0.2);
        let on_box =
            |q: DVec3, centre: DVec3| ((q - centre).abs().max_element() - 1.0).abs() < 1e-6;
        for tb in [
            DMat4::from_translation(shift),
            DMat4::from_translation(shift) * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
        ] {
            let found = crossings_of_pair(&cube, DMat4::IDENTITY, &cube, tb);
            let mut length = 0.0;
            for c in &found {
                let [p, q] = world_ends(&cube, DMat4::IDENTITY, c);
                length += p.distance(q);
                for e in [p, q] {
                    assert!(on_box(e, DVec3::ZERO) && on_box(e, shift), "{e}");
                }
            }
            assert!((length - 8.0).abs() < 1e-5, "{length}");
        }
        // Apart: nothing.
        let apart = DMat4::from_translation(DVec3::new(2.5, 0.3, 0.2));
        assert!(crossings_of_pair(&cube, DMat4::IDENTITY, &cube, apart).is_empty());
    }

    /// Passing over the clusters that miss the overlap loses no crossing: dense spheres,
    /// one stretched and turned, one mirrored, cross where testing all their triangles finds.
    #[test]
    fn near_the_overlap_holds_every_crossing() {
        let sphere = crate::mesh::sphere(20_000).unwrap();
        let record = MeshRecord::unstored(&sphere);
        let ta = DMat4::from_rotation_y(0.4) * DMat4::from_scale(DVec3::new(1.0, 2.5, 0.6));
        let tb = DMat4::from_translation(DVec3::new(0.9, 0.7, 0.1))
            * DMat4::from_rotation_x(1.1)
            * DMat4::from_scale(DVec3::new(-0.8, 0.8, 0.8));
        let found = crossings_of_pair(&record, ta, &record, tb);
        let all = |t: DMat4| -> Vec<[DVec3; 3]> {
            record
                .indices
                .iter()
                .map(|c| c.map(|v| t.transform_point3(record.positions[v as usize].as_dvec3())))
                .collect()
        };
        let boxes = (world_box(record.bounds, ta), world_box(record.bounds, tb));
        let every = crossings_between(&all(ta), &all(tb), pair_tolerance(boxes.0, boxes.1));
        assert!(every.len() > 100, "{}", every.len());
        let pairs = |v: &mut dyn Iterator<Item = (u32, u32)>| v.collect::<Vec<_>>();
        assert_eq!(
            pairs(&mut found.iter().map(|c| (c.t, c.u))),
            pairs(&mut every.iter().map(|c| (c.t, c.u)))
        );
        for (c, e) in found.iter().zip(&every) {
            let ends = world_ends(&record, ta, c);
            for (p, q) in ends.iter().zip(&e.ends) {
                assert!(p.distance(*q) < 1e-5, "{p} {q}");
            }
        }
    }

    /// The box round the crossings' image: an orthographic view 4 units high onto an image
    /// 400×400 maps a crossing from (-1, 0, 0) to (1, 0.5, 0) to pixels (100, 150)..(300,
    /// 200), grown by the margin; one behind the near plane takes the whole image; none, no
    /// box.
    #[test]
    fn the_crossing_box_holds_the_crossings_image() {
        let view = crate::View::orthographic(
            (DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y),
            4.0,
            1.0,
            (1.0, 10.0),
        );
        let segment = |z: f32| PairCrossing {
            t: 0,
            u: 0,
            ends: [[-1.0, 0.0, 0.0], [1.0, 0.5, z]],
        };
        let m = CROSSING_MARGIN;
        let found = crossing_box(&view, (400, 400), DMat4::IDENTITY, &[segment(0.0)]);
        assert_eq!(found, [100.0 - m, 150.0 - m, 300.0 + m, 200.0 + m]);
        // The mesh's stored coordinates placed by the model matrix.
        let moved = DMat4::from_translation(DVec3::new(0.5, 0.0, 0.0));
        let found = crossing_box(&view, (400, 400), moved, &[segment(0.0)]);
        assert_eq!(found, [150.0 - m, 150.0 - m, 350.0 + m, 200.0 + m]);
        let behind = crossing_box(&view, (400, 400), DMat4::IDENTITY, &[segment(4.5)]);
        assert_eq!(behind, WHOLE_IMAGE);
        assert_eq!(
            crossing_box(&view, (400, 400), DMat4::IDENTITY, &[]),
            NO_BOX
        );
        assert_eq!(union_box(NO_BOX, found), found);
    }

    /// A pair's crossings are found once while both keep their placement, again when one
    /// moves, and forgotten once unused for KEEP_FRAMES frames.
    #[test]
    fn the_cache_keeps_a_pair_while_it_stays_put() {
        let mesh = crate::mesh::cube(12).unwrap();
        let record = MeshRecord::unstored(&mesh);
        let (a, b) = (MeshId::unstored(0), MeshId::unstored(1));
        let placed = |x: f64| {
            (
                (a, DMat4::IDENTITY),
                (b, DMat4::from_translation(DVec3::new(x, 0.3, 0.2))),
            )
        };
        let mut cache = PairCache::default();
        cache.begin_frame();
        let first = cache.between(placed(1.5), (&record, &record));
        assert!(!first.is_empty());
        cache.begin_frame();
        assert!(Arc::ptr_eq(
            &first,
            &cache.between(placed(1.5), (&record, &record))
        ));
        let moved = cache.between(placed(1.4), (&record, &record));
        assert!(!Arc::ptr_eq(&first, &moved) && *first != *moved);
        assert!(cache.between(placed(2.5), (&record, &record)).is_empty());
        for _ in 0..KEEP_FRAMES {
            cache.begin_frame();
        }
        assert!(cache.entries.is_empty());
    }
}
