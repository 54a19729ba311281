//! Lines across undrawn edges: wherever a drawn edge is visible its line has its full width,
//! whichever triangle the pixel sees. Polygon mode (quads, n-gons down to pixel size, concave
//! and folded polygons) and feature mode (the creases of a tessellated cube, coarse and
//! dense, with wide lines), each against the ray-cast ground truth with the bounds of
//! tests/ground_truth.rs; an edge just outside the image; and an image drawn as tiles, equal
//! to the whole. Run in release mode (`cargo test --release`).

// `!(a <= b)` is deliberate throughout: NaN must fail the test, not pass it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod common;

use common::{cpu_distance, framing, load, shoot, within_bounds};
use glam::{DVec3, Vec3};
use wirepass::gpu::{DeferredPass, PassOptions, Region};
use wirepass::tools::offline::{draw_deferred_on, Method, Uploaded};
use wirepass::world::{Rendering, Shot, World};
use wirepass::{style, Camera, EdgeSelection, Mesh, Style};

/// Renders `mesh` with the ground truth and the deferred method and checks the bounds;
/// returns both frames.
fn check(
    name: &str,
    mesh: &Mesh,
    camera: Camera,
    size: (u32, u32),
    edges: EdgeSelection,
    line_width: f32,
) -> (Rendering, Rendering) {
    let style = Style {
        line_width,
        ..Style::default()
    };
    let truth = shoot(mesh, camera, &style, size, edges, Method::Raycast);
    let frame = shoot(mesh, camera, &style, size, edges, Method::Deferred);
    let d = within_bounds(name, &truth, &frame).lines;
    assert!(d.pixels > 0, "{name}: nothing measured");
    (truth, frame)
}

/// Pixels whose own triangle's drawn edges are beyond the line's reach but which the ground
/// truth puts within 1 px of a line: where a line crosses an undrawn edge.
fn lines_across_undrawn_edges(
    mesh: &Mesh,
    camera: &Camera,
    truth: &Rendering,
    edges: EdgeSelection,
    line_width: f32,
) -> usize {
    let reach = style::line_reach(f64::from(line_width));
    let (w, _) = truth.size;
    truth
        .ids
        .iter()
        .enumerate()
        .filter(|&(i, &id)| {
            id < mesh.triangle_count() as u32
                && truth.edge_distance[i] < 1.0
                && !(cpu_distance(
                    mesh,
                    camera,
                    truth.size,
                    edges,
                    id,
                    (i as u32 % w, i as u32 / w),
                ) < reach)
        })
        .count()
}

