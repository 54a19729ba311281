//! Technical drawings against their definition: every path's class checked by ray casts
//! at sampled points and a thousandth of a pixel inside each of its ends, the lines'
//! whole in-image length accounted for, the SVG rasterized against the deferred frame, the
//! PDF and DXF read back, and bad input refused.

mod common;

use common::{camera, gpu, load};
use glam::{DMat4, DVec2, DVec3, Vec3};
use std::sync::Arc;
use wirepass::drawing::{Drawing, Page, PathClass};
use wirepass::edge_math;
use wirepass::tools::offline::{draw, Method};
use wirepass::tools::regression::{difference, Rgba};
use wirepass::truth::rays::Rays;
use wirepass::truth::RayCaster;
use wirepass::world::{Object, Shot, World, WorldMesh};
use wirepass::{Camera, EdgeSelection, HiddenLines, LinePattern, Mesh, SectionPlane, Style, View};

/// Pixels inside each end of a path at which its class is checked: the run ends lie within
/// this of where the line's class changes.
const END_CHECK: f64 = 1e-3;

fn hidden_style(pattern: LinePattern) -> Style {
    Style {
        hidden: Some(HiddenLines {
            pattern,
            ..HiddenLines::default()
        }),
        ..Style::default()
    }
}

fn world_of(meshes: Vec<(Mesh, EdgeSelection)>, objects: Vec<(usize, DMat4)>) -> World {
    World {
        meshes: meshes
            .into_iter()
            .enumerate()
            .map(|(k, (mesh, edges))| WorldMesh {
                mesh: Arc::new(mesh),
                edges,
                name: format!("mesh {k}"),
            })
            .collect(),
        objects: objects
            .into_iter()
            .map(|(mesh, t)| Object::new(mesh, t))
            .collect(),
        sections: Vec::new(),
    }
}

/// A case: a world, a view, a style, a size.
struct Case {
    name: &'static str,
    world: World,
    view: View,
    style: Style,
    size: (u32, u32),
}

impl Case {
    fn shot(&self) -> Shot<'_> {
        Shot {
            world: &self.world,
            view: self.view,
            style: &self.style,
            size: self.size,
        }
    }
}

fn perspective(c: Camera, size: (u32, u32)) -> View {
    c.to_view(f64::from(size.0) / f64::from(size.1))
}

fn framed(world: &World, size: (u32, u32)) -> View {
    let (lo, hi) = world.bounds();
    perspective(
        Camera::framing(lo, hi, f64::from(size.0) / f64::from(size.1)),
        size,
    )
}

/// Whether world point `x` is hidden: the segment from the near plane to it along its
/// pixel's ray meets a surface nearer than it by the pass's margin. `None` where the point
/// is within the margin's reach of being either (no surface in front, but a section plane
/// in the world: the cut solid's face may hide it).
fn hidden_at(caster: &RayCaster<'_>, rays: &Rays, x: DVec3) -> bool {
    let c = rays.clip(x);
    let pixel = DVec2::new(
        0.5 * (c.x / c.w + 1.0) * rays.size().x,
        0.5 * (1.0 - c.y / c.w) * rays.size().y,
    );
    let (from, _) = rays.segment(pixel);
    caster.cast(from, x).is_some_and(|hit| {
        let h = rays.clip(hit.point);
        edge_math::nearer(h.z, c.z, c.w)
    })
}

/// Pixels around a line point within which its class must not change for it to be checked.
const AMBIGUOUS: f64 = END_CHECK;

/// Whether the points AMBIGUOUS pixels left, right, above and below world point `x` (at its
/// depth) have its class `hidden`.
fn stable(caster: &RayCaster<'_>, rays: &Rays, x: DVec3, hidden: bool) -> bool {
    let clip = rays.rows().clip;
    let inverse = clip.inverse();
    let c = clip * x.extend(1.0);
    let step = DVec2::splat(2.0 * AMBIGUOUS) / rays.size() * c.w;
    [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]
        .iter()
        .all(|&(dx, dy)| {
            let moved = inverse * (c + glam::DVec4::new(dx * step.x, dy * step.y, 0.0, 0.0));
            hidden_at(caster, rays, moved.truncate() / moved.w) == hidden
        })
}

