//! Outlines and the depth fade, against the ground truth: the deferred pass draws outlines
//! at full width, the forward baselines at half (their error), and every method fades lines
//! with depth by the one profile.

mod common;

use common::{framing, load, TestScene};
use glam::{DVec3, Vec3};
use wirepass::style::{line_intensity, DepthFade};
use wirepass::tools::compare::metrics;
use wirepass::tools::offline::Method;
use wirepass::world::Rendering;
use wirepass::{EdgeSelection, Mesh, Style, View};

const SIZE: (u32, u32) = (256, 256);

fn scene(mesh: &Mesh, style: Style) -> TestScene {
    TestScene::new(
        mesh,
        framing(mesh, SIZE),
        style,
        SIZE,
        EdgeSelection::Feature(30.0),
    )
}

fn draw(scene: &TestScene, method: Method) -> Rendering {
    scene.draw(method)
}

/// fandisk, feature edges at 3 px: the outer half of the outline lies over the background.
/// The deferred pass draws it where the ground truth does; the forward baseline cannot
/// colour pixels outside its triangles, so those pixels have no line at all. (The two-pass
/// baseline's 1 px hardware lines spill either side of an edge at any width.)
#[test]
fn outlines_reach_over_the_background_in_deferred_only() {
    let mesh = load("fandisk.obj");
    let style = Style {
        line_width: 3.0,
        ..Style::default()
    };
    let scene = scene(&mesh, style);
    let truth = draw(&scene, Method::Raycast);
    let deferred = draw(&scene, Method::Deferred);
    let forward = draw(&scene, Method::Forward);
    // Background pixels in the core of the outline (full line colour: within 0.5 px).
    let outer: Vec<usize> = (0..truth.ids.len())
        .filter(|&i| truth.ids[i] == u32::MAX && truth.edge_distance[i] < 0.5)
        .collect();
    assert!(outer.len() > 200, "{} outer outline pixels", outer.len());
    for &i in &outer {
        assert_eq!(deferred.ids[i], u32::MAX);
        let err = (deferred.edge_distance[i] - truth.edge_distance[i]).abs();
        assert!(
            err < 0.01,
            "pixel {i}: deferred {}",
            deferred.edge_distance[i]
        );
        assert!(forward.edge_distance[i].is_infinite() || forward.ids[i] != u32::MAX);
    }
    // The whole outline's width: pixels with full line colour, counted on each side.
    let dark = |f: &Rendering| {
        (0..f.ids.len())
            .filter(|&i| line_intensity(f64::from(f.edge_distance[i]), 3.0) > 0.99)
            .count()
    };
    let (t, d, fw) = (dark(&truth), dark(&deferred), dark(&forward));
    assert!(
        (d as f64 - t as f64).abs() < 0.01 * t as f64,
        "truth {t}, deferred {d}"
    );
    assert!(fw + outer.len() / 2 < t, "forward {fw} of {t}");
    let m = metrics(&truth, &forward).unwrap();
    assert!(m.distance_error_px.max.unwrap_or(0.0) > 1.0, "{m:?}");
}

/// With outlines off the deferred pass draws the edges of small patches (here every edge, a
/// triangle mesh's polygon edges) inside their triangles, like the forward method: no
/// background pixel has a line. (Lines of large patches come from the trace pass and reach
/// over the background where they lie on a silhouette: tests/lines.rs.)
#[test]
fn outlines_off_keep_lines_inside_their_triangles() {
    let mesh = load("fandisk.obj");
    let style = Style {
        line_width: 3.0,
        outlines: false,
        ..Style::default()
    };
    let scene = TestScene::new(
        &mesh,
        framing(&mesh, SIZE),
        style,
        SIZE,
        EdgeSelection::Polygon,
    );
    let deferred = draw(&scene, Method::Deferred);
    let truth = draw(&scene, Method::Raycast);
    for f in [&deferred, &truth] {
        let lined_background = (0..f.ids.len())
            .filter(|&i| f.ids[i] == u32::MAX && f.edge_distance[i].is_finite())
            .count();
        assert_eq!(lined_background, 0);
    }
    let m = metrics(&truth, &deferred).unwrap();
    assert!(m.distance_error_px.max.unwrap() < 0.1, "{m:?}");
}