/// A mesh from OBJ text.
fn obj(name: &str, text: &str) -> Mesh {
    let path =
        std::env::temp_dir().join(format!("wirepass-lines-{}-{name}.obj", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let mesh = wirepass::mesh::load_obj(&path).unwrap_or_else(|e| panic!("{e}"));
    std::fs::remove_file(&path).ok();
    mesh
}

fn looking(eye: DVec3, target: DVec3) -> Camera {
    Camera {
        eye: eye.as_vec3(),
        target: target.as_vec3(),
        up: Vec3::Y,
        fov_y_deg: 40.0,
        near: 0.05,
        far: 1000.0,
    }
}

/// `check` in polygon mode from each of `eyes` looking at `target`, at each line width.
fn check_views(what: &str, mesh: &Mesh, target: DVec3, eyes: &[(&str, DVec3)], widths: &[f32]) {
    for &(name, eye) in eyes {
        let camera = looking(eye, target);
        for &width in widths {
            let name = format!("{what} {name} {width} px");
            check(
                &name,
                mesh,
                camera,
                (320, 240),
                EdgeSelection::Polygon,
                width,
            );
        }
    }
}

#[test]
fn the_creases_of_a_tessellated_cube_are_solid() {
    // Each face a 48 × 48 grid of quads: every crease is the edges of many small triangles.
    let mesh = wirepass::mesh::cube(27_648).unwrap();
    let camera = looking(DVec3::new(2.2, 1.8, 2.6), DVec3::ZERO);
    let size = (600, 450);
    let edges = EdgeSelection::Feature(30.0);
    let (truth, frame) = check("cube48 feature:30 6 px", &mesh, camera, size, edges, 6.0);
    let across = lines_across_undrawn_edges(&mesh, &camera, &truth, edges, 6.0);
    println!("{across} pixels on a crease's line across undrawn edges");
    assert!(across > 100, "{across}");
    // Along the crease facing the eye, every pixel the edge passes through is on the line.
    let vp = camera.view_projection(size.0, size.1);
    for k in 1..200 {
        let y = -1.0 + 2.0 * f64::from(k) / 200.0;
        let c = vp * DVec3::new(1.0, y, 1.0).extend(1.0);
        let x = ((c.x / c.w + 1.0) * 0.5 * f64::from(size.0)).floor();
        let y = ((1.0 - c.y / c.w) * 0.5 * f64::from(size.1)).floor();
        if !(x >= 0.0 && y >= 0.0 && x < f64::from(size.0) && y < f64::from(size.1)) {
            continue;
        }
        let d = frame.edge_distance[y as usize * size.0 as usize + x as usize];
        assert!(
            d <= 0.75,
            "pixel ({x}, {y}) on the crease is {d} px from a line"
        );
    }
}

#[test]
fn feature_lines_on_a_dense_mesh_stay_wide() {
    // About 8 triangles per pixel on the faces, lines 8 px wide; seen near and far.
    let mesh = wirepass::mesh::cube(2_000_000).unwrap();
    let edges = EdgeSelection::Feature(30.0);
    let size = (320, 240);
    for (name, eye) in [
        ("near", DVec3::new(2.2, 1.8, 2.6)),
        ("far", DVec3::new(6.6, 5.4, 7.8)),
    ] {
        let camera = looking(eye, DVec3::ZERO);
        check(
            &format!("cube:2M {name} 8 px"),
            &mesh,
            camera,
            size,
            edges,
            8.0,
        );
    }
}

#[test]
fn suzannes_quads_are_drawn_whole() {
    let mesh = load("suzanne.obj");
    let size = (240, 180);
    let camera = framing(&mesh, size);
    for width in [1.5, 3.0] {
        let (truth, _) = check(
            &format!("suzanne polygon {width} px"),
            &mesh,
            camera,
            size,
            EdgeSelection::Polygon,
            width,
        );
        let across =
            lines_across_undrawn_edges(&mesh, &camera, &truth, EdgeSelection::Polygon, width);
        assert!(across > 50, "{across} pixels with a line across a diagonal");
    }
}

/// Regular n-gons for n = 3 to 12 in a row, and a row of each at a tenth of the size, in the
/// XY plane.
fn polygons() -> String {
    let mut text = String::new();
    let mut v = 0;
    for (row, scale) in [(0.0, 1.0), (-1.6, 0.1)] {
        for n in 3..=12 {
            let cx = (n as f64 - 7.5) * 2.2 * scale;
            for k in 0..n {
                let a = std::f64::consts::TAU * (k as f64 + 0.25) / n as f64;
                text += &format!("v {} {} 0\n", cx + scale * a.cos(), row + scale * a.sin());
            }
            text += "f";
            for k in 0..n {
                text += &format!(" {}", v + k + 1);
            }
            text += "\n";
            v += n;
        }
    }
    text
}

#[test]
fn n_gons_are_drawn_whole_down_to_pixel_size() {
    let mesh = obj("ngons", &polygons());
    // Face on (the small row a few pixels across), then from farther, where the small ones are
    // a pixel or two across.
    let eyes = [
        ("near", DVec3::new(0.0, -0.5, 14.0)),
        ("tilted", DVec3::new(6.0, -4.0, 9.0)),
        ("far", DVec3::new(0.37, -0.91, 50.0)),
    ];
    check_views(
        "n-gons",
        &mesh,
        DVec3::new(0.0, -0.5, 0.0),
        &eyes,
        &[1.5, 4.0],
    );
}

#[test]
fn concave_and_folded_polygons_are_drawn_whole() {
    // A ten-pointed star and an L (concave: lines of their edges pass through their inside),
    // and a quad folded along its diagonal (non-planar).
    let mut text = String::new();
    for k in 0..20 {
        let a = std::f64::consts::TAU * k as f64 / 20.0;
        let r = if k % 2 == 0 { 1.0 } else { 0.45 };
        text += &format!("v {} {} 0\n", -2.5 + r * a.cos(), r * a.sin());
    }
    text += "f";
    for k in 1..=20 {
        text += &format!(" {k}");
    }
    text += "\n";
    for (x, y) in [
        (0.0, -1.0),
        (1.0, -1.0),
        (1.0, 0.6),
        (0.5, 0.6),
        (0.5, 1.0),
        (0.0, 1.0),
    ] {
        text += &format!("v {} {} 0\n", x - 0.5, y);
    }
    text += "f 21 22 23 24 25 26\n";
    text += "v 1.5 -1 0\nv 3.5 -1 0.6\nv 3.5 1 0\nv 1.5 1 0.6\nf 27 28 29 30\n";
    let mesh = obj("concave", &text);
    let eyes = [
        ("front", DVec3::new(0.0, 0.0, 7.0)),
        ("oblique", DVec3::new(4.0, 3.0, 4.0)),
        ("grazing", DVec3::new(0.0, -7.0, 0.6)),
        ("behind", DVec3::new(-1.0, 1.0, -6.0)),
    ];
    check_views("concave/folded", &mesh, DVec3::ZERO, &eyes, &[1.5, 5.0]);
}

#[test]
fn quads_in_any_corner_order_and_winding_are_drawn_whole() {
    // A curved sheet of quads, each split along one diagonal, whose triangles list their
    // corners from any of the three, half of the second triangles wound the other way and
    // some sharing the diagonal's positions, not its vertices: the edge pass reads each
    // quad's other triangle from what the upload recorded about it.
    let (nx, ny) = (9, 7);
    let at = |i: usize, j: usize| {
        let (x, y) = (i as f32 / 3.0 - 1.5, j as f32 / 3.0 - 1.0);
        Vec3::new(x, y, 0.3 * (1.7 * x).sin() * (1.3 * y).cos())
    };
    let mut positions: Vec<Vec3> = (0..=ny)
        .flat_map(|j| (0..=nx).map(move |i| (i, j)))
        .map(|(i, j)| at(i, j))
        .collect();
    let (mut triangles, mut masks) = (Vec::new(), Vec::new());
    for j in 0..ny {
        for i in 0..nx {
            let q = j * nx + i;
            let v = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
            let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
            let (mut a2, mut c2) = (a, c);
            if q % 4 == 1 {
                positions.extend([positions[a as usize], positions[c as usize]]);
                a2 = positions.len() as u32 - 2;
                c2 = a2 + 1;
            }
            let second = if q % 2 == 1 { [a2, d, c2] } else { [a2, c2, d] };
            for (k, mut t) in [[a, b, c], second].into_iter().enumerate() {
                t.rotate_left((q + k) % 3);
                let diagonal = |x: u32, y: u32| {
                    let p = [x, y].map(|v| positions[v as usize]);
                    p.contains(&positions[a as usize]) && p.contains(&positions[c as usize])
                };
                masks.push((0..3).fold(0u8, |m, e| {
                    m | u8::from(!diagonal(t[e], t[(e + 1) % 3])) << e
                }));
                triangles.push(t);
            }
        }
    }
    let mesh = Mesh::new(positions, None, triangles, Some(masks)).unwrap();
    let eyes = [
        ("front", DVec3::new(0.2, 0.1, 4.5)),
        ("oblique", DVec3::new(2.5, -2.0, 2.5)),
        ("behind", DVec3::new(-1.0, 0.5, -4.0)),
    ];
    check_views("quads", &mesh, DVec3::ZERO, &eyes, &[1.5, 5.0]);
}

#[test]
fn a_quad_cut_by_the_near_plane_is_drawn_whole() {
    // One quad, folded, whose near corner lies behind the eye: the other triangle's pixels
    // beside the diagonal measure edges cut by the near plane (measured uncut, those edges
    // would run through them).
    let quad = Mesh::new(
        [
            (-1.5, 0.0, -1.0),
            (1.5, 0.0, -1.0),
            (0.0, 2.0, 4.0),
            (0.0, 0.0, -5.0),
        ]
        .map(|(x, y, z)| Vec3::new(x, y, z))
        .to_vec(),
        None,
        vec![[0, 1, 2], [1, 0, 3]],
        Some(vec![0b110, 0b110]),
    )
    .unwrap();
    let eye = [("from above", DVec3::new(0.3, 1.5, 2.0))];
    check_views(
        "a quad cut by the near plane",
        &quad,
        DVec3::new(0.0, 0.0, -2.0),
        &eye,
        &[1.5, 5.0],
    );
}

#[test]
fn quads_of_a_dense_sphere_are_drawn_whole() {
    // Quads of about half a pixel: the line of a quad edge crosses many diagonals.
    let mesh = wirepass::mesh::sphere(200_000).unwrap();
    let size = (320, 240);
    let camera = framing(&mesh, size);
    check(
        "sphere:200k polygon 3 px",
        &mesh,
        camera,
        size,
        EdgeSelection::Polygon,
        3.0,
    );
}

/// The deferred frame of `window` of `shot`'s image.
fn render_window(shot: &Shot<'_>, up: &Uploaded, window: Region) -> Rendering {
    let ctx = common::gpu();
    let pass = DeferredPass::new(&ctx.device, PassOptions::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .with_diagnostics();
    draw_deferred_on(ctx, shot, up, pass, window.into()).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn tiles_stitch_into_the_whole_image() {
    // Outlines, lines of large patches (the cube's creases) and of polygons (Suzanne's
    // quads), cut into 2 × 2 tiles at odd places, lines crossing every cut.
    let cases = [
        (
            "cube48 feature:30 6 px",
            wirepass::mesh::cube(27_648).unwrap(),
            EdgeSelection::Feature(30.0),
            6.0,
        ),
        (
            "suzanne polygon 3 px",
            load("suzanne.obj"),
            EdgeSelection::Polygon,
            3.0,
        ),
        // Grids one behind the other: outlines pass behind nearer grids at every cut.
        (
            "layers:6 polygon 4 px",
            wirepass::mesh::layers(6).unwrap(),
            EdgeSelection::Polygon,
            4.0,
        ),
    ];
    let size = (301, 227);
    for (name, mesh, edges, line_width) in cases {
        let camera = framing(&mesh, size);
        let world = World::single(mesh, edges);
        let style = Style {
            line_width,
            ..Style::default()
        };
        let shot = Shot {
            world: &world,
            view: camera.to_view(f64::from(size.0) / f64::from(size.1)),
            style: &style,
            size,
        };
        let up = Uploaded::new(&common::gpu().device, &common::gpu().queue, &world)
            .unwrap_or_else(|e| panic!("{e}"));
        let whole = render_window(&shot, &up, Region::whole(size));
        let (cx, cy) = (137, 101);
        for (x0, w) in [(0, cx), (cx, size.0 - cx)] {
            for (y0, h) in [(0, cy), (cy, size.1 - cy)] {
                let window = Region {
                    image: size,
                    origin: (x0, y0),
                    size: (w, h),
                };
                let tile = render_window(&shot, &up, window);
                let mut differ = Vec::new();
                for y in 0..h {
                    for x in 0..w {
                        let i = (y * w + x) as usize;
                        let j = ((y0 + y) * size.0 + x0 + x) as usize;
                        let same = tile.ids[i] == whole.ids[j]
                            && tile.edge_distance[i].to_bits() == whole.edge_distance[j].to_bits()
                            && tile.depth[i].to_bits() == whole.depth[j].to_bits()
                            && tile.rgba[4 * i..4 * i + 4] == whole.rgba[4 * j..4 * j + 4];
                        if !same {
                            differ.push(format!(
                                "({}, {}): id {} / {}, distance {} / {}",
                                x0 + x,
                                y0 + y,
                                tile.ids[i],
                                whole.ids[j],
                                tile.edge_distance[i],
                                whole.edge_distance[j]
                            ));
                        }
                    }
                }
                assert!(
                    differ.is_empty(),
                    "{name}, tile {window:?}: {} pixels differ from the whole image, e.g. {}",
                    differ.len(),
                    differ[..differ.len().min(5)].join("; ")
                );
            }
        }
    }
}

#[test]
fn an_edge_just_outside_the_image_draws_its_line_inside() {
    // A square whose left edge lies 1 px beyond the right border of a 240-pixel-wide image:
    // the background in the last column is 1.5 px from its outline.
    let size = (240u32, 180u32);
    let camera = looking(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO);
    let aspect = f64::from(size.0) / f64::from(size.1);
    let half_width = 5.0 * (f64::from(camera.fov_y_deg) / 2.0).to_radians().tan() * aspect;
    let x = (241.0 / f64::from(size.0) * 2.0 - 1.0) * half_width;
    let text = format!(
        "v {x} -0.5 0\nv {} -0.5 0\nv {} 0.5 0\nv {x} 0.5 0\nf 1 2 3 4\n",
        x + 1.0,
        x + 1.0
    );
    let mesh = obj("outside", &text);
    let (truth, frame) = check(
        "edge outside",
        &mesh,
        camera,
        size,
        EdgeSelection::Polygon,
        3.0,
    );
    let i = (90 * size.0 + 239) as usize;
    for (who, f) in [("ground truth", &truth), ("deferred", &frame)] {
        let d = f64::from(f.edge_distance[i]);
        assert!(
            (d - 1.5).abs() < 1e-3,
            "{who}: pixel (239, 90) is {d} px from a line"
        );
    }
}

#[test]
fn set_edges_redraws_a_stored_mesh_as_a_fresh_upload_would() {
    // Uploaded drawing every edge, switched to polygon edges (quads searched per pixel) and
    // to feature edges (large patches, lines from the trace pass): each frame equals that of
    // a mesh uploaded with the selection in the first place.
    let mesh = load("suzanne.obj");
    let size = (160, 120);
    let camera = framing(&mesh, size);
    let style = Style {
        line_width: 3.0,
        ..Style::default()
    };
    let view = camera.to_view(f64::from(size.0) / f64::from(size.1));
    let ctx = common::gpu();
    let all = World::single(mesh.clone(), EdgeSelection::All);
    let mut switched =
        Uploaded::new(&ctx.device, &ctx.queue, &all).unwrap_or_else(|e| panic!("{e}"));
    for edges in [EdgeSelection::Polygon, EdgeSelection::Feature(30.0)] {
        let world = World::single(mesh.clone(), edges);
        let shot = Shot {
            world: &world,
            view,
            style: &style,
            size,
        };
        let id = switched.ids[0];
        switched
            .store
            .set_edges(&ctx.device, &ctx.queue, id, &mesh, edges)
            .unwrap_or_else(|e| panic!("{e}"));
        let fresh =
            Uploaded::new(&ctx.device, &ctx.queue, &world).unwrap_or_else(|e| panic!("{e}"));
        let a = render_window(&shot, &switched, Region::whole(size));
        let b = render_window(&shot, &fresh, Region::whole(size));
        assert_eq!(a.ids, b.ids, "{edges:?}");
        assert!(
            a.edge_distance
                .iter()
                .zip(&b.edge_distance)
                .all(|(x, y)| x.to_bits() == y.to_bits()),
            "{edges:?}: distances differ"
        );
        assert_eq!(a.rgba, b.rgba, "{edges:?}");
    }
}
