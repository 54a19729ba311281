//! Surfaces that pass through each other: a mesh through itself (two boxes modelled in one
//! file, Suzanne's eyes through its head) and instances through each other. A line point
//! that a nearer surface hides is not drawn, whatever patch it belongs to: the deferred
//! pass matches the ground truth over every pixel, with ordinary, grazing, orthographic and
//! eye-inside cameras and in every edge mode. Intersection lines (where the surfaces meet)
//! match the ground truth the same way, and their class too.

mod common;

use common::{
    load, spot_beside_suzanne, teapot_behind_slab, truth_and_frame, within_bounds, SIDE_BY_SIDE,
    THROUGH,
};
use glam::{DMat4, DVec3, Vec3};
use std::sync::Arc;
use wirepass::world::{LineClass, Object, World, WorldMesh};
use wirepass::{EdgeSelection, Mesh, Style, View};

const SIZE: (u32, u32) = (320, 240);

/// The unit cube's 12 triangles (`wirepass::mesh::cube`) at half-size `half`, turned by
/// `turn` (radians about y, then x) and moved to `centre`, appended to `positions` and
/// `triangles` with its quads' diagonals undrawn (`polygon`).
fn add_box(
    centre: Vec3,
    half: f32,
    turn: (f32, f32),
    positions: &mut Vec<Vec3>,
    triangles: &mut Vec<[u32; 3]>,
    polygon: &mut Vec<u8>,
) {
    let cube = wirepass::mesh::cube(12).unwrap();
    let rotation = glam::Quat::from_rotation_x(turn.1) * glam::Quat::from_rotation_y(turn.0);
    let base = positions.len() as u32;
    positions.extend(
        cube.positions()
            .iter()
            .map(|&p| centre + rotation * (half * p)),
    );
    triangles.extend(cube.triangles().iter().map(|t| t.map(|v| v + base)));
    polygon.extend(cube.edge_mask(EdgeSelection::Polygon));
}

/// Two boxes through each other, one turned, as one mesh.
fn two_boxes() -> Mesh {
    let (mut p, mut t, mut m) = (Vec::new(), Vec::new(), Vec::new());
    add_box(Vec3::ZERO, 1.0, (0.0, 0.0), &mut p, &mut t, &mut m);
    add_box(
        Vec3::new(0.9, 0.45, 0.35),
        0.7,
        (0.5, 0.35),
        &mut p,
        &mut t,
        &mut m,
    );
    Mesh::new(p, None, t, Some(m)).unwrap()
}

fn perspective(eye: DVec3, target: DVec3) -> View {
    wirepass::Camera {
        eye: eye.as_vec3(),
        target: target.as_vec3(),
        up: Vec3::Y,
        fov_y_deg: 50.0,
        near: 0.02,
        far: 100.0,
    }
    .to_view(f64::from(SIZE.0) / f64::from(SIZE.1))
}

/// The deferred frame against the ground truth over every pixel; returns how many pixels
/// the truth draws a line in, and how many of them an intersection line colours most
/// (where the frame's line there is of that class too, within a pixel in 200).
fn check(name: &str, world: &World, view: View, style: &Style) -> (usize, usize) {
    let (truth, frame) = truth_and_frame(world, view, style, SIZE);
    let class = LineClass::Intersection as u8;
    let crossing = (0..truth.line_class.len()).filter(|&i| truth.line_class[i] == class);
    let (count, agree) = crossing.fold((0, 0), |(n, a), i| {
        (n + 1, a + usize::from(frame.line_class[i] == class))
    });
    assert!(
        200 * agree >= 199 * count,
        "{name}: {agree} of {count} intersection-line pixels agree"
    );
    let lines = within_bounds(name, &truth, &frame).lines;
    assert!(lines.pixels > 0, "{name}: no line pixels");
    (lines.pixels, count)
}