/// The length of the projection of edge a → b in front of the near plane, before the far
/// one, on every section plane's kept side and within the image.
fn in_image_length(rays: &Rays, world: &World, a: DVec3, b: DVec3) -> f64 {
    let (ca, cb) = (rays.clip(a), rays.clip(b));
    let depth = rays.rows().depth;
    let mut fs = vec![
        (ca.z, cb.z),
        (depth.dot(a.extend(1.0)), depth.dot(b.extend(1.0))),
        (ca.w + ca.x, cb.w + cb.x),
        (ca.w - ca.x, cb.w - cb.x),
        (ca.w + ca.y, cb.w + cb.y),
        (ca.w - ca.y, cb.w - cb.y),
    ];
    fs.extend(world.sections.iter().map(|s| (s.side(a), s.side(b))));
    let (mut s0, mut s1) = (0.0f64, 1.0f64);
    for (f0, f1) in fs {
        if f0 < 0.0 && f1 < 0.0 {
            return 0.0;
        } else if f0 < 0.0 {
            s0 = s0.max(f0 / (f0 - f1));
        } else if f1 < 0.0 {
            s1 = s1.min(f0 / (f0 - f1));
        }
    }
    if s1 <= s0 {
        return 0.0;
    }
    let project = |p: DVec3| {
        let c = rays.clip(p);
        DVec2::new(c.x / c.w, -c.y / c.w) * 0.5 * rays.size()
    };
    project(a.lerp(b, s0)).distance(project(a.lerp(b, s1)))
}

/// The summed in-image length of every drawn edge and outline edge of the case, each once.
fn drawn_length(case: &Case, rays: &Rays) -> f64 {
    let world = &case.world;
    let eye = case.view.eye();
    let mut total = 0.0;
    for o in &world.objects {
        let mesh = &world.meshes[o.mesh].mesh;
        let mask = mesh.edge_mask(world.meshes[o.mesh].edges);
        let neighbours = mesh.edge_neighbours();
        let mut edges: Vec<(u32, u32)> = (0..mesh.triangle_count() as u32)
            .flat_map(|t| (0..3u32).map(move |i| (t, i)))
            .filter(|&(t, i)| {
                let n = neighbours[t as usize][i as usize];
                mask[t as usize] & (1 << i) != 0 && (n == u32::MAX || t < n)
            })
            .collect();
        if case.style.outlines {
            // Outline edges, but those between two triangles seen edge-on, which a drawing
            // leaves to the edge-on part's own outline.
            let corners = |t: u32| {
                mesh.triangles()[t as usize].map(|v| {
                    o.transform
                        .transform_point3(mesh.positions()[v as usize].as_dvec3())
                })
            };
            let edge_on = |t: u32| {
                let c = corners(t);
                let n = (c[1] - c[0]).cross(c[2] - c[0]);
                let towards = edge_math::towards_eye((c[0] + c[1] + c[2]) / 3.0, eye);
                n.dot(towards).abs() <= edge_math::EDGE_ON * n.length() * towards.length()
            };
            let local = edge_math::local_eye(o.transform, eye);
            edges.extend(
                wirepass::world::outline_edges(mesh, local)
                    .into_iter()
                    .filter(|&(t, i)| {
                        let n = neighbours[t as usize][i as usize];
                        n == u32::MAX || !(edge_on(t) && edge_on(n))
                    }),
            );
        }
        edges.sort_unstable();
        edges.dedup();
        let p = mesh.positions();
        for (t, i) in edges {
            let tri = mesh.triangles()[t as usize];
            let corner = |k: u32| {
                o.transform
                    .transform_point3(p[tri[(k % 3) as usize] as usize].as_dvec3())
            };
            total += in_image_length(rays, world, corner(i), corner(i + 1));
        }
    }
    total
}

