//! A style per line class: outlines take their own colour and width (`Style::outline_color`,
//! `Style::outline_width`, and per instance `InstanceStyle::outline_color`,
//! `InstanceStyle::outline_width`), apart from the drawn edges, in the deferred pass as in
//! the ground truth.

mod common;

use common::{load, shoot_world, worst_pixels};
use glam::{DMat4, DVec3};
use std::sync::Arc;
use wirepass::mesh::Procedural;
use wirepass::tools::compare::metrics;
use wirepass::tools::offline::Method;
use wirepass::world::{Object, Rendering, World, WorldMesh, BACKGROUND};
use wirepass::{Color, EdgeSelection, InstanceStyle, Style, View};

const SIZE: (u32, u32) = (360, 200);

/// fandisk (feature edges: its faces are large patches, whose drawn edges the trace pass
/// draws too) beside a torus with polygon edges; the torus has outlines of its own.
fn world() -> World {
    let fandisk = load("fandisk.obj");
    let (lo, hi) = fandisk.bounds_f64();
    let scale = 2.0 / (hi - lo).max_element();
    let centre = 0.5 * (lo + hi);
    World {
        sections: Vec::new(),
        meshes: vec![
            WorldMesh {
                mesh: Arc::new(fandisk),
                edges: EdgeSelection::Feature(30.0),
                name: "fandisk".into(),
            },
            WorldMesh {
                mesh: Arc::new(Procedural::Torus(1200).build().unwrap()),
                edges: EdgeSelection::Polygon,
                name: "torus".into(),
            },
        ],
        objects: vec![
            Object {
                mesh: 0,
                transform: DMat4::from_translation(DVec3::new(-1.3, 0.0, 0.0))
                    * DMat4::from_scale(DVec3::splat(scale))
                    * DMat4::from_translation(-centre),
                style: InstanceStyle::default(),
            },
            Object {
                mesh: 1,
                transform: DMat4::from_translation(DVec3::new(1.3, 0.0, 0.0))
                    * DMat4::from_rotation_x(1.0),
                style: InstanceStyle {
                    outline_color: Some(Color([0.9, 0.05, 0.05, 1.0])),
                    outline_width: Some(4.0),
                    ..InstanceStyle::default()
                },
            },
        ],
    }
}

fn view(world: &World) -> View {
    let (lo, hi) = world.bounds();
    wirepass::Camera::framing(lo, hi, f64::from(SIZE.0) / f64::from(SIZE.1))
        .to_view(f64::from(SIZE.0) / f64::from(SIZE.1))
}

/// Pixels whose colour is mostly `channel` (0 red, 2 blue), in the core of a line.
fn tinted(frame: &Rendering, channel: usize) -> usize {
    (0..frame.ids.len())
        .filter(|&i| {
            let c = |k: usize| i32::from(frame.rgba[4 * i + k]);
            let others: i32 = (0..3).filter(|&k| k != channel).map(c).sum();
            c(channel) > 150 && c(channel) > others
        })
        .count()
}

/// Whether pixel i is the torus's outline red.
fn is_red(frame: &Rendering, i: usize) -> bool {
    let c = &frame.rgba[4 * i..4 * i + 3];
    c[0] > 150 && c[1] < 100 && c[2] < 100
}

#[test]
fn outlines_take_their_own_colour_and_width() {
    let world = world();
    let view = view(&world);
    let style = Style {
        outline_color: Some(Color([0.05, 0.1, 0.9, 1.0])),
        outline_width: Some(2.5),
        ..Style::default()
    };
    let truth = shoot_world(&world, view, &style, SIZE, Method::Raycast);
    let frame = shoot_world(&world, view, &style, SIZE, Method::Deferred);
    let m = metrics(&truth, &frame).unwrap();
    let d = m.distance_error_px;
    println!(
        "id {:.5}, distance p99 {:.2e} max {:.2e} over {} px, FLIP {:.5}",
        m.id_agreement,
        d.p99.unwrap(),
        d.max.unwrap(),
        d.pixels,
        m.image_difference.flip_mean
    );
    assert!(m.id_agreement >= 0.999, "{m:?}");
    assert!(d.p99.unwrap() <= 0.01, "{m:?}");
    assert!(
        d.max.unwrap() <= 0.1,
        "{m:?}{}",
        worst_pixels(&truth, &frame, 0.1, 8)
    );
    assert!(m.image_difference.flip_mean <= 0.002, "{m:?}");
    // The torus's outline is red and 4 px wide, fandisk's blue (the style's), and the edges
    // keep the line colour: the truth shows both tints, and the frame as many of each.
    let (red, blue) = (tinted(&truth, 0), tinted(&truth, 2));
    let (frame_red, frame_blue) = (tinted(&frame, 0), tinted(&frame, 2));
    println!("red {red} / {frame_red}, blue {blue} / {frame_blue}");
    assert!(red > 300 && blue > 300, "red {red}, blue {blue}");
    assert!(
        red.abs_diff(frame_red) * 50 <= red,
        "red {frame_red} vs {red}"
    );
    assert!(
        blue.abs_diff(frame_blue) * 50 <= blue,
        "blue {frame_blue} vs {blue}"
    );
    // Red lies only about the torus, never on fandisk (the first object's ids), and over the
    // background reaches as far as its width.
    let fandisk = world.meshes[0].mesh.triangles().len() as u32;
    let red_on_fandisk = (0..frame.ids.len())
        .filter(|&i| frame.ids[i] < fandisk && is_red(&frame, i))
        .count();
    assert_eq!(red_on_fandisk, 0);
    let red_on_background = (0..frame.ids.len())
        .filter(|&i| frame.ids[i] == BACKGROUND && frame.edge_distance[i] < 1.0)
        .filter(|&i| is_red(&frame, i))
        .count();
    assert!(red_on_background > 100, "{red_on_background}");
}