/// Cameras that look at the crossing of the two boxes: ordinary, grazing along the first
/// box's top face, orthographic, and from inside the first box.
fn cameras(target: DVec3) -> Vec<(&'static str, View)> {
    let aspect = f64::from(SIZE.0) / f64::from(SIZE.1);
    vec![
        ("ordinary", perspective(DVec3::new(3.0, 2.2, 3.6), target)),
        ("grazing", perspective(DVec3::new(4.5, 1.03, 0.4), target)),
        (
            "orthographic",
            View::orthographic(
                (DVec3::new(2.0, 3.0, 2.5), target, DVec3::Y),
                3.6,
                aspect,
                (-10.0, 10.0),
            ),
        ),
        (
            "eye inside",
            perspective(DVec3::new(-0.6, 0.2, 0.3), DVec3::new(1.2, 0.5, 0.4)),
        ),
    ]
}

#[test]
fn the_crossing_triangles_are_found() {
    let boxes = two_boxes();
    let crossing = boxes.crossed_triangles();
    let count = crossing.iter().filter(|&&c| c).count();
    println!("two boxes: {count} of {} triangles cross", crossing.len());
    assert!(count >= 6 && count < crossing.len(), "{count}");
    let suzanne = load("suzanne.obj");
    let count = suzanne.crossed_triangles().iter().filter(|&&c| c).count();
    println!(
        "suzanne: {count} of {} triangles cross",
        suzanne.triangle_count()
    );
    assert!(count > 0, "Suzanne's eyes pass through its head");
    for name in ["fandisk.obj", "spot.obj"] {
        let mesh = load(name);
        let count = mesh.crossed_triangles().iter().filter(|&&c| c).count();
        assert_eq!(
            count, 0,
            "{name}: a closed, embedded surface crosses nothing"
        );
    }
}

#[test]
fn a_mesh_through_itself_draws_its_lines_only_where_they_are_visible() {
    let target = DVec3::new(0.6, 0.3, 0.2);
    for (edges, width) in [
        (EdgeSelection::Polygon, 1.5),
        (EdgeSelection::All, 1.5),
        (EdgeSelection::Feature(30.0), 4.0),
    ] {
        let world = World::single(two_boxes(), edges);
        let style = Style {
            line_width: width,
            ..Style::default()
        };
        for (camera, view) in cameras(target) {
            check(
                &format!("two boxes, {edges:?}, {camera}"),
                &world,
                view,
                &style,
            );
        }
    }
}

#[test]
fn suzannes_eyes_through_its_head() {
    let mesh = load("suzanne.obj");
    let (lo, hi) = mesh.bounds_f64();
    // Suzanne looks along +z; its eyes are about 0.7 in front of its centre.
    let c = 0.5 * (lo + hi);
    let world = World::single(mesh, EdgeSelection::Polygon);
    let eyes = c + DVec3::new(0.0, 0.2, 0.7);
    for (camera, view) in [
        ("front", perspective(c + DVec3::new(0.8, 0.6, 3.0), eyes)),
        ("close", perspective(c + DVec3::new(0.5, 0.45, 1.6), eyes)),
        (
            "inside",
            perspective(
                c + DVec3::new(0.1, 0.15, 0.1),
                c + DVec3::new(0.5, 0.3, 0.9),
            ),
        ),
    ] {
        check(
            &format!("suzanne, {camera}"),
            &world,
            view,
            &Style::default(),
        );
    }
}