/// Checks a case's drawing against its definition; returns it.
fn check(case: &Case) -> Drawing {
    let drawing = Drawing::new(&case.shot()).unwrap_or_else(|e| panic!("{}: {e}", case.name));
    let caster = RayCaster::new(&case.world);
    let rays = Rays::new(&case.view, case.size, &case.world).unwrap();
    let sectioned = !case.world.sections.is_empty();
    let mut checked = 0;
    let mut wrong = Vec::new();
    for path in &drawing.paths {
        assert_eq!(path.points.len(), path.world_points.len());
        assert!(path.points.len() >= 2, "{}: a path of one point", case.name);
        let hidden = path.class == PathClass::Hidden;
        let pieces = path.world_points.windows(2).zip(path.points.windows(2));
        let last = path.points.len() - 2;
        for (k, (w, q)) in pieces.enumerate() {
            let length = q[0].distance(q[1]);
            if length <= 2.0 * END_CHECK {
                continue;
            }
            // Samples along the piece, and a thousandth of a pixel inside the path's ends.
            let mut at: Vec<f64> = (1..8).map(|j| f64::from(j) / 8.0).collect();
            if k == 0 {
                at.push(END_CHECK / length);
            }
            if k == last {
                at.push(1.0 - END_CHECK / length);
            }
            for u in at {
                // Parameter u on screen is this one along the world segment.
                let (c0, c1) = (rays.clip(w[0]), rays.clip(w[1]));
                let s = u * c0.w / (u * c0.w + (1.0 - u) * c1.w);
                let x = w[0].lerp(w[1], s);
                let is_hidden = hidden_at(&caster, &rays, x);
                // Where a step of AMBIGUOUS px changes the answer, the point lies on a
                // surface's outline on screen, which the definition leaves to rounding.
                if !stable(&caster, &rays, x, is_hidden) {
                    continue;
                }
                checked += 1;
                // With section planes a point with nothing in front may lie behind a cut
                // solid's face: hidden by the section rule, which no ray cast sees.
                let agrees = is_hidden == hidden || (sectioned && hidden && !is_hidden);
                if !agrees {
                    wrong.push(format!(
                        "{:?} path of object {} at {:?}: the ray cast says {}",
                        path.class,
                        path.object,
                        q[0].lerp(q[1], u),
                        if is_hidden { "hidden" } else { "visible" }
                    ));
                }
            }
        }
    }
    assert!(
        checked > 100,
        "{}: only {checked} points checked",
        case.name
    );
    assert!(
        wrong.is_empty(),
        "{}: {} of {checked} points of the wrong class, first: {:?}",
        case.name,
        wrong.len(),
        &wrong[..wrong.len().min(5)]
    );
    // Every part of every line is drawn, visible or hidden, and nothing twice.
    let hidden_everywhere = case.style.hidden.is_some_and(|h| h.edges);
    if hidden_everywhere {
        let drawn: f64 = drawing
            .paths
            .iter()
            .filter(|p| {
                matches!(
                    p.class,
                    PathClass::Hidden | PathClass::Edge | PathClass::Outline
                )
            })
            .map(|p| p.length())
            .sum();
        let want = drawn_length(case, &rays);
        assert!(
            (drawn - want).abs() <= 1e-6 * want + 1e-6,
            "{}: the paths are {drawn} px long, the lines in view {want} px",
            case.name
        );
    }
    drawing
}

fn fandisk_case() -> Case {
    let mesh = load("fandisk.obj");
    let world = World::single(mesh, EdgeSelection::Feature(30.0));
    let size = (320, 240);
    Case {
        name: "fandisk, feature edges, dashed hidden lines",
        view: framed(&world, size),
        world,
        style: hidden_style(LinePattern::Dashed {
            dash: 6.0,
            gap: 4.0,
        }),
        size,
    }
}

#[test]
fn fandisk_with_dashed_hidden_lines_matches_its_definition() {
    let drawing = check(&fandisk_case());
    // Chained: far fewer paths than drawn edges.
    assert!(drawing.of_class(PathClass::Hidden).count() > 10);
    assert!(drawing.paths.len() < 200, "{} paths", drawing.paths.len());
}

