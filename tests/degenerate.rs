//! Degenerate geometry renders without NaN: zero-area triangles, duplicate vertices,
//! collinear polygons, triangles seen edge-on, a single triangle, and meshes entirely behind
//! the camera or outside the view. Every frame must have finite-or-infinite (never NaN) edge
//! distances, depth in [0, 1] and ids that are background or a real triangle.

mod common;

use common::{camera, shoot};
use glam::Vec3;
use wirepass::tools::offline::Method;
use wirepass::world::Rendering;
use wirepass::{Camera, EdgeSelection, Mesh, Style};

const SIZE: (u32, u32) = (64, 48);

fn looking_down_z() -> Camera {
    camera(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 0.1, 20.0)
}

fn draw(mesh: &Mesh, cam: Camera, edges: EdgeSelection) -> Rendering {
    shoot(mesh, cam, &Style::default(), SIZE, edges, Method::Deferred)
}

/// Checks the frame's maps; returns how many pixels show a triangle.
fn check(name: &str, mesh: &Mesh, frame: &Rendering) -> usize {
    let n = (SIZE.0 * SIZE.1) as usize;
    assert_eq!(frame.ids.len(), n, "{name}");
    let mut covered = 0;
    for i in 0..n {
        let (id, depth, d) = (frame.ids[i], frame.depth[i], frame.edge_distance[i]);
        assert!(!d.is_nan(), "{name}: NaN edge distance at pixel {i}");
        assert!((0.0..=1.0).contains(&depth), "{name}: depth {depth} at {i}");
        if id == u32::MAX {
            assert_eq!(depth, 1.0, "{name}: background depth at {i}");
        } else {
            assert!(
                (id as usize) < mesh.triangle_count(),
                "{name}: id {id} of {} triangles at {i}",
                mesh.triangle_count()
            );
            covered += 1;
        }
    }
    covered
}

fn mesh(positions: &[Vec3], triangles: &[[u32; 3]]) -> Mesh {
    Mesh::new(positions.to_vec(), None, triangles.to_vec(), None).unwrap()
}

#[test]
fn degenerate_meshes_render_without_nan() {
    let (a, b, c) = (
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    );
    let one = mesh(&[a, b, c], &[[0, 1, 2]]);
    let cases: Vec<(&str, Mesh, Camera, bool)> = vec![
        ("one triangle", one.clone(), looking_down_z(), true),
        (
            // A good triangle with zero-area triangles on top: a point and a sliver.
            "zero-area triangles",
            mesh(
                &[a, b, c, Vec3::ZERO, Vec3::new(0.5, 0.5, 0.0)],
                &[[0, 1, 2], [3, 3, 3], [0, 3, 4], [0, 0, 1]],
            ),
            looking_down_z(),
            true,
        ),
        (
            // Every corner twice, triangles using either copy, one using both copies of a.
            "duplicate vertices",
            mesh(&[a, b, c, a, b, c], &[[0, 1, 2], [3, 4, 5], [0, 3, 1]]),
            looking_down_z(),
            true,
        ),
        (
            "collinear polygon fan",
            mesh(
                &(0..6)
                    .map(|i| Vec3::new(i as f32 * 0.3 - 0.75, 0.2, 0.0))
                    .collect::<Vec<_>>(),
                &[[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]],
            ),
            looking_down_z(),
            false,
        ),
        (
            // The triangle's plane contains the eye: seen exactly edge-on.
            "edge-on triangle",
            mesh(
                &[
                    Vec3::new(-1.0, 0.0, -1.0),
                    Vec3::new(1.0, 0.0, -1.0),
                    Vec3::new(0.0, 0.0, 1.0),
                ],
                &[[0, 1, 2]],
            ),
            looking_down_z(),
            false,
        ),
        (
            // Edge-on with a corner at the eye and one behind it.
            "edge-on through the eye",
            mesh(
                &[
                    Vec3::new(-1.0, 0.0, -1.0),
                    Vec3::new(0.0, 0.0, 3.0),
                    Vec3::new(0.5, 0.0, 5.0),
                ],
                &[[0, 1, 2]],
            ),
            looking_down_z(),
            false,
        ),
        (
            "entirely behind the camera",
            mesh(
                &[
                    Vec3::new(-1.0, -1.0, 5.0),
                    Vec3::new(1.0, -1.0, 5.0),
                    Vec3::new(0.0, 1.0, 5.0),
                ],
                &[[0, 1, 2]],
            ),
            looking_down_z(),
            false,
        ),
        (
            "entirely outside the view",
            mesh(
                &[
                    Vec3::new(40.0, -1.0, 0.0),
                    Vec3::new(42.0, -1.0, 0.0),
                    Vec3::new(41.0, 1.0, 0.0),
                ],
                &[[0, 1, 2]],
            ),
            looking_down_z(),
            false,
        ),
        (
            "beyond the far plane",
            one.clone(),
            camera(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, 0.1, 2.0),
            false,
        ),
    ];
    for (name, m, cam, visible) in &cases {
        for edges in [EdgeSelection::All, EdgeSelection::Feature(1.0)] {
            let frame = draw(m, *cam, edges);
            let covered = check(name, m, &frame);
            if *visible {
                assert!(covered > 100, "{name}: only {covered} pixels covered");
            } else if name.contains("behind") || name.contains("outside") || name.contains("far") {
                assert_eq!(covered, 0, "{name}: {covered} pixels covered");
                assert!(frame.edge_distance.iter().all(|d| *d == f32::INFINITY));
            }
        }
    }
}

#[test]
fn degenerate_triangles_never_shade_nan() {
    // A zero-area triangle over a background: the image must be finite colours (8-bit
    // anyway), and every pixel either background or the one real triangle's.
    let m = mesh(
        &[
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 0.5),
        ],
        &[[3, 3, 3], [0, 1, 2], [3, 3, 0]],
    );
    let frame = draw(&m, looking_down_z(), EdgeSelection::All);
    check("zero-area in front", &m, &frame);
    assert!(
        frame.ids.iter().all(|&id| id == u32::MAX || id == 1),
        "only the real triangle is visible"
    );
}