/// Two boxes (one turned) and a mirrored Suzanne through the first box's -x face, as
/// instances of two meshes.
fn crossed_instances() -> World {
    let (mut p, mut t, mut m) = (Vec::new(), Vec::new(), Vec::new());
    add_box(Vec3::ZERO, 1.0, (0.0, 0.0), &mut p, &mut t, &mut m);
    let cube = Mesh::new(p, None, t, Some(m)).unwrap();
    let suzanne = load("suzanne.obj");
    let (lo, hi) = suzanne.bounds_f64();
    let centred = DMat4::from_translation(-0.5 * (lo + hi));
    World {
        meshes: vec![
            WorldMesh {
                mesh: Arc::new(cube),
                edges: EdgeSelection::Polygon,
                name: "box".into(),
            },
            WorldMesh {
                mesh: Arc::new(suzanne),
                edges: EdgeSelection::Polygon,
                name: "suzanne".into(),
            },
        ],
        objects: vec![
            Object::new(0, DMat4::IDENTITY),
            Object::new(
                0,
                DMat4::from_translation(DVec3::new(0.9, 0.45, 0.35))
                    * DMat4::from_euler(glam::EulerRot::YXZ, 0.5, 0.35, 0.0)
                    * DMat4::from_scale(DVec3::splat(0.7)),
            ),
            // Mirrored, through the first box's -x face.
            Object::new(
                1,
                DMat4::from_translation(DVec3::new(-1.2, 0.1, 0.3))
                    * DMat4::from_scale(DVec3::new(-0.6, 0.6, 0.6))
                    * centred,
            ),
        ],
        sections: Vec::new(),
    }
}

#[test]
fn instances_through_each_other() {
    let world = crossed_instances();
    for (camera, view) in cameras(DVec3::new(0.2, 0.3, 0.1)) {
        check(
            &format!("instances, {camera}"),
            &world,
            view,
            &Style::default(),
        );
    }
    // Along the box's -x face, through which the mirrored Suzanne passes: the trace
    // pass's pieces see through wide windows (crossed instances) at every sample.
    check(
        "instances, along a crossed face",
        &world,
        perspective(DVec3::new(-1.0, 0.5, 2.2), DVec3::new(-1.2, 0.2, 0.3)),
        &Style::default(),
    );
    // Suzanne's head seen through the box's face it crosses, with hidden lines.
    let hidden = Style {
        hidden: Some(wirepass::HiddenLines::default()),
        ..Style::default()
    };
    check(
        "instances, hidden lines",
        &world,
        perspective(DVec3::new(-3.2, 1.2, 2.0), DVec3::new(-0.8, 0.2, 0.2)),
        &hidden,
    );
    // The mirrored Suzanne's eyes, their intersection lines drawn through its transform.
    let crossings = Style {
        intersection_lines: true,
        intersection_line_width: Some(2.0),
        ..Style::default()
    };
    let (_, crossing) = check(
        "instances, intersection lines",
        &world,
        perspective(DVec3::new(-1.3, 0.3, 2.8), DVec3::new(-1.2, 0.15, 0.3)),
        &crossings,
    );
    assert!(
        crossing > 0,
        "the mirrored eyes' intersection lines are drawn"
    );
}

/// Instances whose bounds meet but whose surfaces do not cross are drawn as any two
/// instances are (each pixel's own triangle gives its lines; with hidden lines, the wide
/// way), and match the ground truth as closely as those that do cross, from every camera;
/// tests/work.rs holds the pieces each way lists.
#[test]
fn instances_whose_bounds_meet_but_not_their_surfaces() {
    let hidden = Style {
        hidden: Some(wirepass::HiddenLines::default()),
        ..Style::default()
    };
    for (what, shift) in [("apart", SIDE_BY_SIDE), ("crossed", THROUGH)] {
        let world = spot_beside_suzanne(shift);
        for (camera, view) in cameras(DVec3::new(0.4, 0.0, 0.0)) {
            check(
                &format!("{what}, {camera}"),
                &world,
                view,
                &Style::default(),
            );
        }
        check(
            &format!("{what}, between them, hidden lines"),
            &world,
            perspective(DVec3::new(0.5, 0.9, 2.4), DVec3::new(0.45, 0.0, 0.0)),
            &hidden,
        );
    }
}

