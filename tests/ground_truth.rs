//! Accuracy of the deferred method against the CPU ray-cast ground truth, on the shared meshes
//! under an ordinary camera and four hard ones, in two looks: every edge at 1.5 px, and
//! feature edges (30°) at 3 px; both with full-width outlines. Run in release mode
//! (`cargo test --release`): the ground truth is a CPU ray cast.
//!
//! Bounds (deferred): id agreement ≥ 0.999 among pixels where either side is foreground;
//! edge-distance error p99 ≤ 0.01 px and max ≤ 0.1 px over pixels whose ids agree (background
//! included, where outlines reach) and whose true distance is under 4 px.

// `!(a < b)` is deliberate throughout: NaN must fail the test, not pass it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod common;

use common::{framing, gpu, load, shoot, MAX_ERROR_PX, MAX_P99_PX, MIN_ID_AGREEMENT};
use glam::{DVec3, Vec3};
use wirepass::tools::compare::{metrics, Metrics};
use wirepass::tools::offline::Method;
use wirepass::truth::RayCaster;
use wirepass::world::{Shot, World};
use wirepass::{Camera, EdgeSelection, Mesh, Style};

const SIZE: (u32, u32) = (320, 240);

/// The hard cameras, each built from the mesh itself so it means the same on every mesh.
#[derive(Clone, Copy, Debug)]
enum Pose {
    /// The automatic framing: front-right-above, whole mesh in view.
    Ordinary,
    /// Looking at a surface point along its tangent plane, 4° above it.
    Grazing,
    /// Eye 2 % of the mesh radius above a surface point, looking at it obliquely.
    Close,
    /// Eye just under the surface looking along it, near plane cutting the triangles.
    Inside,
    /// The ordinary view from so far that the mean triangle covers 0.05 px².
    Far,
}

const POSES: [Pose; 5] = [
    Pose::Ordinary,
    Pose::Grazing,
    Pose::Close,
    Pose::Inside,
    Pose::Far,
];

/// A surface point seen at the image centre of the framing camera, with its unit face normal
/// turned towards that camera.
fn surface_point(mesh: &Mesh, framed: &Camera) -> (DVec3, DVec3) {
    let world = World::single(mesh.clone(), EdgeSelection::All);
    let caster = RayCaster::new(&world);
    let eye = framed.eye.as_dvec3();
    let target = framed.target.as_dvec3();
    let far = eye + (target - eye) * 10.0;
    let hit = caster
        .cast(eye, far)
        .expect("the framing camera's central ray hits the mesh");
    let t = mesh.triangles()[hit.id as usize].map(|v| mesh.positions()[v as usize].as_dvec3());
    let mut n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
    if n.dot(eye - hit.point) < 0.0 {
        n = -n;
    }
    (hit.point, n)
}

/// Mean projected triangle area in the far shot, px².
const FAR_TRIANGLE_AREA: f64 = 0.05;

/// Mean screen area, in px², of the mesh's triangles under `camera` at `SIZE`.
fn mean_triangle_area(mesh: &Mesh, camera: &Camera) -> f64 {
    let vp = camera.view_projection(SIZE.0, SIZE.1);
    let half = glam::DVec2::new(f64::from(SIZE.0), f64::from(SIZE.1)) * 0.5;
    let total: f64 = mesh
        .triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| {
                let p = vp.project_point3(mesh.positions()[v as usize].as_dvec3());
                glam::DVec2::new(p.x, p.y) * half
            });
            0.5 * (b - a).perp_dot(c - a).abs()
        })
        .sum();
    total / mesh.triangle_count() as f64
}

fn camera(mesh: &Mesh, pose: Pose) -> Camera {
    let (lo, hi) = mesh.bounds_f64();
    let framed = framing(mesh, SIZE);
    let radius = (hi - lo).length() * 0.5;
    let (p, n) = surface_point(mesh, &framed);
    // A tangent direction, away from the framing eye's side so the view crosses the mesh.
    let toward_eye = framed.eye.as_dvec3() - p;
    let tangent = (toward_eye - n * toward_eye.dot(n))
        .try_normalize()
        .unwrap_or_else(|| n.any_orthonormal_vector());
    let up = |dir: DVec3| {
        if dir.normalize().cross(DVec3::Y).length() > 0.1 {
            Vec3::Y
        } else {
            Vec3::Z
        }
    };
    let make = |eye: DVec3, target: DVec3, near: f64, far: f64| Camera {
        eye: eye.as_vec3(),
        target: target.as_vec3(),
        up: up(target - eye),
        fov_y_deg: 50.0,
        near: near as f32,
        far: far as f32,
    };
    let cam = match pose {
        Pose::Ordinary => framed,
        Pose::Grazing => {
            let a = 4f64.to_radians();
            let eye = p + (tangent * a.cos() + n * a.sin()) * (1.5 * radius);
            make(eye, p, 0.01 * radius, 5.0 * radius)
        }
        Pose::Close => {
            let eye = p + n * (0.02 * radius) + tangent * (0.01 * radius);
            make(eye, p, 0.001 * radius, 4.0 * radius)
        }
        Pose::Inside => {
            let eye = p - n * (0.01 * radius);
            make(eye, eye - tangent * radius, 0.03 * radius, 4.0 * radius)
        }
        Pose::Far => {
            // Back off until the mean projected triangle covers 0.05 px² (area scales with
            // the inverse square of the distance, near enough at this range).
            let k = (mean_triangle_area(mesh, &framed) / FAR_TRIANGLE_AREA)
                .sqrt()
                .max(1.0);
            let target = framed.target.as_dvec3();
            let eye = target + (framed.eye.as_dvec3() - target) * k;
            let d = (eye - target).length();
            Camera {
                eye: eye.as_vec3(),
                near: (d - 2.0 * radius) as f32,
                far: (d + 2.0 * radius) as f32,
                ..framed
            }
        }
    };
    cam.validate().unwrap_or_else(|e| panic!("{pose:?}: {e}"));
    cam
}

