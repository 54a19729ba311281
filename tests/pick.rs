//! Picking (`PreparedFrame::pick`, `pick_rect_async`, `InstanceHit::locate`) against the
//! frame's own id map and against the ray-cast ground truth: every pixel of a frame of two
//! meshes, one of them mirrored, picks the instance and file triangle the ground truth sees
//! (≥ 99.9 % of foreground pixels, as the id agreement bound) and exactly what the id map
//! holds; the located point projects back to the pixel's centre and has the ground truth's
//! depth; the snapped edge is the ground truth's nearest drawn line; a vertex under the
//! cursor snaps; rectangles list the instances they show; the host's pixels pick the host;
//! misuse is an `Error`.

mod common;

use wirepass::glam::{DMat4, DQuat, DVec3};
use wirepass::gpu::{
    read_texture, texture_2d, Canvas, DeferredPass, HostDepth, PassOptions, PickView, Picked,
    PreparedFrame,
};
use wirepass::tools::offline::{encode_shaded, Uploaded};
use wirepass::truth::draw_raycast;
use wirepass::world::{Object, Shot, World, WorldMesh, BACKGROUND};
use wirepass::{wgpu, Camera, EdgeSelection, Error, Scene, Style};

const SIZE: (u32, u32) = (240, 180);

/// A torus and a mirrored, tilted copy of it beside a sphere: quads and a pole fan.
fn world() -> World {
    let torus = std::sync::Arc::new(wirepass::mesh::torus(800).unwrap());
    let sphere = std::sync::Arc::new(wirepass::mesh::sphere(600).unwrap());
    let tilt = DQuat::from_rotation_x(0.8);
    World {
        sections: Vec::new(),
        meshes: vec![
            WorldMesh {
                mesh: torus,
                edges: EdgeSelection::Polygon,
                name: "torus".into(),
            },
            WorldMesh {
                mesh: sphere,
                edges: EdgeSelection::Feature(20.0),
                name: "sphere".into(),
            },
        ],
        objects: vec![
            Object::new(
                0,
                DMat4::from_rotation_translation(tilt, DVec3::new(-1.4, 0.0, 0.0)),
            ),
            Object::new(
                0,
                DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0))
                    * DMat4::from_rotation_translation(tilt, DVec3::new(-1.4, 0.0, 0.0)),
            ),
            Object::new(1, DMat4::from_translation(DVec3::new(0.0, 1.1, -0.5))),
        ],
    }
}

/// Without outlines, so the ground truth's nearest line is a drawn edge.
fn style() -> Style {
    Style {
        outlines: false,
        ..Style::default()
    }
}

struct Frame {
    world: World,
    up: Uploaded,
    scene: Scene<'static>,
    frame: PreparedFrame,
    view: PickView,
}

fn encoded(world: World, canvas: Option<&wgpu::Texture>) -> Frame {
    let ctx = common::gpu();
    let up = Uploaded::new(&ctx.device, &ctx.queue, &world).unwrap();
    let (lo, hi) = world.bounds();
    let aspect = f64::from(SIZE.0) / f64::from(SIZE.1);
    let view = Camera::framing(lo, hi, aspect).to_view(aspect);
    let scene = up.scene(&world, view);
    let mut pass = DeferredPass::new(&ctx.device, PassOptions::default()).unwrap();
    let mut on = Canvas::new(SIZE);
    if let Some(depth) = canvas {
        on = on.with_host_depth(HostDepth {
            texture: depth,
            matrices: view,
        });
    }
    let style = style();
    let shot = Shot {
        world: &world,
        view,
        style: &style,
        size: SIZE,
    };
    let (frame, _image) =
        encode_shaded(&ctx.device, &ctx.queue, &shot, &up, &mut pass, on).unwrap();
    ctx.finish().unwrap();
    Frame {
        world,
        up,
        scene,
        frame,
        view: PickView {
            view,
            image: SIZE,
            vertices: wirepass::gpu::SnapVertices::Any,
            sections: Vec::new(),
        },
    }
}

/// Where world point `p` falls in the image, in pixels (x right, y down), and its depth.
fn on_screen(view: &PickView, p: DVec3) -> ((f64, f64), f64) {
    let clip = view.view.view_projection() * p.extend(1.0);
    let ndc = clip.truncate() / clip.w;
    let (w, h) = (f64::from(view.image.0), f64::from(view.image.1));
    (((ndc.x + 1.0) * 0.5 * w, (1.0 - ndc.y) * 0.5 * h), ndc.z)
}