#[test]
fn hidden_lines_of_the_hard_cameras_match_their_definition() {
    let size = (240, 180);
    let solid = hidden_style(LinePattern::Solid);
    let teapot_eye = Vec3::new(2.054_089, 2.744_056_6, 3.340_162);
    let teapot_target = Vec3::new(0.217, 1.575, 0.0);
    let teapot_camera = |near: f32| Camera {
        fov_y_deg: 40.0,
        ..camera(teapot_eye, teapot_target, near, 41.024)
    };
    let bunny = load("stanford-bunny.obj");
    let teapot = load("teapot.obj");
    let feature = EdgeSelection::Feature(30.0);
    let cases = [
        ("bunny, default view", bunny.clone(), feature, None),
        (
            "bunny, close up with the near plane through it",
            bunny,
            feature,
            Some(Camera {
                fov_y_deg: 40.0,
                ..camera(
                    Vec3::new(0.048_816_68, 0.151_935_84, 0.117_839_7),
                    Vec3::new(-0.016_840_5, 0.110_154, -0.001_537),
                    0.128_254,
                    1.251_23,
                )
            }),
        ),
        (
            "spot, polygon edges (quads)",
            load("spot.obj"),
            EdgeSelection::Polygon,
            None,
        ),
        (
            "teapot, all edges",
            teapot.clone(),
            EdgeSelection::All,
            Some(teapot_camera(0.041_024)),
        ),
        (
            "teapot, near plane through it",
            teapot,
            feature,
            Some(teapot_camera(3.588_54)),
        ),
    ];
    for (name, mesh, edges, cam) in cases {
        let world = World::single(mesh, edges);
        let view = match cam {
            Some(c) => perspective(c, size),
            None => framed(&world, size),
        };
        check(&Case {
            name,
            world,
            view,
            style: solid.clone(),
            size,
        });
    }
}

#[test]
fn orthographic_views_mirrored_instances_and_sections_match_their_definition() {
    let size = (320, 240);
    let fandisk = load("fandisk.obj");
    let feature = EdgeSelection::Feature(30.0);
    let mirrored = DMat4::from_translation(DVec3::new(0.6, 0.1, -0.3))
        * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
    let world = world_of(
        vec![(fandisk.clone(), feature)],
        vec![(0, DMat4::IDENTITY), (0, mirrored)],
    );
    for name in ["iso", "front", "top"] {
        let view = wirepass::tools::load::named_view(&world, name, size).unwrap();
        check(&Case {
            name: "two fandisks, one mirrored, orthographic",
            world: world.clone(),
            view,
            style: hidden_style(LinePattern::Solid),
            size,
        });
    }
    // Seen from the front, the part's sides are edge-on: their outline is drawn by the
    // edges they share with the front and back, not by every edge of their triangulation
    // (over a thousand paths, most on top of each other, at 800x600).
    let one = World::single(fandisk, feature);
    let view = wirepass::tools::load::named_view(&one, "front", size).unwrap();
    let drawing = check(&Case {
        name: "fandisk from the front",
        world: one,
        view,
        style: hidden_style(LinePattern::Solid),
        size,
    });
    assert!(drawing.paths.len() < 200, "{} paths", drawing.paths.len());
    let mut cut = World::single(load("stanford-bunny.obj"), feature);
    let (lo, hi) = cut.bounds();
    cut.sections.push(SectionPlane {
        point: 0.5 * (lo + hi),
        normal: DVec3::new(-1.0, 0.0, -0.4),
    });
    let view = framed(&cut, size);
    let drawing = check(&Case {
        name: "bunny cut by a section plane",
        world: cut,
        view,
        style: hidden_style(LinePattern::Solid),
        size,
    });
    assert!(drawing.of_class(PathClass::Cut).count() > 0);
}