/// The intersection lines of the two boxes through each other (`boxes`, in an edge mode)
/// from every camera of `cameras`, thin and wide, against the ground truth.
fn boxes_from_every_camera(what: &str, boxes: impl Fn(EdgeSelection) -> World) {
    for (edges, width) in [
        (EdgeSelection::Polygon, 1.5),
        (EdgeSelection::Feature(30.0), 3.0),
    ] {
        let world = boxes(edges);
        let style = Style {
            intersection_lines: true,
            intersection_line_width: Some(width),
            ..Style::default()
        };
        let mut drawn = 0;
        for (camera, view) in cameras(DVec3::new(0.6, 0.3, 0.2)) {
            let (_, crossing) = check(
                &format!("{what}, intersection lines, {edges:?}, {camera}"),
                &world,
                view,
                &style,
            );
            drawn += usize::from(crossing > 0);
        }
        // From inside the first box its walls hide the second's crossing; the other
        // cameras see it.
        assert!(
            drawn >= 3,
            "{what}, {edges:?}: {drawn} views draw intersection lines"
        );
    }
}

/// A box mesh, polygon edges.
fn box_mesh() -> Arc<Mesh> {
    let (mut p, mut t, mut m) = (Vec::new(), Vec::new(), Vec::new());
    add_box(Vec3::ZERO, 1.0, (0.0, 0.0), &mut p, &mut t, &mut m);
    Arc::new(Mesh::new(p, None, t, Some(m)).unwrap())
}

/// Two instances of one box through each other, the second moved by `shift`, turned and
/// shrunk; and `more` objects of other meshes.
fn boxes_as_instances(shift: DVec3, edges: EdgeSelection) -> World {
    World {
        meshes: vec![WorldMesh {
            mesh: box_mesh(),
            edges,
            name: "box".into(),
        }],
        objects: vec![
            Object::new(0, DMat4::IDENTITY),
            Object::new(
                0,
                DMat4::from_translation(shift)
                    * DMat4::from_euler(glam::EulerRot::YXZ, 0.5, 0.35, 0.0)
                    * DMat4::from_scale(DVec3::splat(0.7)),
            ),
        ],
        sections: Vec::new(),
    }
}

/// Intersection lines between instances (where two placed surfaces meet, found as the frame
/// is prepared): the boxes as two instances of one mesh (every camera, both edge modes),
/// dense spheres through each other (one stretched, one mirrored) with wide lines, against
/// the ground truth over every pixel.
#[test]
fn intersection_lines_between_instances() {
    let shift = DVec3::new(0.9, 0.45, 0.35);
    boxes_from_every_camera("box instances", |edges| boxes_as_instances(shift, edges));
    let sphere = Arc::new(wirepass::mesh::sphere(20_000).unwrap());
    let world = World {
        meshes: vec![WorldMesh {
            mesh: sphere,
            edges: EdgeSelection::Polygon,
            name: "sphere".into(),
        }],
        objects: vec![
            Object::new(
                0,
                DMat4::from_rotation_y(0.4) * DMat4::from_scale(DVec3::new(1.0, 1.6, 0.7)),
            ),
            Object::new(
                0,
                DMat4::from_translation(DVec3::new(0.9, 0.5, 0.1))
                    * DMat4::from_rotation_x(1.1)
                    * DMat4::from_scale(DVec3::new(-0.8, 0.8, 0.8)),
            ),
        ],
        sections: Vec::new(),
    };
    let style = Style {
        line_width: 1.0,
        intersection_lines: true,
        intersection_line_width: Some(4.0),
        ..Style::default()
    };
    let (_, crossing) = check(
        "sphere instances, intersection lines",
        &world,
        perspective(DVec3::new(2.2, 2.0, 3.4), DVec3::new(0.5, 0.3, 0.1)),
        &style,
    );
    assert!(crossing > 0, "the spheres' intersection line is drawn");
    // The boxes cut by a section plane through their crossing: the lines end at the cut, and
    // the section faces inside show through it.
    let mut cut = boxes_as_instances(shift, EdgeSelection::Polygon);
    cut.sections = vec![wirepass::SectionPlane::new(
        DVec3::new(0.0, 0.5, 0.0),
        DVec3::new(0.3, -1.0, 0.2),
    )];
    let style = Style {
        intersection_lines: true,
        intersection_line_width: Some(2.0),
        ..Style::default()
    };
    let (_, crossing) = check(
        "box instances cut, intersection lines",
        &cut,
        perspective(DVec3::new(2.6, 3.2, 3.4), DVec3::new(0.6, 0.3, 0.2)),
        &style,
    );
    assert!(crossing > 0, "the cut boxes' intersection lines are drawn");
}