#[test]
fn every_pixel_picks_what_the_id_map_and_the_ground_truth_show() {
    let ctx = common::gpu();
    let f = encoded(world(), None);
    let style = style();
    let truth = draw_raycast(&Shot {
        world: &f.world,
        view: f.view.view,
        style: &style,
        size: SIZE,
    })
    .unwrap();
    let first = f.world.first_ids();
    // The whole id map, decoded the tools' way, for exact equality.
    let raw = read_texture(
        &ctx.device,
        &ctx.queue,
        f.frame.id_texture(),
        wgpu::TextureAspect::All,
    )
    .unwrap();
    let words: Vec<u32> = bytemuck::pod_collect_to_vec(&raw);
    let (g, width) = (f.frame.guard(), f.frame.id_texture().width());

    // The id map (which every pick equals, below) against the ground truth, every pixel.
    let mut foreground = 0;
    let mut agree = 0;
    for y in 0..SIZE.1 {
        for x in 0..SIZE.0 {
            let texel = ((y + g) * width + x + g) as usize;
            let raw = [words[2 * texel], words[2 * texel + 1]];
            let got =
                f.up.global_ids(&f.world, f.frame.instance_order(), &[raw])
                    .unwrap()[0];
            let want = truth.ids[(y * SIZE.0 + x) as usize];
            if want != BACKGROUND || got != BACKGROUND {
                foreground += 1;
                agree += usize::from(want == got);
            }
        }
    }
    let (mut picks, mut located, mut snapped, mut on_line, mut same_line) = (0, 0, 0, 0, 0);
    let (mut exact_foreground, mut exact_agree) = (0, 0);
    let mut worst_depth = 0f64;
    let mut worst_reprojection = 0f64;
    let mut worst_snap = 0f64;
    for y in (0..SIZE.1).step_by(2) {
        for x in (0..SIZE.0).step_by(2) {
            let picked = f
                .frame
                .pick(&ctx.device, &ctx.queue, &f.up.store, &f.scene, (x, y))
                .unwrap();
            let texel = ((y + g) * width + x + g) as usize;
            let raw = [words[2 * texel], words[2 * texel + 1]];
            let global =
                f.up.global_ids(&f.world, f.frame.instance_order(), &[raw])
                    .unwrap()[0];
            let k = (y * SIZE.0 + x) as usize;
            let want = truth.ids[k];
            let got = match picked {
                Picked::Background => BACKGROUND,
                Picked::Host => panic!("no host here"),
                Picked::Instance(hit) => first[hit.instance] + hit.triangle,
            };
            assert_eq!(
                got, global,
                "pixel ({x}, {y}): the pick is not the id map's value"
            );
            picks += 1;
            let Picked::Instance(hit) = picked else {
                exact_foreground += usize::from(want != BACKGROUND);
                continue;
            };
            let object = &f.world.objects[hit.instance];
            let wm = &f.world.meshes[object.mesh];
            // The hit carries the instance's placement and its mesh's drawn edges.
            assert_eq!((hit.transform, hit.edges), (object.transform, wm.edges));
            let at = hit.locate(&wm.mesh, &f.view, (x, y), 3.0).unwrap();
            // Off the surface at a silhouette: what is behind, here the background.
            let exact = if at.inside {
                first[hit.instance] + at.triangle
            } else {
                BACKGROUND
            };
            exact_foreground += 1;
            exact_agree += usize::from(exact == want);
            if exact != want || !at.inside {
                continue;
            }
            located += 1;
            // The point lies on the pixel's ray, at the ground truth's depth.
            let (px, depth) = on_screen(&f.view, at.point);
            worst_reprojection = worst_reprojection
                .max((px.0 - (f64::from(x) + 0.5)).abs())
                .max((px.1 - (f64::from(y) + 0.5)).abs());
            worst_depth = worst_depth.max((depth - f64::from(truth.depth[k])).abs());
            // The normal faces the eye.
            let eye = f.view.view.eye();
            assert!(
                at.normal.dot(eye.truncate() - at.point * eye.w) > 0.0,
                "({x}, {y})"
            );
            // The nearest drawn line of the ground truth is the snapped edge.
            let d = f64::from(truth.edge_distance[k]);
            if d < 2.5 {
                on_line += 1;
                if let Some(edge) = at.edge {
                    snapped += 1;
                    // Never farther than the line the pixel shows; the same line but where
                    // another patch's line passes nearer.
                    worst_snap = worst_snap.max(edge.distance_px - d);
                    same_line += usize::from((edge.distance_px - d).abs() < 1e-3);
                }
            }
        }
    }
    let agreement = agree as f64 / foreground as f64;
    let exact = exact_agree as f64 / exact_foreground as f64;
    println!(
        "{foreground} foreground pixels, agreement {agreement:.5}; {picks} picks, located \
         triangles agree on {exact:.5} of the foreground, {located} located: reprojection ≤ {worst_reprojection:.2e} px, depth ≤ {worst_depth:.2e}; \
         {snapped} of {on_line} near a line snapped ({same_line} to the ground truth's own \
         line), never farther than it by more than {worst_snap:.2e} px"
    );
    assert!(agreement >= 0.999, "{agreement}");
    assert!(
        exact >= 0.9995 && exact >= agreement,
        "{exact} against {agreement}"
    );
    assert!(located > 1000);
    assert!(worst_reprojection < 1e-6, "{worst_reprojection}");
    assert!(worst_depth < 1e-6, "{worst_depth}");
    assert!(
        on_line > 200 && snapped * 100 >= on_line * 99,
        "{snapped} of {on_line}"
    );
    assert!(worst_snap < 1e-3, "{worst_snap}");
    assert!(same_line * 100 >= snapped * 95, "{same_line} of {snapped}");
}