#[test]
fn intersection_lines_between_instances_are_drawn_where_visible() {
    let world = common::spot_beside_suzanne(common::THROUGH);
    let size = (320, 240);
    let case = Case {
        name: "spot through suzanne, intersection lines",
        view: framed(&world, size),
        world,
        style: Style {
            intersection_lines: true,
            ..hidden_style(LinePattern::Solid)
        },
        size,
    };
    let drawing = check(&case);
    let lines: Vec<_> = drawing.of_class(PathClass::Intersection).collect();
    assert!(!lines.is_empty());
    // Segments meeting end to end are one path.
    let pieces: usize = lines.iter().map(|p| p.points.len() - 1).sum();
    assert!(
        lines.len() * 3 < pieces,
        "{} paths of {pieces} pieces",
        lines.len()
    );
}

/// The drawing's SVG rasterized at its size, 8-bit RGBA.
fn rasterize(svg: &str) -> (Vec<u8>, (u32, u32)) {
    let tree = resvg::usvg::Tree::from_str(svg, &resvg::usvg::Options::default()).unwrap();
    let size = tree.size().to_int_size();
    let mut pixmap = resvg::tiny_skia::Pixmap::new(size.width(), size.height()).unwrap();
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::default(),
        &mut pixmap.as_mut(),
    );
    (pixmap.data().to_vec(), (size.width(), size.height()))
}

#[test]
fn the_svg_looks_like_the_deferred_frame_of_the_same_view() {
    // Surfaces in the background's colour, unlit: the frame's lines on the background, as
    // a drawing has them.
    let mesh = load("fandisk.obj");
    let size = (320, 240);
    for (pattern, outlines) in [
        (LinePattern::Solid, true),
        (
            LinePattern::Dashed {
                dash: 6.0,
                gap: 4.0,
            },
            false,
        ),
        (LinePattern::Dotted { spacing: 4.0 }, false),
    ] {
        let world = World::single(mesh.clone(), EdgeSelection::Feature(30.0));
        let style = Style {
            fill_color: Style::default().background,
            ambient: 1.0,
            outlines,
            ..hidden_style(pattern)
        };
        let case = Case {
            name: "fandisk",
            view: framed(&world, size),
            world,
            style,
            size,
        };
        let drawing = Drawing::new(&case.shot()).unwrap();
        let frame = draw(gpu(), &case.shot(), Method::Deferred).unwrap();
        let (svg, svg_size) = rasterize(&drawing.to_svg(&Page::pixels()));
        assert_eq!(svg_size, size);
        let d = difference(
            Rgba::new(&frame.rgba, size).unwrap(),
            Rgba::new(&svg, size).unwrap(),
        )
        .unwrap();
        // The raster's line profile and resvg's coverage antialias thin lines differently.
        assert!(d.mean < 0.04, "{pattern:?}: FLIP {d:?}");
        // Each line pixel of the frame (its line's core) is covered by the same kind of line
        // in the drawing: visible (a drawn edge that is also an outline may be either class
        // in the raster, by which line is nearer), hidden, cut, intersection.
        let kinds: [(&[PathClass], &[u8]); 4] = [
            (&[PathClass::Edge, PathClass::Outline], &[1, 2]),
            (&[PathClass::Hidden], &[3]),
            (&[PathClass::Cut], &[4]),
            (&[PathClass::Intersection], &[5]),
        ];
        let mut agree = (0, 0);
        for (classes, codes) in kinds {
            let only = Drawing {
                paths: drawing
                    .paths
                    .iter()
                    .filter(|p| classes.contains(&p.class))
                    .cloned()
                    .collect(),
                ..drawing.clone()
            };
            let (raster, _) = rasterize(&only.to_svg(&Page::pixels()));
            for i in 0..frame.line_class.len() {
                let core = frame.edge_distance[i].min(frame.hidden_distance[i]) < 0.25;
                if codes.contains(&frame.line_class[i]) && core {
                    agree.1 += 1;
                    // Anything off the white background.
                    if raster[4 * i..4 * i + 3].iter().any(|&v| v < 250) {
                        agree.0 += 1;
                    }
                }
            }
        }
        let share = f64::from(agree.0) / f64::from(agree.1.max(1));
        assert!(
            agree.1 > 200 && share >= 0.99,
            "{pattern:?}: {agree:?} line pixels agree"
        );
    }
}

