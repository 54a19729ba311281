//! Section planes (`Scene::sections`, `World::sections`): the deferred pass cuts surfaces
//! and lines where the ground truth does, and draws the back faces seen through the cut in
//! the section colour.

mod common;

use common::{channel_difference, load, shoot_world, truth_and_frame, within_bounds};
use glam::{DMat4, DVec3, Vec3};
use std::sync::Arc;
use wirepass::mesh::Procedural;
use wirepass::tools::offline::Method;
use wirepass::truth::accuracy::{hidden_distance_error, line_class_agreement};
use wirepass::world::LineClass;
use wirepass::world::{Object, World, WorldMesh};
use wirepass::{EdgeSelection, Error, Mesh, SectionPlane, Style, View};

const SIZE: (u32, u32) = (320, 240);

fn perspective(world: &World, eye: DVec3) -> View {
    let (lo, hi) = world.bounds();
    wirepass::Camera {
        eye: eye.as_vec3(),
        target: (0.5 * (lo + hi)).as_vec3(),
        up: Vec3::Y,
        fov_y_deg: 45.0,
        near: 0.05,
        far: 100.0,
    }
    .to_view(f64::from(SIZE.0) / f64::from(SIZE.1))
}

fn plane(point: [f64; 3], normal: [f64; 3]) -> SectionPlane {
    SectionPlane::new(DVec3::from(point), DVec3::from(normal))
}

/// The deferred frame against the ground truth; returns the pixels showing a section face
/// (a back face in the section colour) and those a cut line colours, in the truth.
fn check(name: &str, world: &World, view: View, style: &Style) -> (usize, usize) {
    let (truth, frame) = truth_and_frame(world, view, style, SIZE);
    within_bounds(name, &truth, &frame);
    // Colours where both show the same triangle away from lines: the section face and the
    // shaded surface alike.
    let section = style.section_color.to_srgb8();
    let (mut faces, mut worst_channel) = (0, 0);
    for i in 0..truth.ids.len() {
        if truth.ids[i] != frame.ids[i] || truth.edge_distance[i] < 3.0 {
            continue;
        }
        worst_channel = worst_channel.max(channel_difference(&truth, &frame, i));
        if truth.rgba[4 * i..4 * i + 3] == section[..3] {
            faces += 1;
        }
    }
    assert!(
        worst_channel <= 1,
        "{name}: colours differ by {worst_channel}"
    );
    // Which line colours each pixel: the cut lines are a class of their own.
    let classes = line_class_agreement(&truth, &frame).unwrap().unwrap_or(1.0);
    let cut = LineClass::Cut as u8;
    let cuts = truth.line_class.iter().filter(|&&c| c == cut).count();
    let gpu_cuts = frame.line_class.iter().filter(|&&c| c == cut).count();
    println!(
        "{name}: {faces} section-face pixels, {cuts} cut-line pixels ({gpu_cuts} deferred), \
         classes agree on {classes:.5}"
    );
    assert!(classes >= 0.999, "{name}: line classes agree on {classes}");
    (faces, cuts)
}

fn single(mesh: Mesh, edges: EdgeSelection, sections: Vec<SectionPlane>) -> World {
    let mut world = World::single(mesh, edges);
    world.sections = sections;
    world
}