/// The depth fade over the middle fifth of the visible depths. The deferred image matches
/// the ground truth's; in every method the lines in front of the fade are untouched and those
/// behind it are gone.
#[test]
fn lines_fade_with_depth_in_every_method() {
    let mesh = load("suzanne.obj");
    let base = Style {
        line_width: 2.0,
        outlines: false,
        ..Style::default()
    };
    let plain = scene(&mesh, base.clone());
    let without_truth = draw(&plain, Method::Raycast);
    // View depth per covered pixel, from the 0..1 depth of `perspective_rh`.
    let cam = framing(&mesh, SIZE);
    let (n, f) = (f64::from(cam.near), f64::from(cam.far));
    let view_depth = |frame: &Rendering, i: usize| {
        let z = f64::from(frame.depth[i]);
        n * f / (f - z * (f - n))
    };
    let mut depths: Vec<f64> = (0..without_truth.ids.len())
        .filter(|&i| without_truth.ids[i] != u32::MAX)
        .map(|i| view_depth(&without_truth, i))
        .collect();
    depths.sort_by(f64::total_cmp);
    let at = |q: f64| depths[(q * depths.len() as f64) as usize];
    let (start, end) = (at(0.4), at(0.6));
    let fading = scene(
        &mesh,
        Style {
            depth_fade: Some(DepthFade {
                start: start as f32,
                end: end as f32,
            }),
            ..base
        },
    );
    let truth = draw(&fading, Method::Raycast);
    let deferred = draw(&fading, Method::Deferred);
    let m = metrics(&truth, &deferred).unwrap();
    assert!(m.image_difference.flip_mean < 2e-3, "{m:?}");
    for method in [Method::Deferred, Method::Forward, Method::TwoPass] {
        let with = draw(&fading, method);
        let without = draw(&plain, method);
        assert_eq!(
            with.ids, without.ids,
            "{method:?}: the fade changes no coverage"
        );
        // How much lighter the red channel gets, over pixels in front of the fade and behind.
        let lightening = |keep: &dyn Fn(f64) -> bool| -> f64 {
            (0..with.ids.len())
                .filter(|&i| with.ids[i] != u32::MAX && keep(view_depth(&without, i)))
                .map(|i| f64::from(with.rgba[4 * i]) - f64::from(without.rgba[4 * i]))
                .sum()
        };
        let near = lightening(&|w| w < 0.99 * start);
        let far = lightening(&|w| w > 1.01 * end);
        assert!(
            near.abs() < 200.0,
            "{method:?}: in front of the fade {near}"
        );
        assert!(far > 10_000.0, "{method:?}: behind the fade {far}");
    }
}

/// A box with the eye in the plane of a face, and seen along its axes orthographically: the
/// faces seen exactly edge-on fold, so the edges they share with the faces in view are
/// outlines, drawn at full width over the background. Edge-on only to rounding, such a face
/// made those edges outlines in f32 and plain edges in the ground truth's f64 (or the other
/// way round): the outline's outer half was missing (errors up to 1.8 px).
#[test]
fn faces_seen_edge_on_fold_into_outlines() {
    let cube = wirepass::mesh::cube(12).unwrap();
    let aspect = f64::from(SIZE.0) / f64::from(SIZE.1);
    let perspective =
        |eye: Vec3, target: Vec3| common::camera(eye, target, 0.1, 20.0).to_view(aspect);
    let orthographic = |eye: DVec3, up: DVec3| {
        View::orthographic((eye, DVec3::ZERO, up), 3.0, aspect, (0.1, 20.0))
    };
    let views = [
        (
            "eye in a side's plane",
            perspective(Vec3::new(-1.0, 0.5, 2.2), Vec3::new(-1.2, 0.2, 0.3)),
        ),
        (
            "eye in the top's plane",
            perspective(Vec3::new(0.3, 1.0, 3.0), Vec3::new(0.0, 0.6, 0.0)),
        ),
        (
            "orthographic, along z",
            orthographic(DVec3::new(0.0, 0.0, 5.0), DVec3::Y),
        ),
        (
            "orthographic, along x, rolled",
            orthographic(DVec3::new(5.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.6)),
        ),
    ];
    for (name, view) in views {
        let mut scene = TestScene::new(
            &cube,
            framing(&cube, SIZE),
            Style::default(),
            SIZE,
            EdgeSelection::Polygon,
        );
        scene.view = view;
        let truth = within_bounds(name, &scene);
        // The outline's core over the background, along the box's whole silhouette.
        let outer = (0..truth.ids.len())
            .filter(|&i| truth.ids[i] == u32::MAX && truth.edge_distance[i] < 0.5)
            .count();
        assert!(
            outer > 100,
            "{name}: {outer} background pixels in the outline's core"
        );
    }
}