#[test]
fn the_pdf_and_the_dxf_read_back_to_the_same_polylines() {
    let case = fandisk_case();
    let drawing = Drawing::new(&case.shot()).unwrap();
    let page = Page::pixels();

    // PDF: the content stream's move-to / line-to runs, back in pixels.
    let pdf = lopdf::Document::load_mem(&drawing.to_pdf(&page)).unwrap();
    let pages = pdf.get_pages();
    assert_eq!(pages.len(), 1);
    let page_id = *pages.values().next().unwrap();
    let content = lopdf::content::Content::decode(&pdf.get_page_content(page_id)).unwrap();
    let number = |o: &lopdf::Object| o.as_float().map(f64::from).unwrap();
    let mut polylines: Vec<Vec<DVec2>> = Vec::new();
    let mut dashes = Vec::new();
    for op in &content.operations {
        match op.operator.as_str() {
            "m" => polylines.push(vec![DVec2::new(
                number(&op.operands[0]),
                number(&op.operands[1]),
            )]),
            "l" => polylines
                .last_mut()
                .unwrap()
                .push(DVec2::new(number(&op.operands[0]), number(&op.operands[1]))),
            "d" => dashes.push(number(&op.operands[1])),
            _ => {}
        }
    }
    assert_eq!(polylines.len(), drawing.paths.len());
    for (got, path) in polylines.iter().zip(&drawing.paths) {
        assert_eq!(got.len(), path.points.len());
        for (g, p) in got.iter().zip(&path.points) {
            assert!(g.distance(*p) < 1e-3, "{g} against {p}");
        }
    }
    let patterned: Vec<f64> = drawing
        .paths
        .iter()
        .filter(|p| p.pattern[1] > 0.0)
        .map(|p| p.offset)
        .collect();
    assert_eq!(dashes.len(), patterned.len());
    for (d, o) in dashes.iter().zip(&patterned) {
        assert!((d - o).abs() < 1e-3, "dash phase {d} against {o}");
    }

    // DXF: a polyline per path on its class's layer, the pattern as a linetype.
    let text = drawing.to_dxf(&page);
    let dxf = dxf::Drawing::load(&mut text.as_bytes()).unwrap();
    let layers: Vec<String> = dxf.layers().map(|l| l.name.clone()).collect();
    for class in PathClass::ALL {
        assert!(
            layers.contains(&class.name().to_ascii_uppercase()),
            "{layers:?}"
        );
    }
    let height = f64::from(drawing.size.1);
    let mut read = 0;
    for (entity, path) in dxf.entities().zip(&drawing.paths) {
        let dxf::entities::EntityType::Polyline(line) = &entity.specific else {
            panic!("not a polyline: {:?}", entity.specific);
        };
        assert_eq!(entity.common.layer, path.class.name().to_ascii_uppercase());
        assert_eq!(
            entity.common.line_type_name == "CONTINUOUS",
            path.pattern[1] == 0.0
        );
        // The linetype draws the path's pattern from the path's phase: a dash (or dot) at
        // the same places along it, to the file's ten-thousandths.
        if path.pattern[1] > 0.0 {
            let kind = dxf
                .line_types()
                .find(|t| t.name == entity.common.line_type_name)
                .unwrap();
            let elements = &kind.dash_dot_space_lengths;
            assert!((kind.total_pattern_length - path.pattern[1]).abs() < 1e-3);
            let total: f64 = elements.iter().map(|e| e.abs()).sum();
            assert!((total - path.pattern[1]).abs() < 1e-3, "{elements:?}");
            let [dash, period] = path.pattern;
            for k in 0..40 {
                let along = 0.37 * f64::from(k);
                // The element `along` falls in: a dash (or dot) is drawn there.
                let mut at = along.rem_euclid(period);
                let mut in_file = false;
                for &e in elements {
                    if at <= e.abs() {
                        in_file = e >= 0.0;
                        break;
                    }
                    at -= e.abs();
                }
                let position = (path.offset + along).rem_euclid(period);
                let in_path = position <= dash;
                // Only a position within the file's rounding of a dash's end may differ.
                let near_end = position.min((position - dash).abs()).min(period - position) < 1e-3;
                assert!(
                    in_file == in_path || near_end,
                    "{along} px along {path:?}: {elements:?}"
                );
            }
        }
        let got: Vec<DVec2> = line
            .vertices()
            .map(|v| DVec2::new(v.location.x, height - v.location.y))
            .collect();
        assert_eq!(got.len(), path.points.len());
        for (g, p) in got.iter().zip(&path.points) {
            assert!(g.distance(*p) < 1e-3, "{g} against {p}");
        }
        read += 1;
    }
    assert_eq!(read, drawing.paths.len());
}