#[test]
fn a_closed_part_cut_open_shows_its_section_face() {
    let mesh = load("fandisk.obj");
    let (lo, hi) = mesh.bounds_f64();
    let centre = 0.5 * (lo + hi);
    let world = single(
        mesh,
        EdgeSelection::Feature(30.0),
        vec![plane(centre.to_array(), [1.0, 0.0, 0.3])],
    );
    let view = perspective(&world, centre + DVec3::new(-1.5, 1.0, 2.2));
    let (faces, cuts) = check("fandisk", &world, view, &Style::default());
    assert!(faces > 500, "fandisk: {faces} section-face pixels");
    assert!(cuts > 300, "fandisk: {cuts} cut-line pixels");
    // With hidden lines: what lies behind the section face is drawn hidden, where the truth
    // puts it.
    let hidden = Style {
        hidden: Some(wirepass::HiddenLines::default()),
        ..Style::default()
    };
    check("fandisk, hidden lines", &world, view, &hidden);
    let truth = shoot_world(&world, view, &hidden, SIZE, Method::Raycast);
    let frame = shoot_world(&world, view, &hidden, SIZE, Method::Deferred);
    let h = hidden_distance_error(&truth, &frame).unwrap();
    println!("fandisk, hidden lines: {h:?}");
    assert!(h.pixels > 300, "{h:?}");
    assert!(h.p99.unwrap() <= 0.01 && h.max.unwrap() <= 0.1, "{h:?}");
    // The cut away half is gone: fewer triangles seen than uncut.
    let mut whole = world.clone();
    whole.sections.clear();
    let cut = shoot_world(&world, view, &Style::default(), SIZE, Method::Deferred);
    let uncut = shoot_world(&whole, view, &Style::default(), SIZE, Method::Deferred);
    let differ = (0..cut.ids.len())
        .filter(|&i| cut.ids[i] != uncut.ids[i])
        .count();
    assert!(differ > 5000, "{differ} pixels changed by the cut");
}

#[test]
fn a_plane_that_misses_everything_changes_nothing() {
    let mesh = Procedural::Torus(2000).build().unwrap();
    let world = single(
        mesh.clone(),
        EdgeSelection::All,
        vec![plane([0.0, -5.0, 0.0], [0.0, 1.0, 0.0])],
    );
    let view = perspective(&world, DVec3::new(1.5, 2.0, 2.5));
    assert_eq!(check("missing", &world, view, &Style::default()), (0, 0));
    // The same image as without it, but for the drawn edges now found by the trace pass
    // (the same lines within the usual bounds).
    let plain = shoot_world(
        &World::single(mesh, EdgeSelection::All),
        view,
        &Style::default(),
        SIZE,
        Method::Deferred,
    );
    let cut = shoot_world(&world, view, &Style::default(), SIZE, Method::Deferred);
    assert_eq!(plain.ids, cut.ids);
}

#[test]
fn two_planes_cut_a_corner_out_of_a_box() {
    let world = single(
        Procedural::Cube(300).build().unwrap(),
        EdgeSelection::Feature(30.0),
        vec![
            plane([0.2, 0.0, 0.0], [-1.0, 0.0, 0.0]),
            plane([0.0, 0.1, 0.0], [0.0, -1.0, 0.0]),
        ],
    );
    // What is kept: x <= 0.2 and y <= 0.1, two cuts meeting along an edge, seen from the
    // side they open.
    let view = perspective(&world, DVec3::new(2.0, 2.2, 2.6));
    // Wide cut lines.
    let style = Style {
        section_line_width: Some(3.0),
        ..Style::default()
    };
    let (faces, cuts) = check("corner", &world, view, &style);
    assert!(faces > 1000, "corner: {faces} section-face pixels");
    assert!(cuts > 300, "corner: {cuts} cut-line pixels");
    // Without edges or outlines, the cut lines are still drawn.
    let mut bare = world.clone();
    bare.objects[0].style.edges = Some(false);
    bare.objects[0].style.outlines = Some(false);
    let (_, cuts) = check("corner, no edges or outlines", &bare, view, &style);
    assert!(cuts > 300, "no edges or outlines: {cuts} cut-line pixels");
}

