//! Scenes of instances through the host's own views, against the ray-cast ground truth:
//! overlapping instances (one mirrored and non-uniformly scaled), orthographic views (front,
//! grazing, and one the mesh fills), an infinite far plane, reverse-Z against standard-Z, an
//! instance moved between frames, a thousand instances, and a scene file with an
//! orthographic camera.
//!
//! Bounds (deferred), as in tests/ground_truth.rs: id agreement ≥ 0.999, edge-distance error
//! p99 ≤ 0.01 px and max ≤ 0.1 px, outlines on.

mod common;

use common::{load, shoot_world, truth_and_frame, within_bounds};
use glam::{DMat4, DQuat, DVec3};
use std::sync::Arc;
use wirepass::tools::compare::metrics;
use wirepass::tools::offline::Method;
use wirepass::world::{Object, Rendering, World, WorldMesh, BACKGROUND};
use wirepass::{Camera, DepthRange, EdgeSelection, InstanceStyle, Mesh, Style, View};

const SIZE: (u32, u32) = (320, 240);
const ASPECT: f64 = 320.0 / 240.0;

fn world(meshes: Vec<(Mesh, EdgeSelection)>, objects: Vec<(usize, DMat4)>) -> World {
    World {
        sections: Vec::new(),
        meshes: meshes
            .into_iter()
            .map(|(mesh, edges)| WorldMesh {
                mesh: Arc::new(mesh),
                edges,
                name: "test".into(),
            })
            .collect(),
        objects: objects
            .into_iter()
            .map(|(mesh, transform)| Object {
                mesh,
                transform,
                style: InstanceStyle::default(),
            })
            .collect(),
    }
}

/// The deferred frame against the ground truth, within the accuracy bounds; panics past
/// them.
fn check(name: &str, world: &World, view: View, style: &Style) -> Rendering {
    let (truth, frame) = truth_and_frame(world, view, style, SIZE);
    let d = within_bounds(name, &truth, &frame).lines;
    assert!(d.pixels > 500, "{name}: only {} pixels measured", d.pixels);
    frame
}

/// A camera looking at `world` from the framing direction.
fn framing(world: &World) -> Camera {
    let (lo, hi) = world.bounds();
    Camera::framing(lo, hi, ASPECT)
}

#[test]
fn overlapping_instances_one_mirrored_and_stretched() {
    let suzanne = load("suzanne.obj");
    let mirrored = DMat4::from_translation(DVec3::new(0.9, 0.2, -0.6))
        * DMat4::from_quat(DQuat::from_rotation_y(0.6))
        * DMat4::from_scale(DVec3::new(-1.2, 0.8, 1.0));
    assert!(mirrored.determinant() < 0.0);
    for edges in [EdgeSelection::Polygon, EdgeSelection::Feature(30.0)] {
        let w = world(
            vec![(suzanne.clone(), edges)],
            vec![(0, DMat4::IDENTITY), (0, mirrored)],
        );
        let view = framing(&w).to_view(ASPECT);
        let style = Style {
            line_width: 2.0,
            ..Style::default()
        };
        let frame = check(&format!("two suzannes {edges:?}"), &w, view, &style);
        // Both instances show, and the second's ids follow the first's.
        let n = suzanne.triangle_count() as u32;
        let first = frame.ids.iter().filter(|&&id| id < n).count();
        let second = frame
            .ids
            .iter()
            .filter(|&&id| id >= n && id < 2 * n)
            .count();
        assert!(first > 1000 && second > 1000, "{first} and {second} pixels");
    }
}

#[test]
fn orthographic_views_front_grazing_and_filling() {
    let fandisk = load("fandisk.obj");
    let (lo, hi) = fandisk.bounds_f64();
    let centre = (lo + hi) * 0.5;
    let radius = (hi - lo).length() * 0.5;
    let w = world(
        vec![(fandisk, EdgeSelection::Feature(30.0))],
        vec![(0, DMat4::IDENTITY)],
    );
    let style = Style {
        line_width: 3.0,
        ..Style::default()
    };
    let views = [
        (
            "ortho front",
            View::orthographic(
                (centre + DVec3::Z * 3.0 * radius, centre, DVec3::Y),
                2.5 * radius,
                ASPECT,
                (0.5 * radius, 6.0 * radius),
            ),
        ),
        (
            "ortho grazing",
            View::orthographic(
                (
                    centre + DVec3::new(3.0, 0.15, 0.4).normalize() * 3.0 * radius,
                    centre,
                    DVec3::Y,
                ),
                2.5 * radius,
                ASPECT,
                (0.5 * radius, 6.0 * radius),
            ),
        ),
        (
            "ortho filling the image",
            View::orthographic(
                (
                    centre + DVec3::new(0.4, 0.5, 1.0).normalize() * 3.0 * radius,
                    centre,
                    DVec3::Y,
                ),
                0.4 * radius,
                ASPECT,
                (-2.0 * radius, 6.0 * radius),
            ),
        ),
    ];
    for (name, view) in views {
        let frame = check(name, &w, view, &style);
        if name.contains("filling") {
            let covered = frame.ids.iter().filter(|&&id| id != BACKGROUND).count();
            assert!(covered * 10 > frame.ids.len() * 9, "{name}: {covered}");
        }
    }
}