#[test]
fn a_drawing_to_scale_measures_the_world_in_millimetres() {
    // A unit cube seen from the front at 1:10, its unit a metre: 100 mm wide on the page.
    let world = World::single(
        wirepass::tools::load::load_mesh(Some("cube:12")).unwrap(),
        EdgeSelection::Feature(30.0),
    );
    let size = (400, 300);
    let view = wirepass::tools::load::named_view(&world, "front", size).unwrap();
    let page = Page::to_scale(&view, size, 1000.0, 10.0).unwrap();
    let shot = Shot {
        world: &world,
        view,
        style: &Style::default(),
        size,
    };
    let drawing = Drawing::new(&shot).unwrap();
    let (lo, hi) = drawing
        .paths
        .iter()
        .flat_map(|p| &p.points)
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let (w_mm, h_mm) = ((hi - lo).x * page.per_pixel, (hi - lo).y * page.per_pixel);
    let (cube_lo, cube_hi) = world.bounds();
    let side = (cube_hi - cube_lo).x * 100.0;
    assert!(
        (w_mm - side).abs() < 1e-6 && (h_mm - side).abs() < 1e-6,
        "{w_mm} x {h_mm} mm"
    );
    let svg = drawing.to_svg(&page);
    assert!(svg.contains("mm\" height="), "{}", &svg[..200]);
    // A perspective view has no scale.
    assert!(Page::to_scale(&framed(&world, size), size, 1.0, 10.0).is_err());
}

#[test]
fn what_cannot_be_drawn_is_a_clear_error() {
    let size = (200, 150);
    let empty = World::default();
    let style = Style::default();
    let view = perspective(camera(Vec3::Z * 3.0, Vec3::ZERO, 0.1, 10.0), size);
    let shot = |world: &World, view: View, size: (u32, u32)| {
        Drawing::new(&Shot {
            world,
            view,
            style: &style,
            size,
        })
    };
    let e = shot(&empty, view, size).unwrap_err().to_string();
    assert!(e.contains("no objects"), "{e}");
    let cube = World::single(
        wirepass::tools::load::load_mesh(Some("cube:12")).unwrap(),
        EdgeSelection::All,
    );
    // Looking away from the cube.
    let away = perspective(camera(Vec3::Z * 3.0, Vec3::Z * 6.0, 0.1, 10.0), size);
    let e = shot(&cube, away, size).unwrap_err().to_string();
    assert!(e.contains("nothing to draw"), "{e}");
    for size in [(0, 10), (10, 0), (100_000, 10)] {
        let e = shot(&cube, view, size).unwrap_err().to_string();
        assert!(e.contains("each side must be 1 to 65536"), "{e}");
    }
    let drawing = shot(&cube, view, size).unwrap();
    let dir = std::env::temp_dir().join("wirepass-drawing-errors");
    let _ = std::fs::create_dir_all(&dir);
    let e = drawing
        .write(&dir.join("no/such/dir/out.svg"), &Page::pixels())
        .unwrap_err()
        .to_string();
    assert!(e.contains("out.svg"), "{e}");
    let e = drawing
        .write(&dir.join("out.png"), &Page::pixels())
        .unwrap_err()
        .to_string();
    assert!(e.contains(".svg, .pdf or .dxf"), "{e}");
}
