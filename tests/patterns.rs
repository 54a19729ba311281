//! Patterned visible lines (`Style::edge_pattern`, `Style::outline_pattern` and their
//! per-instance overrides): the deferred pass dashes the visible drawn edges and outlines
//! where the ground truth does, the edges' dashes running on along chains of drawn edges,
//! beside hidden lines of another pattern.

mod common;

use common::{cylinder, load, shoot_world, truth_and_frame, within_bounds, worst_pixels};
use glam::{DMat4, DVec3, Vec3};
use std::sync::Arc;
use wirepass::mesh::Procedural;
use wirepass::tools::offline::Method;
use wirepass::world::{Object, World, WorldMesh};
use wirepass::{Color, EdgeSelection, HiddenLines, LinePattern, Style, View};

const SIZE: (u32, u32) = (320, 240);

const DASHED: LinePattern = LinePattern::Dashed {
    dash: 6.0,
    gap: 4.0,
};
const DOTTED: LinePattern = LinePattern::Dotted { spacing: 5.0 };

/// fandisk (feature edges: long creases of many short edges) beside a torus with polygon
/// edges.
fn part_and_torus() -> World {
    World {
        sections: Vec::new(),
        meshes: vec![
            WorldMesh {
                mesh: Arc::new(load("fandisk.obj")),
                edges: EdgeSelection::Feature(30.0),
                name: "fandisk".into(),
            },
            WorldMesh {
                mesh: Arc::new(Procedural::Torus(600).build().unwrap()),
                edges: EdgeSelection::All,
                name: "torus".into(),
            },
        ],
        objects: vec![
            Object::new(0, DMat4::IDENTITY),
            Object::new(
                1,
                DMat4::from_translation(DVec3::new(0.2, -0.1, -0.6))
                    * DMat4::from_rotation_x(1.1)
                    * DMat4::from_scale(DVec3::splat(0.5)),
            ),
        ],
    }
}

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

/// The deferred frame against the ground truth; returns the visible-line pixels measured.
fn check(name: &str, world: &World, view: View, style: &Style) -> usize {
    let (truth, frame) = truth_and_frame(world, view, style, SIZE);
    let accuracy = within_bounds(name, &truth, &frame);
    let visible = accuracy.lines;
    assert!(visible.pixels > 0, "{name}: no line pixels");
    assert!(
        style.hidden.is_none() || accuracy.hidden.pixels > 0,
        "{name}: no hidden-line pixels"
    );
    let worst = || worst_pixels(&truth, &frame, 0.01, 8);
    // Where the truth's dashes leave a gap, the pass draws no line either (but at the very
    // edge of a line's reach).
    let extra = (0..truth.ids.len())
        .filter(|&i| truth.ids[i] == frame.ids[i])
        .filter(|&i| truth.edge_distance[i] > 2.5 && frame.edge_distance[i] < 1.5)
        .count();
    assert_eq!(
        extra,
        0,
        "{name}: line pixels the truth has not\n{}",
        worst()
    );
    visible.pixels
}

#[test]
fn dashed_edges_and_dotted_outlines_match_the_ground_truth() {
    let world = part_and_torus();
    let style = Style {
        line_width: 1.5,
        edge_pattern: DASHED,
        outline_pattern: DOTTED,
        outline_width: Some(2.0),
        ..Style::default()
    };
    let view = perspective(&world, DVec3::new(1.6, 1.2, 2.4));
    let pixels = check("perspective", &world, view, &style);
    assert!(pixels > 1500, "{pixels} line pixels");
    let aspect = f64::from(SIZE.0) / f64::from(SIZE.1);
    let at = (DVec3::new(-3.0, 2.0, 3.0), DVec3::ZERO, DVec3::Y);
    let ortho = View::orthographic(at, 2.5, aspect, (0.1, 20.0));
    check("orthographic", &world, ortho, &style);
    // The eye close to the part, its edges crossing the near plane.
    let close = perspective(&world, DVec3::new(0.35, 0.3, 0.45));
    check("close", &world, close, &style);
    // Visible lines dotted, hidden ones dashed: two patterns of different periods along the
    // same chains.
    let both = Style {
        edge_pattern: LinePattern::Dotted { spacing: 4.0 },
        hidden: Some(HiddenLines {
            pattern: LinePattern::Dashed {
                dash: 5.0,
                gap: 3.0,
            },
            color: Color([0.8, 0.1, 0.1, 1.0]),
            ..HiddenLines::default()
        }),
        ..style
    };
    check("with hidden lines", &world, view, &both);
}

/// An edge that starts behind the eye: its patterns are measured from where the near plane
/// cuts it, which projects some 3·10⁴ px off-screen here (the eye 0.05 above a grid whose
/// edges are 1 long, near plane 0.001 away). The dashes stand where the ground truth puts
/// them, visible and hidden, perspective and with the depth range reversed.
#[test]
fn dashes_keep_their_phase_where_the_near_plane_cuts_far_off_screen() {
    let world = World::single(Procedural::Grid(8).build().unwrap(), EdgeSelection::All);
    let camera = wirepass::Camera {
        eye: Vec3::new(0.3, 0.5, 0.05),
        target: Vec3::new(0.3, 2.0, 0.0),
        up: Vec3::Z,
        fov_y_deg: 60.0,
        near: 0.001,
        far: 10.0,
    };
    let aspect = f64::from(SIZE.0) / f64::from(SIZE.1);
    let style = Style {
        edge_pattern: DASHED,
        ..Style::default()
    };
    let pixels = check("grid", &world, camera.to_view(aspect), &style);
    assert!(pixels > 500, "{pixels} line pixels");
    // A small upright grid in front hides the far part of those edges: their hidden parts'
    // dashes are measured from the near plane's cut too.
    let mut screened = world.clone();
    screened.objects.push(Object::new(
        0,
        DMat4::from_translation(DVec3::new(0.3, 0.8, 0.0))
            * DMat4::from_rotation_x(std::f64::consts::FRAC_PI_2)
            * DMat4::from_scale(DVec3::splat(0.3)),
    ));
    let hidden = Style {
        hidden: Some(HiddenLines {
            pattern: LinePattern::Dashed {
                dash: 5.0,
                gap: 3.0,
            },
            ..HiddenLines::default()
        }),
        ..style
    };
    check(
        "grid behind a screen",
        &screened,
        camera.to_view(aspect),
        &hidden,
    );
    // Reverse-Z with an infinite far plane, as game engines draw.
    use wirepass::glam::dcamera::rh::{proj::directx as proj, view::look_at_mat4};
    let reversed = View::new(
        look_at_mat4(camera.eye.as_dvec3(), camera.target.as_dvec3(), DVec3::Z),
        proj::perspective_infinite_reverse(60f64.to_radians(), aspect, 0.001),
        wirepass::DepthRange::Reversed,
    );
    check("grid, reverse-Z", &world, reversed, &style);
}