/// Intersection lines follow the instances from frame to frame of one upload: drawn where
/// the boxes cross, gone when one moves clear, back to the same bits when it returns.
#[test]
fn intersection_lines_follow_moving_instances() {
    use wirepass::gpu::Canvas;
    use wirepass::gpu::{DeferredPass, PassOptions};
    use wirepass::tools::offline::draw_deferred_on;
    use wirepass::tools::offline::Uploaded;
    use wirepass::world::Shot;
    let ctx = common::gpu();
    let crossed = boxes_as_instances(DVec3::new(0.9, 0.45, 0.35), EdgeSelection::Polygon);
    let apart = boxes_as_instances(DVec3::new(3.0, 0.45, 0.35), EdgeSelection::Polygon);
    let up = Uploaded::new(&ctx.device, &ctx.queue, &crossed).unwrap();
    let style = Style {
        intersection_lines: true,
        intersection_line_width: Some(2.0),
        ..Style::default()
    };
    let view = perspective(DVec3::new(3.0, 2.2, 4.6), DVec3::new(0.9, 0.3, 0.2));
    let draw = |world: &World| {
        let shot = Shot {
            world,
            view,
            style: &style,
            size: SIZE,
        };
        let pass = DeferredPass::new(&ctx.device, PassOptions::default()).unwrap();
        draw_deferred_on(
            ctx,
            &shot,
            &up,
            pass.with_diagnostics(),
            Canvas::new(shot.size),
        )
        .unwrap()
    };
    let class = LineClass::Intersection as u8;
    let lines =
        |r: &wirepass::world::Rendering| r.line_class.iter().filter(|&&c| c == class).count();
    let first = draw(&crossed);
    assert!(lines(&first) > 0);
    assert_eq!(lines(&draw(&apart)), 0);
    let back = draw(&crossed);
    assert!(first
        .edge_distance
        .iter()
        .zip(&back.edge_distance)
        .all(|(a, b)| a.to_bits() == b.to_bits()));
    check("box instances, moved back", &crossed, view, &style);
}

/// Intersection lines, where the surfaces of a mesh meet: the two boxes (thin and wide lines,
/// every camera; every polygon edge or the box edges) and Suzanne's eyes, against the ground truth.
#[test]
fn intersection_lines_are_drawn_where_visible() {
    boxes_from_every_camera("two boxes", |edges| World::single(two_boxes(), edges));
    let mesh = load("suzanne.obj");
    let (lo, hi) = mesh.bounds_f64();
    let c = 0.5 * (lo + hi);
    let world = World::single(mesh, EdgeSelection::Polygon);
    let eyes = c + DVec3::new(0.0, 0.2, 0.7);
    let style = Style {
        intersection_lines: true,
        intersection_line_width: Some(2.0),
        ..Style::default()
    };
    for (camera, view) in [
        ("front", perspective(c + DVec3::new(0.8, 0.6, 3.0), eyes)),
        ("close", perspective(c + DVec3::new(0.5, 0.45, 1.6), eyes)),
        ("grazing", perspective(c + DVec3::new(3.0, 0.3, 0.9), eyes)),
    ] {
        let (_, crossing) = check(
            &format!("suzanne, intersection lines, {camera}"),
            &world,
            view,
            &style,
        );
        assert!(
            crossing > 0,
            "{camera}: the eyes' intersection lines are drawn"
        );
    }
}

