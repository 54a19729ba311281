//! Selection highlights (`Highlight`, `InstanceStyle::highlighted`): the highlighted
//! instance's outline as an object in its own colour and width, dashed where other surfaces
//! hide it, its fill tinted; against the ground truth, every pixel.

mod common;

use common::{channel_difference, shoot_world, worst_of};
use glam::{DMat4, DVec3};
use std::sync::Arc;
use wirepass::mesh::Procedural;
use wirepass::tools::offline::Method;
use wirepass::truth::accuracy::{
    distance_error, hidden_distance_error, hidden_distance_errors, id_agreement,
};
use wirepass::world::{Object, World, WorldMesh};
use wirepass::{EdgeSelection, Highlight, InstanceStyle, Style};

const SIZE: (u32, u32) = (320, 240);

/// A torus in front of a sphere, which it hides in part; both with polygon edges.
fn world() -> World {
    World {
        sections: Vec::new(),
        meshes: vec![
            WorldMesh {
                mesh: Arc::new(Procedural::Sphere(800).build().unwrap()),
                edges: EdgeSelection::Polygon,
                name: "sphere".into(),
            },
            WorldMesh {
                mesh: Arc::new(Procedural::Torus(1200).build().unwrap()),
                edges: EdgeSelection::Polygon,
                name: "torus".into(),
            },
        ],
        objects: vec![
            Object::new(0, DMat4::from_translation(DVec3::new(0.3, 0.1, -1.5))),
            Object::new(1, DMat4::from_rotation_x(1.2)),
        ],
    }
}

#[test]
fn a_highlighted_instance_shows_its_outline_through_what_hides_it() {
    let mut world = world();
    let style = Style::default();
    let view = wirepass::Camera {
        eye: glam::Vec3::new(0.5, 1.0, 4.0),
        target: glam::Vec3::new(0.1, 0.0, -0.6),
        up: glam::Vec3::Y,
        fov_y_deg: 45.0,
        near: 0.05,
        far: 100.0,
    }
    .to_view(f64::from(SIZE.0) / f64::from(SIZE.1));
    let plain = shoot_world(&world, view, &style, SIZE, Method::Deferred);
    // The sphere, behind the torus, highlighted.
    world.objects[0].style = InstanceStyle::default().highlighted(&Highlight::default(), &style);
    let truth = shoot_world(&world, view, &style, SIZE, Method::Raycast);
    let frame = shoot_world(&world, view, &style, SIZE, Method::Deferred);
    let (ids, _) = id_agreement(&truth, &frame).unwrap();
    let visible = distance_error(&truth, &frame).unwrap();
    let hidden = hidden_distance_error(&truth, &frame).unwrap();
    println!("id {ids:.5}, visible {visible:?}, hidden {hidden:?}");
    assert!(ids >= 0.999, "id agreement {ids}");
    assert!(
        visible.p99.unwrap() <= 0.01 && visible.max.unwrap() <= 0.1,
        "{visible:?}"
    );
    let errors = hidden_distance_errors(&truth, &frame).unwrap();
    let worst = || worst_of(&truth, &frame, (&errors, |r| &r.hidden_distance), 0.01, 8);
    assert!(hidden.p99.unwrap() <= 0.01, "{hidden:?}\n{}", worst());
    assert!(hidden.max.unwrap() <= 0.1, "{hidden:?}\n{}", worst());
    // Only the sphere's outline is drawn hidden: over the torus that hides it, and over the
    // sphere only where the line spills past the torus's edge (its own drawn edges' hidden
    // parts, behind its front, are not drawn).
    let sphere = world.meshes[0].mesh.triangle_count() as u32;
    let count = |r: &wirepass::world::Rendering, on_sphere: bool| {
        (0..r.ids.len())
            .filter(|&i| r.hidden_distance[i] < 1.0 && (r.ids[i] < sphere) == on_sphere)
            .count()
    };
    let (on_torus, on_sphere) = (count(&frame, false), count(&frame, true));
    println!("{on_torus} hidden-outline pixels over the torus, {on_sphere} over the sphere");
    assert!(on_torus > 100, "{on_torus}");
    assert!(on_sphere * 20 <= on_torus, "{on_sphere}");
    assert_eq!(
        (on_torus, on_sphere),
        (count(&truth, false), count(&truth, true))
    );
    // The colours, the outline's orange and the tint included, as the truth has them.
    let (mut compared, mut worst_channel, mut changed) = (0, 0, 0);
    for i in 0..truth.ids.len() {
        if truth.ids[i] != frame.ids[i] {
            continue;
        }
        compared += 1;
        let d = channel_difference(&truth, &frame, i);
        worst_channel = worst_channel.max(d);
        changed += usize::from(frame.rgba[4 * i..4 * i + 4] != plain.rgba[4 * i..4 * i + 4]);
    }
    println!("{compared} pixels, worst channel difference {worst_channel}, {changed} changed");
    assert!(
        worst_channel <= 2,
        "worst channel difference {worst_channel}"
    );
    assert!(changed > 2000, "{changed}");
    // Nothing highlighted: the frame is the plain one.
    world.objects[0].style = InstanceStyle::default();
    let again = shoot_world(&world, view, &style, SIZE, Method::Deferred);
    assert_eq!(again.rgba, plain.rgba);
}