#[test]
fn a_vertex_under_the_cursor_snaps_and_polygons_count_as_the_file_does() {
    let ctx = common::gpu();
    // A quad, a triangle and a pentagon: triangles 0–1, 2 and 3–5.
    let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 3.5 0.8 0\nv 2.5 1.4 0\nv 1.6 0.9 0\n\
f 1 2 3 4\nf 2 5 3\nf 5 6 7 8 9\n";
    let mesh = wirepass::mesh::load_bytes(std::path::Path::new("faces.obj"), obj).unwrap();
    assert_eq!(mesh.triangle_count(), 6);
    let world = World::single(mesh, EdgeSelection::Polygon);
    let f = encoded(world, None);
    let mesh = &f.world.meshes[0].mesh;
    let locate = |hit: &wirepass::gpu::InstanceHit, px, radius| {
        hit.locate(mesh, &f.view, px, radius).unwrap()
    };
    let mut polygons = Vec::new();
    for t in 0..6u32 {
        // The centroid of each triangle, on screen.
        let [a, b, c] =
            mesh.triangles()[t as usize].map(|v| mesh.positions()[v as usize].as_dvec3());
        let centroid = (a + b + c) / 3.0;
        let ((sx, sy), _) = on_screen(&f.view, centroid);
        let px = (sx as u32, sy as u32);
        let Picked::Instance(hit) = f
            .frame
            .pick(&ctx.device, &ctx.queue, &f.up.store, &f.scene, px)
            .unwrap()
        else {
            panic!("triangle {t}'s centroid shows no triangle");
        };
        assert_eq!(hit.triangle, t);
        let at = locate(&hit, px, 1.0);
        polygons.push(at.polygon);
    }
    assert_eq!(polygons, [0, 0, 1, 2, 2, 2]);

    // Vertex 7 (the pentagon's top), one pixel off: it snaps, with its index and position.
    let p = mesh.positions()[7].as_dvec3();
    let ((sx, sy), _) = on_screen(&f.view, p);
    let px = ((sx - 1.0) as u32, (sy + 1.0) as u32);
    let Picked::Instance(hit) = f
        .frame
        .pick(&ctx.device, &ctx.queue, &f.up.store, &f.scene, px)
        .unwrap()
    else {
        panic!("no triangle next to vertex 7");
    };
    let at = locate(&hit, px, 3.0);
    let vertex = at.vertex.expect("a vertex within 3 px");
    assert_eq!(vertex.vertex, 7);
    assert!((vertex.position - p).length() < 1e-12);
    assert!(vertex.distance_px < 3.0);
    let edge = at.edge.expect("an edge within 3 px");
    assert!(edge.vertices.contains(&7), "{edge:?}");
    assert!(edge.t >= 0.0 && edge.t <= 1.0);
    // None within a radius of zero.
    let at = locate(&hit, px, 0.0);
    assert_eq!((at.vertex, at.edge), (None, None));
}