#[test]
fn default_outline_style_is_the_line_style() {
    let world = world();
    let view = view(&world);
    let plain = World {
        sections: Vec::new(),
        objects: world
            .objects
            .iter()
            .map(|o| Object {
                style: InstanceStyle::default(),
                ..o.clone()
            })
            .collect(),
        ..world.clone()
    };
    let style = Style::default();
    let same = Style {
        outline_color: Some(style.wire_color),
        outline_width: Some(style.line_width),
        ..Style::default()
    };
    let a = shoot_world(&plain, view, &style, SIZE, Method::Deferred);
    let b = shoot_world(&plain, view, &same, SIZE, Method::Deferred);
    assert_eq!(a.rgba, b.rgba);
    assert_eq!(a.edge_distance, b.edge_distance);
}

#[test]
fn outline_styles_that_cannot_make_an_image_are_errors() {
    for width in [-1.0, f32::NAN, 1000.0] {
        let style = Style {
            outline_width: Some(width),
            ..Style::default()
        };
        assert!(style.validate().is_err(), "{width}");
        let instance = InstanceStyle {
            outline_width: Some(width),
            ..InstanceStyle::default()
        };
        assert!(instance.validate(0).is_err(), "{width}");
    }
    let nan = Color([f32::NAN, 0.0, 0.0, 1.0]);
    let style = Style {
        outline_color: Some(nan),
        ..Style::default()
    };
    assert!(style.validate().is_err());
    let instance = InstanceStyle {
        outline_color: Some(nan),
        ..InstanceStyle::default()
    };
    assert!(instance.validate(0).is_err());
}

/// The line-class map (`Rendering::line_class`, `--dump`'s `line_class.npy`): which class of
/// line colours each pixel most, drawn edge, outline or hidden line, as the ground truth
/// says.
#[test]
fn line_class_maps_match_the_ground_truth() {
    use wirepass::world::LineClass;
    let world = world();
    let view = view(&world);
    let style = Style {
        outline_color: Some(Color([0.05, 0.1, 0.9, 1.0])),
        hidden: Some(wirepass::HiddenLines::default()),
        ..Style::default()
    };
    let truth = shoot_world(&world, view, &style, SIZE, Method::Raycast);
    let frame = shoot_world(&world, view, &style, SIZE, Method::Deferred);
    assert_eq!(frame.line_class.len(), frame.ids.len());
    let (mut lined, mut agree) = (0, 0);
    let mut counts = [0usize; 4];
    for i in 0..truth.ids.len() {
        let (t, f) = (truth.line_class[i], frame.line_class[i]);
        if truth.ids[i] != frame.ids[i] || (t == 0 && f == 0) {
            continue;
        }
        lined += 1;
        counts[usize::from(t)] += 1;
        agree += usize::from(t == f);
        if t != f {
            println!(
                "  ({}, {}): truth {t} frame {f}, distances {} / {}, hidden {} / {}",
                i % SIZE.0 as usize,
                i / SIZE.0 as usize,
                truth.edge_distance[i],
                frame.edge_distance[i],
                truth.hidden_distance[i],
                frame.hidden_distance[i]
            );
        }
    }
    let share = agree as f64 / lined as f64;
    let measured = wirepass::truth::accuracy::line_class_agreement(&truth, &frame).unwrap();
    assert_eq!(measured, Some(share));
    println!("{agree} of {lined} line pixels agree ({share:.5}); truth classes {counts:?}");
    for class in [LineClass::Edge, LineClass::Outline, LineClass::Hidden] {
        assert!(counts[class as usize] > 300, "{class:?}: {counts:?}");
    }
    assert!(share >= 0.999, "{share}");
}