/// The bunny framed, with the far plane at infinity, and with standard and reversed depth:
/// one image whatever the depth convention.
#[test]
fn infinite_far_and_reversed_depth() {
    let bunny = load("stanford-bunny.obj");
    let w = world(
        vec![(bunny, EdgeSelection::Polygon)],
        vec![(0, DMat4::IDENTITY)],
    );
    let cam = Camera {
        far: f32::INFINITY,
        ..framing(&w)
    };
    let style = Style::default();
    check("infinite far", &w, cam.to_view(ASPECT), &style);

    use glam::dcamera::rh::proj::directx as proj;
    let fov = f64::from(cam.fov_y_deg).to_radians();
    let (near, far) = (f64::from(cam.near), 3.0 * f64::from(framing(&w).far));
    let standard = View::new(
        cam.view(),
        proj::perspective(fov, ASPECT, near, far),
        DepthRange::Standard,
    );
    let reversed = View::new(
        cam.view(),
        proj::perspective(fov, ASPECT, far, near),
        DepthRange::Reversed,
    );
    let infinite_reversed = View::new(
        cam.view(),
        proj::perspective_infinite_reverse(fov, ASPECT, near),
        DepthRange::Reversed,
    );
    let a = check("standard depth", &w, standard, &style);
    let b = check("reversed depth", &w, reversed, &style);
    let c = check("infinite reversed depth", &w, infinite_reversed, &style);
    for (name, other) in [("reversed", &b), ("infinite reversed", &c)] {
        let same = a.ids.iter().zip(&other.ids).filter(|(x, y)| x == y).count();
        assert!(
            same as f64 >= 0.9999 * a.ids.len() as f64,
            "{name}: {same} of {} ids agree",
            a.ids.len()
        );
        let m = metrics(&a, other).unwrap();
        assert!(m.image_difference.flip_mean < 1e-4, "{name}: {m:?}");
        assert!(
            m.distance_error_px.max.unwrap_or(0.0) < 1e-3,
            "{name}: {m:?}"
        );
    }
}

#[test]
fn moving_one_instance_changes_only_its_pixels() {
    let sphere = wirepass::mesh::sphere(2000).unwrap();
    let torus = wirepass::mesh::torus(3000).unwrap();
    let place = |x: f64| DMat4::from_translation(DVec3::new(x, 0.0, 0.0));
    let before = world(
        vec![
            (sphere.clone(), EdgeSelection::Polygon),
            (torus.clone(), EdgeSelection::Polygon),
        ],
        vec![(0, place(-1.5)), (1, place(1.2)), (0, place(3.5))],
    );
    let mut after = before.clone();
    after.objects[1].transform = place(1.2) * DMat4::from_rotation_x(0.7);
    let view = Camera::framing(
        DVec3::new(-3.0, -1.5, -1.5),
        DVec3::new(5.0, 1.5, 1.5),
        ASPECT,
    )
    .to_view(ASPECT);
    let style = Style::default();
    let a = shoot_world(&before, view, &style, SIZE, Method::Deferred);
    let b = shoot_world(&after, view, &style, SIZE, Method::Deferred);
    let first = before.first_ids();
    let torus_ids = first[1]..first[2];
    // Pixels showing the torus in either frame, grown by the line's reach (its outline lies
    // over its neighbours' pixels too).
    let (w, h) = (SIZE.0 as i64, SIZE.1 as i64);
    let reach = wirepass::style::line_reach(f64::from(style.line_width)).ceil() as i64 + 1;
    let mut near_torus = vec![false; a.ids.len()];
    for i in 0..a.ids.len() {
        if torus_ids.contains(&a.ids[i]) || torus_ids.contains(&b.ids[i]) {
            let (x, y) = (i as i64 % w, i as i64 / w);
            for dy in -reach..=reach {
                for dx in -reach..=reach {
                    let (qx, qy) = (x + dx, y + dy);
                    if (0..w).contains(&qx) && (0..h).contains(&qy) {
                        near_torus[(qy * w + qx) as usize] = true;
                    }
                }
            }
        }
    }
    // The torus passes through a sphere, whose lines near the crossings the trace pass
    // draws, elsewhere the edge pass: where the crossings' image moves, a line of the sphere
    // may change passes, and so its colour by rounding (one level).
    let mut changed = 0;
    for (i, &near) in near_torus.iter().enumerate() {
        let rounding = (0..4).all(|k| a.rgba[4 * i + k].abs_diff(b.rgba[4 * i + k]) <= 1);
        let differs = a.ids[i] != b.ids[i] || a.rgba[4 * i..4 * i + 4] != b.rgba[4 * i..4 * i + 4];
        if differs && !near && a.ids[i] == b.ids[i] && rounding {
            continue;
        }
        if differs {
            changed += 1;
            assert!(
                near,
                "pixel ({}, {}) changed but the torus is nowhere near it",
                i as i64 % w,
                i as i64 / w
            );
        }
    }
    assert!(changed > 500, "the move changed only {changed} pixels");
}