#[test]
fn a_dense_mesh_cut_at_a_grazing_angle_and_an_open_mesh() {
    let world = single(
        Procedural::Sphere(200_000).build().unwrap(),
        EdgeSelection::Polygon,
        vec![plane([0.0, 0.0, 0.0], [0.05, 0.2, 1.0])],
    );
    // The eye just off the plane (0.01 in front of it): the section face seen edge-on.
    let view = perspective(&world, DVec3::new(2.4, -0.3, -0.05));
    let (_, cuts) = check("grazing", &world, view, &Style::default());
    assert!(cuts > 100, "grazing: {cuts} cut-line pixels");
    // A grid (open boundaries) cut across, and a mirrored copy, orthographic.
    let grid = Procedural::Grid(2000).build().unwrap();
    let mut world = single(
        grid,
        EdgeSelection::All,
        vec![plane([0.1, 0.0, 0.0], [1.0, 0.4, 0.2])],
    );
    world.objects.push(Object::new(
        0,
        DMat4::from_translation(DVec3::new(0.0, 0.0, -0.5))
            * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
    ));
    let aspect = f64::from(SIZE.0) / f64::from(SIZE.1);
    let at = (DVec3::new(-1.0, 2.0, 3.0), DVec3::ZERO, DVec3::Y);
    let ortho = View::orthographic(at, 3.0, aspect, (0.1, 20.0));
    check("open, orthographic", &world, ortho, &Style::default());
}

#[test]
fn a_cut_ring_and_its_mirror_image_show_no_lines_over_their_section_faces() {
    // A torus (ring in the xz plane) and its mirror image across x = 0, cut by a plane that
    // the mirror leaves in place, seen from an eye on the mirror plane: the image is its own
    // mirror image.
    let mesh = Arc::new(Procedural::Torus(4000).build().unwrap());
    let placed = DMat4::from_translation(DVec3::new(-1.6, 0.0, 0.0));
    let mirror = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
    let world = World {
        meshes: vec![WorldMesh {
            mesh: mesh.clone(),
            edges: EdgeSelection::Feature(30.0),
            name: "torus".into(),
        }],
        objects: vec![Object::new(0, placed), Object::new(0, mirror * placed)],
        sections: vec![plane([0.0, 0.0, 0.0], [0.0, 0.2, -1.0])],
    };
    let view = perspective(&world, DVec3::new(0.0, 1.4, 3.2));
    let style = Style::default();
    let (faces, cuts) = check("ring and mirror", &world, view, &style);
    assert!(faces > 1000, "ring and mirror: {faces} section-face pixels");
    assert!(cuts > 200, "ring and mirror: {cuts} cut-line pixels");
    // Section faces where the mirror puts them: a mirrored instance's outward side is its
    // mesh's, whatever the transform does to the winding.
    let truth = shoot_world(&world, view, &style, SIZE, Method::Raycast);
    let section = style.section_color.to_srgb8();
    let (w, h) = (SIZE.0 as usize, SIZE.1 as usize);
    let is_face = |x: usize, y: usize| {
        let i = y * w + x;
        truth.rgba[4 * i..4 * i + 3] == section[..3]
    };
    let differ = (0..w * h)
        .filter(|&i| is_face(i % w, i / w) != is_face(w - 1 - i % w, i / w))
        .count();
    println!("ring and mirror: {differ} pixels differ from their mirror image");
    assert!(
        differ <= w * h / 1000,
        "{differ} pixels differ from their mirror image"
    );
    // Through the cut the eye sees the ring's inside: no silhouette of it is drawn over the
    // section face, inwards folds included. Pixels within half a pixel of an outline whose
    // neighbours two pixels round all show back faces (a visible silhouette has its own front
    // face next to it); facing by the mesh's own winding, from the eye in each instance's
    // space.
    let eye = view.eye();
    let triangles = mesh.triangles();
    let positions = mesh.positions();
    let back = |frame: &wirepass::world::Rendering, i: usize| {
        let id = frame.ids[i] as usize;
        if id >= 2 * triangles.len() {
            return false;
        }
        let local = world.objects[id / triangles.len()].transform.inverse() * eye;
        let c = triangles[id % triangles.len()].map(|v| positions[v as usize].as_dvec3());
        let normal = (c[1] - c[0]).cross(c[2] - c[0]);
        normal.dot(local.truncate() - c[0] * local.w) < 0.0
    };
    let deferred = shoot_world(&world, view, &style, SIZE, Method::Deferred);
    for (name, frame) in [("truth", &truth), ("deferred", &deferred)] {
        let over = (2..h - 2)
            .flat_map(|y| (2..w - 2).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let i = y * w + x;
                frame.line_class[i] == LineClass::Outline as u8
                    && frame.edge_distance[i] < 0.5
                    && (0..25).all(|k| back(frame, (y + k / 5 - 2) * w + x + k % 5 - 2))
            })
            .inspect(|(x, y)| {
                println!(
                    "  over at {x} {y} id {} d {}",
                    frame.ids[y * w + x],
                    frame.edge_distance[y * w + x]
                )
            })
            .count();
        println!("ring and mirror: {over} silhouette pixels over the section face ({name})");
        assert_eq!(over, 0, "{name}: silhouette pixels over the section face");
    }
}