/// A CAD host snaps to the ends of drawn edges only (`SnapVertices::OnDrawnEdges`): on a flat
/// grid whose feature edges are its boundary, an interior vertex under the cursor snaps with
/// `Any` and not with `OnDrawnEdges`, and a boundary corner snaps with either.
#[test]
fn vertices_on_no_drawn_edge_can_be_left_out_of_snapping() {
    use wirepass::gpu::SnapVertices;
    let ctx = common::gpu();
    // 4 × 4 cells over [-1, 1]²: vertex 12 is the centre, vertex 0 the corner (-1, -1).
    let grid = wirepass::mesh::grid(32).unwrap();
    let edges = EdgeSelection::Feature(30.0);
    let f = encoded(World::single(grid, edges), None);
    let mesh = &f.world.meshes[0].mesh;
    let snapped = |v: usize, offset: (f64, f64), vertices: SnapVertices| {
        let ((sx, sy), _) = on_screen(&f.view, mesh.positions()[v].as_dvec3());
        let px = ((sx + offset.0) as u32, (sy + offset.1) as u32);
        let Picked::Instance(hit) = f
            .frame
            .pick(&ctx.device, &ctx.queue, &f.up.store, &f.scene, px)
            .unwrap()
        else {
            panic!("no triangle next to vertex {v}");
        };
        let view = f.view.clone().snapping_to(vertices);
        let at = hit.locate(mesh, &view, px, 3.0).unwrap();
        at.vertex.map(|s| s.vertex)
    };
    assert_eq!(mesh.positions()[12], wirepass::glam::Vec3::ZERO);
    assert_eq!(snapped(12, (1.0, 1.0), SnapVertices::Any), Some(12));
    assert_eq!(snapped(12, (1.0, 1.0), SnapVertices::OnDrawnEdges), None);
    assert_eq!(snapped(0, (1.0, -1.0), SnapVertices::OnDrawnEdges), Some(0));
}

#[test]
fn rectangles_hosts_and_misuse() {
    let ctx = common::gpu();
    let f = encoded(world(), None);
    let pick = |origin, size, triangles| {
        pollster::block_on(f.frame.pick_rect_async(
            &ctx.device,
            &ctx.queue,
            &f.up.store,
            &f.scene,
            origin,
            size,
            triangles,
        ))
    };
    let all = pick((0, 0), SIZE, false).unwrap();
    assert_eq!(all.instances, [0, 1, 2]);
    assert!(all.triangles.is_empty() && !all.host);
    let with = pick((0, 0), SIZE, true).unwrap();
    assert!(with.triangles.len() > 500, "{}", with.triangles.len());
    // The top-left corner is background.
    let corner = pick((0, 0), (4, 4), true).unwrap();
    assert!(corner.instances.is_empty() && corner.triangles.is_empty());
    // Misuse: outside the frame, empty, another scene.
    for (origin, size) in [
        ((SIZE.0, 0), (1, 1)),
        ((0, 0), (0, 1)),
        ((10, 10), (SIZE.0, 1)),
    ] {
        match pick(origin, size, false) {
            Err(Error::InvalidSetting(_)) => {}
            other => panic!("{origin:?} {size:?}: {other:?}"),
        }
    }
    let fewer = Scene::borrowed(f.scene.view, &f.scene.instances[..2]);
    match f
        .frame
        .pick(&ctx.device, &ctx.queue, &f.up.store, &fewer, (1, 1))
    {
        Err(Error::Misuse(_)) => {}
        other => panic!("{other:?}"),
    }

    // A host depth at the near plane everywhere: every pixel is the host's.
    let depth = texture_2d(
        &ctx.device,
        "host depth",
        SIZE,
        wgpu::TextureFormat::Depth32Float,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("host"),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &depth.create_view(&Default::default()),
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(0.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        ..Default::default()
    });
    ctx.queue.submit([encoder.finish()]);
    let h = encoded(world(), Some(&depth));
    let centre = (SIZE.0 / 2, SIZE.1 / 2);
    assert_eq!(
        h.frame
            .pick(&ctx.device, &ctx.queue, &h.up.store, &h.scene, centre)
            .unwrap(),
        Picked::Host
    );
    ctx.finish().unwrap();
}