/// A 2 M-triangle sphere at 1280×720: each pole is a fan of about 2000 slivers, and the
/// trace passes beside it, where background pixels next to the rim were once off by up to
/// 0.19 px. Every pixel within the bounds.
#[test]
fn outline_beside_a_pole_fan_of_slivers() {
    let sphere = wirepass::mesh::sphere(2_000_000).unwrap();
    let size = (1280, 720);
    let camera = framing(&sphere, size);
    let scene = TestScene::new(
        &sphere,
        camera,
        Style::default(),
        size,
        EdgeSelection::Polygon,
    );
    within_bounds("pole fan", &scene);
}

/// The deferred frame of `scene` against the ground truth over every pixel, within the
/// accuracy bounds (`common::within_bounds`); returns the truth.
fn within_bounds(name: &str, scene: &TestScene) -> Rendering {
    let truth = draw(scene, Method::Raycast);
    let deferred = draw(scene, Method::Deferred);
    common::within_bounds(name, &truth, &deferred);
    truth
}

/// A frame whose pieces overflow the trace pass's piece list draws the same lines, to the
/// bit: the clusters (and groups of intersection segments) it had no room for are drawn by
/// lanes of their own, every piece of their lines. fandisk with dashed hidden lines and a
/// section plane lists thousands of pieces; Suzanne's eyes add intersection lines.
#[test]
fn pieces_beyond_the_lists_room_are_drawn_all_the_same() {
    use wirepass::gpu::{Canvas, DeferredPass, PassOptions};
    use wirepass::tools::offline::draw_deferred_on;
    use wirepass::tools::offline::Uploaded;
    let ctx = common::gpu();
    let hidden = Style {
        hidden: Some(wirepass::HiddenLines::default()),
        ..Style::default()
    };
    let crossing = Style {
        intersection_lines: true,
        ..Style::default()
    };
    for (mesh, style) in [("fandisk.obj", hidden), ("suzanne.obj", crossing)] {
        let scene = scene(&load(mesh), style);
        let up = Uploaded::new(&ctx.device, &ctx.queue, &scene.world).unwrap();
        let draw = |room: Option<u64>| {
            let mut pass = DeferredPass::new(&ctx.device, PassOptions::default())
                .unwrap()
                .with_diagnostics();
            if let Some(room) = room {
                pass = pass.with_piece_room(room);
            }
            draw_deferred_on(ctx, &scene.shot(), &up, pass, Canvas::new(scene.size)).unwrap()
        };
        let listed = draw(None);
        let overflowed = draw(Some(64));
        let bits = |r: &Rendering| {
            let maps = r.edge_distance.iter().chain(&r.hidden_distance);
            maps.map(|d| d.to_bits()).collect::<Vec<_>>()
        };
        let lines = listed
            .edge_distance
            .iter()
            .filter(|d| d.is_finite())
            .count();
        assert!(lines > 1000, "{mesh}: {lines} line pixels");
        let (a, b) = (bits(&listed), bits(&overflowed));
        let differ = a.iter().zip(&b).filter(|(a, b)| a != b).count();
        assert_eq!(differ, 0, "{mesh}: {differ} pixels differ");
        assert_eq!(listed.rgba, overflowed.rgba, "{mesh}");
    }
}