/// The two looks: (edge selection, line width).
const LOOKS: [(EdgeSelection, f32); 2] = [
    (EdgeSelection::All, 1.5),
    (EdgeSelection::Feature(30.0), 3.0),
];

fn measure(
    mesh: &Mesh,
    pose: Pose,
    (edges, line_width): (EdgeSelection, f32),
) -> (Metrics, String) {
    let style = Style {
        line_width,
        ..Style::default()
    };
    let cam = camera(mesh, pose);
    let truth = shoot(mesh, cam, &style, SIZE, edges, Method::Raycast);
    let frame = shoot(mesh, cam, &style, SIZE, edges, Method::Deferred);
    let m = metrics(&truth, &frame).unwrap_or_else(|e| panic!("{e}"));
    (m, common::worst_pixels(&truth, &frame, MAX_ERROR_PX, 5))
}

/// Measures every shot of `name`, prints the numbers, then checks the bounds (all shots are
/// measured and printed before any assertion fails).
fn check(name: &str) {
    let mesh = load(name);
    let mut failures = Vec::new();
    let mut feature_pixels = 0;
    for (pose, look) in POSES.iter().flat_map(|&s| LOOKS.map(|l| (s, l))) {
        let (m, worst) = measure(&mesh, pose, look);
        let d = m.distance_error_px;
        let line = format!(
            "{name:<20} {pose:<9} {:<12} id {:.5} coverage {:.5} distance p99 {:.2e} max {:.2e} ({} px)",
            format!("{:?}", look.0),
            m.id_agreement,
            m.coverage_agreement,
            d.p99.unwrap_or(f64::NAN),
            d.max.unwrap_or(f64::NAN),
            d.pixels,
            pose = format!("{pose:?}"),
        );
        println!("{line}");
        if m.id_agreement < MIN_ID_AGREEMENT {
            failures.push(format!("{line}: id agreement under {MIN_ID_AGREEMENT}"));
        }
        // Every shot shows edges in the first look; the feature look may show none up close.
        if d.pixels == 0 && look == LOOKS[0] {
            failures.push(format!("{line}: no pixel to measure the distance on"));
        }
        if look == LOOKS[1] {
            feature_pixels += d.pixels;
        }
        if d.p99.is_some_and(|v| !(v <= MAX_P99_PX)) {
            failures.push(format!("{line}: distance p99 over {MAX_P99_PX} px"));
        }
        if d.max.is_some_and(|v| !(v <= MAX_ERROR_PX)) {
            failures.push(format!(
                "{line}: distance max over {MAX_ERROR_PX} px{worst}"
            ));
        }
    }
    if feature_pixels == 0 {
        failures.push(format!(
            "{name}: no shot measured a feature edge or outline"
        ));
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn bunny() {
    check("stanford-bunny.obj");
}

#[test]
fn fandisk() {
    check("fandisk.obj");
}

#[test]
fn suzanne() {
    check("suzanne.obj");
}

#[test]
fn spot() {
    check("spot.obj");
}

#[test]
fn teapot() {
    check("teapot.obj");
}

/// `compare::run` writes every file it promises, and report.json has the documented shape.
#[test]
fn compare_writes_images_and_report() {
    let mesh = load("suzanne.obj");
    let size = (96, 72);
    let world = World::single(mesh.clone(), EdgeSelection::Polygon);
    let style = Style::default();
    let shot = Shot {
        world: &world,
        view: framing(&mesh, size).to_view(96.0 / 72.0),
        style: &style,
        size,
    };
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("compare_suzanne");
    let _ = std::fs::remove_dir_all(&out);
    let report =
        wirepass::tools::compare::run(gpu(), &shot, &out).unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(out.join("report.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(json["size"], serde_json::json!([96, 72]));
    assert_eq!(json["triangles"], mesh.triangle_count());
    let methods = json["methods"].as_object().unwrap();
    assert!(
        !methods.contains_key("raycast"),
        "the reference is not a method"
    );
    for &m in Method::ALL.iter().filter(|&&m| m != Method::Raycast) {
        let key = m.name().replace('-', "_");
        let entry = &methods[&key];
        assert!(entry.is_object(), "{key} missing from {text}");
        if entry.get("skipped").is_some() {
            continue;
        }
        for field in ["id_agreement", "coverage_agreement", "gpu_ms", "wall_ms"] {
            assert!(entry.get(field).is_some(), "{key}.{field} missing");
        }
        for field in ["mean", "p99", "max"] {
            assert!(entry["distance_error_px"].get(field).is_some());
        }
        assert!(entry["image_difference"]["flip_mean"].is_number());
        for file in [
            format!("{}.png", m.name()),
            format!("{key}_distance_error.png"),
            format!("{key}_flip.png"),
        ] {
            assert!(out.join(&file).is_file(), "{file} not written");
        }
    }
    let deferred = &methods["deferred"];
    assert!(deferred["id_agreement"].as_f64().unwrap() >= MIN_ID_AGREEMENT);
    for file in ["raycast.png", "sheet.png"] {
        assert!(out.join(file).is_file(), "{file} not written");
    }
    assert!(wirepass::tools::compare::table(&report).contains("deferred"));
}
