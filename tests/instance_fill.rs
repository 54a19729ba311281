//! Each instance's own fill colour (`InstanceStyle::fill_color`): every method shades an
//! instance's surface with it, as the ground truth does, and an instance without one takes
//! the style's.

mod common;

use common::shoot_world;
use glam::{DMat4, DVec3};
use std::sync::Arc;
use wirepass::mesh::Procedural;
use wirepass::tools::load::CameraPlacement;
use wirepass::tools::offline::Method;
use wirepass::world::{Object, World, WorldMesh, BACKGROUND};
use wirepass::{Color, EdgeSelection, InstanceStyle, Style};

const SIZE: (u32, u32) = (300, 120);

/// Three spheres in a row: a red fill, the style's, a blue fill.
fn world() -> World {
    let object = |x: f64, fill: Option<&str>| Object {
        mesh: 0,
        transform: DMat4::from_translation(DVec3::new(x, 0.0, 0.0)),
        style: InstanceStyle {
            fill_color: fill.map(|c| Color::from_hex(c).unwrap()),
            ..InstanceStyle::default()
        },
    };
    World {
        sections: Vec::new(),
        meshes: vec![WorldMesh {
            mesh: Arc::new(Procedural::Sphere(2000).build().unwrap()),
            edges: EdgeSelection::Feature(60.0),
            name: "sphere".into(),
        }],
        objects: vec![
            object(-2.2, Some("#c03020")),
            object(0.0, None),
            object(2.2, Some("#2050d0")),
        ],
    }
}

#[test]
fn every_method_shades_each_instance_with_its_fill_colour() {
    let world = world();
    let camera = CameraPlacement::default()
        .camera(world.bounds(), SIZE)
        .unwrap();
    let view = camera.to_view(f64::from(SIZE.0) / f64::from(SIZE.1));
    let style = Style::default();
    let truth = shoot_world(&world, view, &style, SIZE, Method::Raycast);
    // The truth shows all three colours: red, the style's grey-blue, blue.
    let pixel = |img: &[u8], i: usize| [img[4 * i], img[4 * i + 1], img[4 * i + 2]].map(i32::from);
    let count = |f: &dyn Fn([i32; 3]) -> bool| {
        (0..truth.ids.len())
            .filter(|&i| truth.ids[i] != BACKGROUND && f(pixel(&truth.rgba, i)))
            .count()
    };
    let red = count(&|[r, g, b]| r > g + b);
    let blue = count(&|[r, g, b]| b > r + g);
    let neither = count(&|[r, g, b]| r <= g + b && b <= r + g);
    println!("truth: {red} red, {blue} blue, {neither} other surface pixels");
    assert!(red > 1000 && blue > 1000 && neither > 1000);
    for method in [Method::Deferred, Method::Forward, Method::TwoPass] {
        let frame = shoot_world(&world, view, &style, SIZE, method);
        // Surface pixels both agree on, away from the outlines.
        let (mut compared, mut off, mut worst) = (0, 0, 0);
        for i in 0..truth.ids.len() {
            // (The truth's distance is inf where no line is near.)
            let near_line = truth.edge_distance[i] <= 4.0;
            if truth.ids[i] == BACKGROUND || truth.ids[i] != frame.ids[i] || near_line {
                continue;
            }
            compared += 1;
            let d = (0..3)
                .map(|c| (pixel(&truth.rgba, i)[c] - pixel(&frame.rgba, i)[c]).abs())
                .max()
                .unwrap();
            worst = worst.max(d);
            if d > 1 {
                off += 1;
            }
        }
        println!(
            "{}: {compared} surface pixels, {off} more than 1 step off, at most {worst}",
            method.name()
        );
        assert!(compared > 3000, "{}: {compared} pixels", method.name());
        assert!(
            worst <= 2 && off * 1000 <= compared,
            "{}: {off} of {compared} pixels off, at most {worst} steps",
            method.name()
        );
    }
}