/// A rim of edges shorter than a dash dashes evenly (its pattern's share of the solid
/// line's core, not a dash restarted at every vertex), where the ground truth puts the
/// dashes; and each instance, one mirrored, in its own phase.
#[test]
fn edge_dashes_run_on_along_chains() {
    let world = World::single(cylinder(160), EdgeSelection::Feature(30.0));
    let view = perspective(&world, DVec3::new(0.6, 2.2, 2.6));
    let dashed = Style {
        edge_pattern: LinePattern::Dashed {
            dash: 6.0,
            gap: 6.0,
        },
        outlines: false,
        ..Style::default()
    };
    check("cylinder", &world, view, &dashed);
    let core = |style: &Style, method| {
        let r = shoot_world(&world, view, style, SIZE, method);
        r.edge_distance.iter().filter(|&&d| d <= 0.5).count() as f64
    };
    let solid = Style {
        edge_pattern: LinePattern::Solid,
        ..dashed.clone()
    };
    for method in [Method::Raycast, Method::Deferred] {
        let share = core(&dashed, method) / core(&solid, method);
        println!("{method:?}: {share:.3} of the solid line's core is dashed");
        // A 6 px dash and its round caps' 0.5 px each, every 12 px: 0.583 (restarted at every
        // vertex of the 3 px edges, it would be 1).
        assert!((0.52..0.65).contains(&share), "{method:?}: {share}");
    }
    let mut world = world;
    world.objects = vec![
        Object::new(0, DMat4::from_translation(DVec3::new(-1.2, 0.0, -0.5))),
        Object::new(
            0,
            DMat4::from_translation(DVec3::new(1.2, 0.1, -0.3))
                * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
        ),
    ];
    let view = perspective(&world, DVec3::new(0.8, 3.0, 4.5));
    check("two cylinders", &world, view, &dashed);
}

/// Per instance: one dotted, one solid (the frame's) and one with dashed outlines only.
#[test]
fn patterns_per_instance() {
    let mut world = part_and_torus();
    world.objects.push(Object::new(
        1,
        DMat4::from_translation(DVec3::new(-0.6, 0.3, 0.2)) * DMat4::from_scale(DVec3::splat(0.4)),
    ));
    world.objects[0].style.edge_pattern = Some(LinePattern::Dotted { spacing: 3.0 });
    world.objects[2].style.outline_pattern = Some(DASHED);
    world.objects[2].style.edges = Some(false);
    let view = perspective(&world, DVec3::new(1.6, 1.2, 2.4));
    check("per instance", &world, view, &Style::default());
}

/// A dashed outline runs its pattern on along the outline: a teapot's silhouette, made of
/// edges a pixel or two long, is dashed evenly (about the pattern's share of the solid
/// outline's core; restarted at every edge it would be nearly solid), where the ground
/// truth puts the dashes, in perspective and orthographic views.
#[test]
fn dashed_outlines_run_on_along_the_silhouette() {
    let mut world = World::single(load("teapot.obj"), EdgeSelection::Feature(30.0));
    world.objects[0].style.edges = Some(false);
    let dashed = Style {
        outline_pattern: LinePattern::Dashed {
            dash: 6.0,
            gap: 6.0,
        },
        ..Style::default()
    };
    let view = perspective(&world, DVec3::new(-3.0, 2.5, 5.0));
    check("solid", &world, view, &Style::default());
    check("teapot", &world, view, &dashed);
    let core = |style: &Style, method| {
        let r = shoot_world(&world, view, style, SIZE, method);
        r.edge_distance.iter().filter(|&&d| d <= 0.5).count() as f64
    };
    let solid = Style {
        outline_pattern: LinePattern::Solid,
        ..dashed.clone()
    };
    for method in [Method::Raycast, Method::Deferred] {
        let share = core(&dashed, method) / core(&solid, method);
        println!("{method:?}: {share:.3} of the solid outline's core is dashed");
        // A 6 px dash and its core's round ends, 0.5 px each, every 12 px: 0.583 (restarted
        // at every edge of 1-3 px, as before the outline chains: 0.81).
        assert!((0.554..0.613).contains(&share), "{method:?}: {share}");
    }
    let aspect = f64::from(SIZE.0) / f64::from(SIZE.1);
    let at = (
        DVec3::new(-3.0, 2.0, 4.0),
        DVec3::new(0.2, 0.8, 0.0),
        DVec3::Y,
    );
    check(
        "orthographic",
        &world,
        View::orthographic(at, 3.5, aspect, (0.1, 20.0)),
        &dashed,
    );
}