#[test]
fn a_thousand_instances_match_the_ground_truth() {
    let sphere = wirepass::mesh::sphere(80).unwrap();
    let objects: Vec<(usize, DMat4)> = (0..1000)
        .map(|i| {
            let (x, y, z) = (i % 10, (i / 10) % 10, i / 100);
            let offset = DVec3::new(f64::from(x), f64::from(y), f64::from(z)) * 1.6;
            let scale = 0.5 + 0.04 * f64::from(i % 7);
            (
                0,
                DMat4::from_translation(offset) * DMat4::from_scale(DVec3::splat(scale)),
            )
        })
        .collect();
    let w = world(vec![(sphere, EdgeSelection::Polygon)], objects);
    let style = Style::default();
    let frame = check("1000 spheres", &w, framing(&w).to_view(ASPECT), &style);
    let first = w.first_ids();
    let seen: std::collections::BTreeSet<usize> = frame
        .ids
        .iter()
        .filter(|&&id| id != BACKGROUND)
        .map(|&id| w.locate(&first, id).0)
        .collect();
    assert!(seen.len() > 300, "only {} instances visible", seen.len());
}

#[test]
fn a_scene_file_with_an_orthographic_camera_matches_the_ground_truth() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("scene_file_ortho");
    std::fs::create_dir_all(&dir).unwrap();
    let mesh =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes/suzanne.obj");
    let scene = dir.join("scene.json");
    std::fs::write(
        &scene,
        format!(
            r##"{{
  "objects": [
    {{"mesh": "{}", "transform": {{"rotate_deg": [0, 30, 0]}}}},
    {{"mesh": "{}", "transform": {{"translate": [1.6, 0, -1], "rotate_deg": [10, -20, 5], "scale": [-1, 1.2, 0.9]}},
      "edges": "feature:30", "wire_color": "#c03020", "line_width": 3}},
    {{"mesh": "sphere:400", "transform": {{"translate": [-1.4, -0.6, 0.5], "scale": 0.6}}, "edges": "none"}}
  ],
  "camera": {{"eye": [1, 2, 6], "target": [0.3, 0, 0], "up": [0, 1, 0],
              "orthographic": {{"height": 4, "near": 0.1, "far": 20}}}}
}}"##,
            mesh.display(),
            mesh.display()
        ),
    )
    .unwrap();
    let options = wirepass::tools::load::WorldOptions {
        edges: Some(EdgeSelection::Polygon),
        ..Default::default()
    };
    let wirepass::tools::load::Loaded { world, camera, .. } =
        wirepass::tools::load::load_world(Some(scene.to_str().unwrap()), &options).unwrap();
    assert_eq!(world.objects.len(), 3);
    assert_eq!(
        world.meshes.len(),
        3,
        "two edge selections of suzanne and the sphere"
    );
    let view = camera.expect("the file's camera").view(ASPECT);
    assert!(view.is_orthographic());
    check("scene file, orthographic", &world, view, &Style::default());
}