/// The same frame drawn again from the same upload is the same to the bit: a batch of the
/// trace pass's pieces (wide visibility windows where instances cross) keeps under
/// llvmpipe's loop cap whichever pieces share it (`src/gpu/loop_budget.rs`). The cameras look
/// along the box's -x face, through which the mirrored Suzanne passes, and through it.
#[test]
fn crossed_instances_draw_the_same_frame_every_time() {
    use wirepass::gpu::Canvas;
    use wirepass::gpu::{DeferredPass, PassOptions};
    use wirepass::tools::offline::draw_deferred_on;
    use wirepass::tools::offline::Uploaded;
    use wirepass::world::Shot;
    let world = crossed_instances();
    let ctx = common::gpu();
    let up = Uploaded::new(&ctx.device, &ctx.queue, &world).unwrap();
    // And with lines as wide as loop_budget::COVERED_WIDTH, hidden lines too.
    let wide = Style {
        line_width: 16.0,
        outline_width: Some(16.0),
        hidden: Some(wirepass::HiddenLines {
            width: 16.0,
            ..wirepass::HiddenLines::default()
        }),
        ..Style::default()
    };
    let along = (DVec3::new(-1.0, 0.5, 2.2), DVec3::new(-1.2, 0.2, 0.3));
    let through = (DVec3::new(-3.2, 1.2, 2.0), DVec3::new(-0.8, 0.2, 0.2));
    for ((eye, target), style) in [
        (along, Style::default()),
        (through, Style::default()),
        (along, wide),
    ] {
        let shot = Shot {
            world: &world,
            view: perspective(eye, target),
            style: &style,
            size: SIZE,
        };
        let draw = || {
            let pass = DeferredPass::new(&ctx.device, PassOptions::default()).unwrap();
            draw_deferred_on(
                ctx,
                &shot,
                &up,
                pass.with_diagnostics(),
                Canvas::new(shot.size),
            )
            .unwrap()
        };
        let first = draw();
        for round in 1..6 {
            let again = draw();
            let bits = |r: &wirepass::world::Rendering| {
                let maps = r.edge_distance.iter().chain(&r.hidden_distance);
                maps.map(|d| d.to_bits()).collect::<Vec<_>>()
            };
            let (a, b) = (bits(&first), bits(&again));
            let differ = a.iter().zip(&b).filter(|(a, b)| a != b).count();
            assert_eq!(
                differ, 0,
                "eye {eye}: {differ} pixels differ in round {round}"
            );
            assert_eq!(
                first.ids, again.ids,
                "eye {eye}: ids differ in round {round}"
            );
        }
    }
}

/// A teapot (its spout and handle pass through its body, so its lines look for surfaces in
/// front of them over a wider window) behind a slab whose top face, seen nearly edge-on,
/// lies between two rows of pixel centres: the top face hides the teapot's outline where it
/// passes behind it, found by a walk from the slab's front face. That face is met first at
/// the window's outer ring, whose walks take few steps, and again next to the point.
#[test]
fn a_face_between_pixel_centres_hides_an_outline_in_the_wide_window() {
    let world = teapot_behind_slab();
    // The slab's top face spans image rows 97.55 to 98.3 where the outline passes behind it.
    let view = wirepass::Camera {
        eye: Vec3::new(0.5, 2.5, 9.0),
        target: Vec3::new(0.217, 1.575, 0.25),
        up: Vec3::Y,
        fov_y_deg: 45.0,
        near: 0.05,
        far: 100.0,
    }
    .to_view(f64::from(SIZE.0) / f64::from(SIZE.1));
    check("teapot behind a slab", &world, view, &Style::default());
}