#[test]
fn bad_section_planes_are_errors() {
    let mesh = Arc::new(Procedural::Sphere(200).build().unwrap());
    let mut world = World {
        meshes: vec![WorldMesh {
            mesh,
            edges: EdgeSelection::All,
            name: "sphere".into(),
        }],
        objects: vec![Object::new(0, DMat4::IDENTITY)],
        sections: Vec::new(),
    };
    for (sections, expect) in [
        (vec![plane([0.0; 3], [0.0; 3])], "normal"),
        (vec![plane([0.0; 3], [f64::NAN, 1.0, 0.0])], "normal"),
        (
            vec![plane([f64::INFINITY, 0.0, 0.0], [1.0, 0.0, 0.0])],
            "point",
        ),
        (vec![plane([0.0; 3], [1.0, 0.0, 0.0]); 7], "at most 6"),
    ] {
        world.sections = sections;
        let e = world.validate().unwrap_err();
        assert!(matches!(e, Error::InvalidScene(_)), "{e}");
        assert!(e.to_string().contains(expect), "{e}");
    }
}

/// Picking sees what the cut leaves: the located point, the snapped edge and vertex are
/// never cut away, and the triangle is the ground truth's.
#[test]
fn picks_ignore_what_is_cut_away() {
    let world = single(
        Procedural::Cube(300).build().unwrap(),
        EdgeSelection::Feature(30.0),
        vec![plane([0.2, 0.0, 0.0], [-1.0, 0.0, 0.0])],
    );
    let view = perspective(&world, DVec3::new(2.0, 2.2, 2.6));
    let style = Style::default();
    let shot = wirepass::world::Shot {
        world: &world,
        view,
        style: &style,
        size: SIZE,
    };
    let truth = shoot_world(&world, view, &style, SIZE, Method::Raycast);
    let plane = &world.sections[0];
    let kept = |p: [f64; 3]| plane.side(DVec3::from(p)) >= -1e-9;
    let (mut picked, mut agree, mut snapped) = (0, 0, 0);
    // Each pick renders the shot: a sparse grid of pixels.
    for y in (0..SIZE.1).step_by(13) {
        for x in (0..SIZE.0).step_by(13) {
            let id = truth.ids[(y * SIZE.0 + x) as usize];
            if id == wirepass::world::BACKGROUND {
                continue;
            }
            let r = wirepass::tools::pick::pick(common::gpu(), &shot, (x, y), 12.0).unwrap();
            let Some(point) = r.point else {
                continue;
            };
            picked += 1;
            agree += usize::from(r.triangle == Some(id));
            assert!(kept(point), "({x}, {y}): {point:?} is cut away");
            if let Some(e) = &r.edge {
                snapped += 1;
                assert!(
                    kept(e.point),
                    "({x}, {y}): edge point {:?} is cut away",
                    e.point
                );
            }
            if let Some(v) = &r.vertex {
                assert!(
                    kept(v.position),
                    "({x}, {y}): vertex {:?} is cut away",
                    v.position
                );
            }
        }
    }
    println!("{agree} of {picked} picks on the truth's triangle, {snapped} snapped to an edge");
    assert!(picked > 40, "{picked} picks");
    assert!(agree as f64 >= 0.99 * picked as f64, "{agree} of {picked}");
    assert!(snapped > 5, "{snapped} snaps");
}
