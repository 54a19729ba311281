//! The deferred pass end to end on a software adapter: edge selection, hard cameras,
//! determinism, and the post-process (overlay) mode of the library API.

mod common;

use common::{camera, cpu_distance, framing, gpu, load, near_crossed, shoot};
use glam::{DMat4, Vec3};
use wirepass::gpu::{
    Canvas, DeferredPass, EncodeOptions, MeshStore, OutputTarget, PassOptions, PreparedFrame,
    Tuning,
};
use wirepass::tools::compare::metrics;
use wirepass::tools::offline::{draw_deferred_on, Method, Uploaded};
use wirepass::world::{Rendering, BACKGROUND};
use wirepass::{
    Camera, Color, EdgeSelection, HiddenLines, Instance, LinePattern, Mesh, Scene, Style,
};

/// Draws without outlines: the tests here check each triangle's own edges against the CPU
/// definition; outlines are checked against the ground truth (tests/ground_truth.rs,
/// tests/outline.rs).
fn draw(mesh: &Mesh, camera: Camera, size: (u32, u32), edges: EdgeSelection) -> Rendering {
    let style = Style {
        outlines: false,
        ..Style::default()
    };
    draw_styled(mesh, camera, size, edges, style)
}

fn draw_styled(
    mesh: &Mesh,
    camera: Camera,
    size: (u32, u32),
    edges: EdgeSelection,
    style: Style,
) -> Rendering {
    shoot(mesh, camera, &style, size, edges, Method::Deferred)
}

/// Largest |GPU − CPU| edge distance over covered pixels whose true distance is under
/// `reach` pixels, given the GPU's own ids. This checks the edge pass's math (not coverage):
/// same triangle, same definition, f32 on the GPU against f64 on the CPU. Pixels within
/// 5 px of a drawn edge of a patch that crosses another surface are left out
/// ([`near_crossed`]).
fn max_distance_error(
    mesh: &Mesh,
    cam: &Camera,
    frame: &Rendering,
    edges: EdgeSelection,
    reach: f64,
) -> (f64, usize) {
    let (w, h) = frame.size;
    let crossed = near_crossed(mesh, edges, cam, frame.size, 5.0);
    let mut worst: f64 = 0.0;
    let mut measured = 0;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let id = frame.ids[i];
            let gpu_d = frame.edge_distance[i];
            assert!(!gpu_d.is_nan(), "NaN distance at ({x}, {y})");
            if crossed[i] {
                continue;
            }
            if id == BACKGROUND {
                assert!(
                    gpu_d.is_infinite(),
                    "background pixel ({x}, {y}) has distance {gpu_d}"
                );
                continue;
            }
            let cpu_d = cpu_distance(mesh, cam, frame.size, edges, id, (x, y));
            if cpu_d < reach {
                measured += 1;
                worst = worst.max((f64::from(gpu_d) - cpu_d).abs());
            }
        }
    }
    (worst, measured)
}

#[test]
fn suzanne_draws_no_quad_diagonal() {
    let mesh = load("suzanne.obj");
    let size = (256, 256);
    let cam = framing(&mesh, size);
    // 3 px lines: full line colour within 0.5 px of an edge.
    let style = Style {
        line_width: 3.0,
        outlines: false,
        ..Style::default()
    };
    let polygon = draw_styled(&mesh, cam, size, EdgeSelection::Polygon, style.clone());
    let all = draw_styled(&mesh, cam, size, EdgeSelection::All, style.clone());
    assert_eq!(
        polygon.ids, all.ids,
        "edge selection must not change coverage"
    );

    // With every edge drawn the own triangle's edges are the definition (tests/lines.rs
    // holds polygon mode, where lines cross diagonals, to the ground truth).
    let (err, n) = max_distance_error(&mesh, &cam, &all, EdgeSelection::All, 4.0);
    assert!(n > 1000, "too few pixels near edges: {n}");
    assert!(err <= 0.01, "All: max |GPU − CPU| distance {err} px");
    // Pixels on a quad diagonal: a line with `All`, none with `Polygon`.
    let masks = mesh.edge_mask(EdgeSelection::Polygon);
    let wire = style.wire_color.to_srgb8();
    let mut on_diagonal = 0;
    for (i, &id) in polygon.ids.iter().enumerate() {
        if id == BACKGROUND || masks[id as usize] == 0b111 {
            continue;
        }
        let (x, y) = (i as u32 % size.0, i as u32 / size.0);
        let to_diagonal = cpu_distance(&mesh, &cam, size, EdgeSelection::All, id, (x, y));
        if to_diagonal < 0.25 && polygon.edge_distance[i] > 3.0 {
            on_diagonal += 1;
            let near_wire = |px: &[u8]| px.iter().zip(wire).all(|(a, b)| a.abs_diff(b) < 40);
            assert!(
                near_wire(&all.rgba[4 * i..4 * i + 3]),
                "All: no line on a diagonal at ({x}, {y})"
            );
            assert!(
                !near_wire(&polygon.rgba[4 * i..4 * i + 3]),
                "Polygon: a diagonal is drawn at ({x}, {y})"
            );
        }
    }
    assert!(
        on_diagonal > 100,
        "only {on_diagonal} diagonal pixels checked"
    );
}

#[test]
fn triangle_mesh_with_all_edges_matches_the_cpu_definition() {
    let mesh = load("teapot.obj");
    let cam = framing(&mesh, (320, 240));
    let frame = draw(&mesh, cam, (320, 240), EdgeSelection::All);
    let (err, n) = max_distance_error(&mesh, &cam, &frame, EdgeSelection::All, 4.0);
    assert!(n > 1000);
    assert!(
        err <= 0.01,
        "max |GPU − CPU| distance {err} px over {n} pixels"
    );
}

#[test]
fn eye_inside_the_bunny_cuts_the_near_plane_cleanly() {
    let mesh = load("stanford-bunny.obj");
    let (lo, hi) = mesh.bounds();
    let centre = (lo + hi) * 0.5;
    // Inside the body, looking towards the head: the near plane cuts many triangles, some
    // of whose vertices are behind the eye.
    let cam = camera(centre, centre + Vec3::new(-0.3, 0.4, 0.2), 0.02, 1.0);
    let frame = draw(&mesh, cam, (320, 240), EdgeSelection::All);
    let covered = frame.ids.iter().filter(|&&id| id != BACKGROUND).count();
    assert!(
        covered > 320 * 240 / 2,
        "only {covered} pixels see the inside of the bunny"
    );
    let (err, n) = max_distance_error(&mesh, &cam, &frame, EdgeSelection::All, 4.0);
    assert!(n > 1000);
    assert!(
        err <= 0.01,
        "max |GPU − CPU| distance {err} px over {n} pixels"
    );
    assert!(
        seen_crossing(&mesh, &cam, &frame, |clip| clip.z < 0.0) > 1000,
        "the near plane should cut visible triangles"
    );
}

#[test]
fn vertices_behind_the_eye_keep_exact_edges() {
    // A coarse floor seen from just above it: visible triangles reach behind the eye.
    let mesh = wirepass::mesh::grid(200).unwrap();
    let cam = camera(
        Vec3::new(0.1, -0.2, 0.03),
        Vec3::new(0.3, 1.0, 0.0),
        0.01,
        10.0,
    );
    let cam = Camera { up: Vec3::Z, ..cam };
    let frame = draw(&mesh, cam, (320, 240), EdgeSelection::All);
    let (err, n) = max_distance_error(&mesh, &cam, &frame, EdgeSelection::All, 4.0);
    assert!(n > 1000);
    assert!(
        err <= 0.01,
        "max |GPU − CPU| distance {err} px over {n} pixels"
    );
    assert!(
        seen_crossing(&mesh, &cam, &frame, |clip| clip.w < 0.0) > 1000,
        "no visible triangle reaches behind the eye"
    );
}

/// Number of covered pixels whose triangle has a corner for which `test(clip)` holds.
fn seen_crossing(
    mesh: &Mesh,
    cam: &Camera,
    frame: &Rendering,
    test: impl Fn(glam::DVec4) -> bool,
) -> usize {
    let vp = cam.view_projection(frame.size.0, frame.size.1);
    frame
        .ids
        .iter()
        .filter(|&&id| id != BACKGROUND)
        .filter(|&&id| {
            mesh.triangles()[id as usize]
                .iter()
                .any(|&v| test(vp * mesh.positions()[v as usize].as_dvec3().extend(1.0)))
        })
        .count()
}

#[test]
fn same_render_twice_is_identical() {
    let mesh = wirepass::mesh::builtin_mesh();
    let cam = framing(&mesh, (300, 200));
    let a = draw(&mesh, cam, (300, 200), EdgeSelection::Polygon);
    let b = draw(&mesh, cam, (300, 200), EdgeSelection::Polygon);
    assert_eq!(a.rgba, b.rgba);
    assert_eq!(a.ids, b.ids);
    assert_eq!(
        bytemuck::cast_slice::<f32, u8>(&a.edge_distance),
        bytemuck::cast_slice::<f32, u8>(&b.edge_distance)
    );
}

/// A mesh in a fresh store, and the scene of one instance of it at the origin.
fn single(mesh: &Mesh, edges: EdgeSelection, view: wirepass::View) -> (MeshStore, Scene<'static>) {
    let ctx = gpu();
    let mut store = MeshStore::new(&ctx.device);
    let id = store.insert(&ctx.device, &ctx.queue, mesh, edges).unwrap();
    let scene = Scene::new(view, vec![Instance::new(id, DMat4::IDENTITY)]);
    (store, scene)
}

#[test]
fn overlay_blends_lines_over_the_host_image_and_resizes() {
    let ctx = gpu();
    let device = &ctx.device;
    let mesh = wirepass::mesh::sphere(2000).unwrap();
    let mut pass = DeferredPass::new(
        device,
        PassOptions {
            output_format: wgpu::TextureFormat::Rgba16Float,
            ..Default::default()
        },
    )
    .unwrap()
    .with_diagnostics();
    let style = Style::default();
    let host_color = [0.2_f32, 0.4, 0.6, 1.0];
    for size in [(64u32, 48u32), (96, 96)] {
        let cam = framing(&mesh, size);
        let aspect = f64::from(size.0) / f64::from(size.1);
        let (store, scene) = single(&mesh, EdgeSelection::All, cam.to_view(aspect));
        let frame = pass.prepare(device, &store, &scene, &style, size).unwrap();
        let texture = |usage| {
            wirepass::gpu::texture_2d(
                device,
                "test",
                size,
                wgpu::TextureFormat::Rgba16Float,
                usage,
            )
        };
        use wgpu::TextureUsages as U;
        let host = texture(U::TEXTURE_BINDING | U::RENDER_ATTACHMENT);
        let output = texture(U::STORAGE_BINDING | U::COPY_SRC);
        let (host_view, out_view) = (
            host.create_view(&Default::default()),
            output.create_view(&Default::default()),
        );
        let mut encoder = device.create_command_encoder(&Default::default());
        // The host's own rendering: a flat clear.
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &host_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: 0.2,
                        g: 0.4,
                        b: 0.6,
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.encode(
            device,
            &mut encoder,
            &store,
            &frame,
            OutputTarget::Overlay {
                host: &host_view,
                output: &out_view,
            },
        )
        .unwrap();
        pass.encode_with(
            device,
            &mut encoder,
            &store,
            &frame,
            OutputTarget::Diagnostic,
            EncodeOptions {
                reuse_ids: true,
                ..Default::default()
            },
        )
        .unwrap();
        ctx.queue.submit([encoder.finish()]);
        ctx.finish().unwrap();
        let texels: Vec<[half::f16; 4]> = bytemuck::pod_collect_to_vec(
            &wirepass::gpu::read_texture(device, &ctx.queue, &output, wgpu::TextureAspect::All)
                .unwrap(),
        );
        let diag: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(
            &wirepass::gpu::read_texture(
                device,
                &ctx.queue,
                frame.diagnostic_texture().unwrap(),
                wgpu::TextureAspect::All,
            )
            .unwrap(),
        );
        let (mut lines, mut plain) = (0, 0);
        for (t, d) in texels.iter().zip(&diag) {
            let c = t.map(half::f16::to_f32);
            let far_from_edges = d[0] >= 3.0; // beyond the 1.5 px line's reach
            if far_from_edges {
                plain += 1;
                for k in 0..4 {
                    assert!(
                        (c[k] - host_color[k]).abs() < 2e-3,
                        "host colour changed: {c:?}"
                    );
                }
            } else if d[0] < 0.1 {
                lines += 1;
                let wire = style.wire_color.0;
                let i = wirepass::style::line_intensity(f64::from(d[0]), 1.5) as f32;
                for k in 0..3 {
                    let expect = host_color[k] * (1.0 - i) + wire[k] * i;
                    assert!(
                        (c[k] - expect).abs() < 5e-3,
                        "line pixel {c:?}, expected {expect}"
                    );
                }
            }
        }
        assert!(
            lines > 10 && plain > 10,
            "{lines} line pixels, {plain} plain pixels at {size:?}"
        );
    }
}

#[test]
fn timer_reports_every_pass() {
    let ctx = gpu();
    let device = &ctx.device;
    let mesh = wirepass::mesh::builtin_mesh();
    let mut pass = DeferredPass::new(device, PassOptions::default())
        .unwrap()
        .with_diagnostics();
    let cam = framing(&mesh, (64, 64));
    let (store, scene) = single(&mesh, EdgeSelection::Polygon, cam.to_view(1.0));
    let frame = pass
        .prepare(device, &store, &scene, &Style::default(), (64, 64))
        .unwrap();
    let mut timer = wirepass::gpu::GpuTimer::new(device, &ctx.queue, 16)
        .expect("software adapters expose TIMESTAMP_QUERY");
    // The second round reads the timer without blocking.
    for round in 0..2 {
        let mut encoder = device.create_command_encoder(&Default::default());
        pass.encode_with(
            device,
            &mut encoder,
            &store,
            &frame,
            OutputTarget::Diagnostic,
            EncodeOptions {
                timer: Some(&mut timer),
                ..Default::default()
            },
        )
        .unwrap();
        timer.resolve(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
        let spans = match round {
            0 => timer.read(device).unwrap(),
            _ => pollster::block_on(timer.read_async(device)).unwrap(),
        };
        let names: Vec<_> = spans.iter().map(|s| s.0).collect();
        assert_eq!(
            names,
            [
                "visibility",
                "trace.cull",
                "trace.list",
                "trace.pieces",
                "edge.classify",
                "edge.border",
                "edge.background",
                "edge.traced",
                "edge.tiles",
                "edge.refine"
            ]
        );
        assert!(
            spans.iter().all(|s| s.1.is_finite() && s.1 >= 0.0),
            "{spans:?}"
        );
    }
}

#[test]
fn vertex_pulling_fallback_matches_primitive_index() {
    let ctx = gpu();
    let device = &ctx.device;
    let mesh = load("suzanne.obj");
    let size = (128, 128);
    let cam = framing(&mesh, size);
    // Two instances, so the pulled pass's triangle numbering per instance is checked too.
    let (store, mut scene) = single(&mesh, EdgeSelection::Polygon, cam.to_view(1.0));
    let copy = Instance::new(
        scene.instances[0].mesh,
        DMat4::from_translation(glam::DVec3::new(0.4, 0.1, -0.5)),
    );
    scene.instances.to_mut().push(copy);
    let read = |pulled: bool| {
        let mut pass = common::diagnostic_pass(device, pulled);
        let frame = pass
            .prepare(device, &store, &scene, &Style::default(), size)
            .unwrap();
        let mut encoder = device.create_command_encoder(&Default::default());
        pass.encode(
            device,
            &mut encoder,
            &store,
            &frame,
            OutputTarget::Diagnostic,
        )
        .unwrap();
        ctx.queue.submit([encoder.finish()]);
        ctx.finish().unwrap();
        let ids = frame.id_texture();
        wirepass::gpu::read_texture(device, &ctx.queue, ids, wgpu::TextureAspect::All).unwrap()
    };
    let pulled = read(true);
    let indexed = read(false);
    let ids = bytemuck::cast_slice::<u8, [u32; 2]>(&pulled);
    let covered = ids.iter().filter(|id| id[0] != BACKGROUND).count();
    assert!(covered > 1000);
    for slot in [0, 1] {
        assert!(
            ids.iter().any(|id| id[0] == slot),
            "no pixel of instance {slot}"
        );
    }
    assert_eq!(
        pulled, indexed,
        "the fallback visibility pass must give the same ids"
    );
}

#[test]
fn edge_work_lists_the_tiles_with_foreground_and_the_background_beside_it() {
    let ctx = gpu();
    let device = &ctx.device;
    let mesh = load("suzanne.obj");
    let size = (100, 70);
    let cam = framing(&mesh, size);
    let (store, scene) = single(&mesh, EdgeSelection::Polygon, cam.to_view(100.0 / 70.0));
    let mut pass = DeferredPass::new(device, PassOptions::default())
        .unwrap()
        .with_diagnostics();
    let mut draw = |store: &MeshStore, scene: &Scene<'_>| {
        let frame = pass
            .prepare(device, store, scene, &Style::default(), size)
            .unwrap();
        let mut encoder = device.create_command_encoder(&Default::default());
        pass.encode(
            device,
            &mut encoder,
            store,
            &frame,
            OutputTarget::Diagnostic,
        )
        .unwrap();
        ctx.queue.submit([encoder.finish()]);
        let work = frame.edge_work(device, &ctx.queue).unwrap();
        (frame, work)
    };
    let (frame, work) = draw(&store, &scene);
    // What the rasterizer left, read back: foreground where the instance slot is valid.
    let ids = wirepass::gpu::read_texture(
        device,
        &ctx.queue,
        frame.id_texture(),
        wgpu::TextureAspect::All,
    )
    .unwrap();
    let (w, h) = (size.0 as i64, size.1 as i64);
    // The targets hold a guard band around the output; (x, y) are output pixels.
    let g = i64::from(frame.guard());
    let fg_any = |x: i64, y: i64| {
        (-g..w + g).contains(&x) && (-g..h + g).contains(&y) && {
            let i = (((y + g) * (w + 2 * g) + x + g) * 8) as usize;
            u32::from_le_bytes(ids[i..i + 4].try_into().unwrap()) < u32::MAX - 1
        }
    };
    let fg = |x: i64, y: i64| (0..w).contains(&x) && (0..h).contains(&y) && fg_any(x, y);
    let tiles = (0..(h + 7) / 8)
        .flat_map(|ty| (0..(w + 7) / 8).map(move |tx| (tx, ty)))
        .filter(|&(tx, ty)| (0..64).any(|k| fg(tx * 8 + k % 8, ty * 8 + k / 8)))
        .count() as u32;
    let mut beside = 0;
    let mut foreground = 0;
    for y in 0..h {
        for x in 0..w {
            if fg(x, y) {
                foreground += 1;
            } else if fg_any(x - 1, y) || fg_any(x + 1, y) || fg_any(x, y - 1) || fg_any(x, y + 1) {
                // Beside foreground in the output or in the guard band.
                beside += 1;
            }
        }
    }
    assert_eq!(work.tiles, tiles, "{work:?}");
    assert_eq!(work.all_tiles, 13 * 9);
    // The tiles the outline's lines reach, each listed once: there are more pieces, each
    // reaching a tile at least, than tiles.
    assert!(
        work.traced_tiles > 10 && work.traced_tiles <= work.all_tiles,
        "{work:?}"
    );
    assert!(work.traced_pieces > work.all_tiles, "{work:?}");
    assert_eq!(work.pixels, 7000);
    assert!(tiles > 10 && beside > 50, "{tiles} tiles, {beside} beside");
    // Every background pixel beside the foreground once, and the foreground the exact test
    // could not settle: a few per cent of it at most.
    assert!(
        work.refined >= beside && work.refined <= beside + foreground / 20,
        "{work:?}: {beside} background pixels beside {foreground} foreground"
    );

    // Looking away from the mesh: nothing for the later dispatches.
    let away = Camera {
        target: cam.eye + (cam.eye - cam.target),
        ..cam
    };
    let (store, scene) = single(&mesh, EdgeSelection::Polygon, away.to_view(100.0 / 70.0));
    let (_, work) = draw(&store, &scene);
    assert_eq!(
        (work.tiles, work.traced_tiles, work.refined),
        (0, 0, 0),
        "{work:?}"
    );
}

/// `warm_up` builds every pipeline the frame's encode uses: after it, encoding builds
/// none, for a frame with outlines, one without, and a second output kind. Without it, the
/// first encode of each kind builds its own.
#[test]
fn warm_up_builds_what_the_first_encode_would() {
    let ctx = gpu();
    let d = &ctx.device;
    let mesh = wirepass::mesh::torus(500).unwrap();
    let size = (64, 48);
    let view = framing(&mesh, size).to_view(64.0 / 48.0);
    let (store, scene) = single(&mesh, EdgeSelection::Polygon, view);
    use wirepass::wgpu::TextureUsages as U;
    let encode = |pass: &DeferredPass, frame: &PreparedFrame, target: OutputTarget<'_>| {
        let mut encoder = d.create_command_encoder(&Default::default());
        pass.encode(d, &mut encoder, &store, frame, target).unwrap();
        ctx.queue.submit([encoder.finish()]);
    };
    for outlines in [true, false] {
        let style = Style {
            outlines,
            ..Style::default()
        };
        let mut pass = DeferredPass::new(d, PassOptions::default()).unwrap();
        let usage = U::STORAGE_BINDING | U::TEXTURE_BINDING;
        let output = wirepass::gpu::texture_2d(d, "out", size, pass.output_format(), usage);
        let host = wirepass::gpu::texture_2d(d, "host", size, pass.output_format(), usage);
        let out = output.create_view(&Default::default());
        let host = host.create_view(&Default::default());
        let frame = pass.prepare(d, &store, &scene, &style, size).unwrap();
        let shaded = OutputTarget::Shaded(&out);
        let overlay = || OutputTarget::Overlay {
            host: &host,
            output: &out,
        };

        pass.warm_up(d, &frame, &shaded).unwrap();
        let built = pass.pipelines_built();
        assert!(built >= 1, "outlines {outlines}");
        encode(&pass, &frame, shaded);
        assert_eq!(pass.pipelines_built(), built, "outlines {outlines}");

        // Another output kind, not warmed up: its first encode builds its pipelines.
        encode(&pass, &frame, overlay());
        let after = pass.pipelines_built();
        assert!(after > built, "outlines {outlines}");
        pass.warm_up(d, &frame, &overlay()).unwrap();
        encode(&pass, &frame, overlay());
        assert_eq!(pass.pipelines_built(), after, "outlines {outlines}");
    }
    ctx.finish().unwrap();
}

/// The async readback gives the bytes the blocking one gives, for the output and the id
/// target, and the same edge work counters (padded rows: 37 texels of 4 or 8 bytes), driven by the simplest executor, which
/// nothing else polls the device for. (GL cannot copy depth textures out.)
#[test]
fn async_readback_reads_what_the_blocking_one_reads() {
    let ctx = gpu();
    let d = &ctx.device;
    let mesh = wirepass::mesh::torus(300).unwrap();
    let size = (37, 29);
    let view = framing(&mesh, size).to_view(37.0 / 29.0);
    let (store, scene) = single(&mesh, EdgeSelection::Polygon, view);
    let mut pass = DeferredPass::new(d, PassOptions::default()).unwrap();
    let frame = pass
        .prepare(d, &store, &scene, &Style::default(), size)
        .unwrap();
    use wirepass::wgpu::TextureUsages as U;
    let usage = U::STORAGE_BINDING | U::COPY_SRC;
    let output = wirepass::gpu::texture_2d(d, "out", size, pass.output_format(), usage);
    let out = output.create_view(&Default::default());
    let mut encoder = d.create_command_encoder(&Default::default());
    pass.encode(d, &mut encoder, &store, &frame, OutputTarget::Shaded(&out))
        .unwrap();
    ctx.queue.submit([encoder.finish()]);
    use wirepass::gpu::{read_texture, read_texture_async};
    use wirepass::wgpu::TextureAspect as A;
    for (texture, aspect) in [(&output, A::All), (frame.id_texture(), A::All)] {
        let blocking = read_texture(d, &ctx.queue, texture, aspect).unwrap();
        let future = read_texture_async(d, &ctx.queue, texture, aspect);
        let awaited = pollster::block_on(future).unwrap();
        assert_eq!(blocking, awaited, "{:?}", texture.format());
        assert!(blocking.iter().any(|&b| b != 0), "{:?}", texture.format());
    }
    let work = frame.edge_work(d, &ctx.queue).unwrap();
    let awaited = pollster::block_on(frame.edge_work_async(d, &ctx.queue)).unwrap();
    assert_eq!(work, awaited);
    assert!(work.tiles > 0 && work.traced_clusters > 0, "{work:?}");
    ctx.finish().unwrap();
}

/// The GPU tuning (outline edges in pieces of 1 px, the background written by a dispatch),
/// which the software adapters the tests run on never pick by themselves, draws to the
/// bounds the software tuning does: against the ground truth on every pixel (outlines over
/// the background, dashed hidden lines, the eye inside, a grazing view), and the two images
/// a step of 8 bits apart at most. It lists the outline edges in many more pieces.
#[test]
fn gpu_tuning_draws_what_the_software_tuning_draws() {
    let ctx = gpu();
    let device = &ctx.device;
    let fandisk = load("fandisk.obj");
    let suzanne = load("suzanne.obj");
    let torus = wirepass::mesh::torus(3000).unwrap();
    let size = (200, 150);
    let hidden = |pattern| {
        Some(HiddenLines {
            pattern,
            color: Color([0.8, 0.1, 0.1, 1.0]),
            width: 1.0,
            behind_host: false,
            edges: true,
        })
    };
    let wide = Style {
        line_width: 3.0,
        hidden: hidden(LinePattern::Dashed {
            dash: 6.0,
            gap: 4.0,
        }),
        ..Style::default()
    };
    let dotted = Style {
        hidden: hidden(LinePattern::Dotted { spacing: 4.0 }),
        ..Style::default()
    };
    // From the head's centre, up and to the side, through the eyes' sockets.
    let (lo, hi) = suzanne.bounds();
    let centre = (lo + hi) * 0.5;
    let inside = camera(centre, centre + Vec3::new(-0.3, 0.4, 0.2), 1e-3, 10.0);
    let grazing = camera(Vec3::new(3.0, 0.25, 0.4), Vec3::ZERO, 0.05, 20.0);
    let cases = [
        (
            "fandisk",
            &fandisk,
            framing(&fandisk, size),
            wide,
            EdgeSelection::Feature(30.0),
        ),
        (
            "suzanne inside",
            &suzanne,
            inside,
            dotted,
            EdgeSelection::Polygon,
        ),
        (
            "torus grazing",
            &torus,
            grazing,
            Style::default(),
            EdgeSelection::Polygon,
        ),
    ];
    for (name, mesh, cam, style, edges) in cases {
        let scene = common::TestScene::new(mesh, cam, style, size, edges);
        let shot = scene.shot();
        let truth = scene.draw(Method::Raycast);
        let up = Uploaded::new(device, &ctx.queue, shot.world).unwrap();
        let frames = [Tuning::Software, Tuning::Gpu].map(|tuning| {
            let options = PassOptions {
                tuning,
                ..PassOptions::default()
            };
            let pass = DeferredPass::new(device, options)
                .unwrap()
                .with_diagnostics();
            let frame = draw_deferred_on(ctx, &shot, &up, pass, Canvas::new(shot.size)).unwrap();
            let m = metrics(&truth, &frame).unwrap();
            println!("{name} {tuning:?}: {m:?}");
            assert!(m.id_agreement >= 0.999, "{name} {tuning:?}: {m:?}");
            let hidden = wirepass::truth::accuracy::hidden_distance_errors(&truth, &frame).unwrap();
            let worst = common::worst_pixels(&truth, &frame, 0.01, 5)
                + &common::worst_of(&truth, &frame, (&hidden, |r| &r.hidden_distance), 0.01, 5);
            for d in [&m.distance_error_px, &m.hidden_distance_error_px] {
                let within = d.p99.unwrap_or(0.0) <= 0.01 && d.max.unwrap_or(0.0) <= 0.1;
                assert!(within, "{name} {tuning:?}: {m:?}{worst}");
            }
            frame
        });
        let apart = (0..frames[0].ids.len())
            .filter(|&i| common::channel_difference(&frames[0], &frames[1], i) > 1)
            .count();
        assert_eq!(apart, 0, "{name}: pixels more than a step apart");
    }

    // The pieces: up to a pixel of outline each on the GPU, up to 2 px in software (so the
    // GPU's list is the longer wherever fandisk's outline edges are longer than a pixel).
    let cam = framing(&fandisk, size);
    let aspect = f64::from(size.0) / f64::from(size.1);
    let (store, scene) = single(&fandisk, EdgeSelection::Feature(30.0), cam.to_view(aspect));
    let pieces = [Tuning::Software, Tuning::Gpu].map(|tuning| {
        let options = PassOptions {
            tuning,
            ..PassOptions::default()
        };
        let mut pass = DeferredPass::new(device, options).unwrap();
        common::frame_work(&mut pass, &store, &scene, &Style::default(), size).traced_pieces
    });
    assert!(
        pieces[0] > 50 && 2 * pieces[1] > 3 * pieces[0],
        "pieces {pieces:?}"
    );
}

#[test]
fn a_pipeline_cache_changes_nothing_drawn() {
    let ctx = gpu();
    if !ctx
        .device
        .features()
        .contains(wgpu::Features::PIPELINE_CACHE)
    {
        println!(
            "{}: no pipeline cache (wgpu has one on Vulkan)",
            ctx.describe()
        );
        return;
    }
    // SAFETY: made from no data: an empty cache.
    let cache = unsafe {
        ctx.device
            .create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
                label: None,
                data: None,
                fallback: true,
            })
    };
    let fandisk = load("fandisk.obj");
    let size = (200, 150);
    let style = Style {
        hidden: Some(HiddenLines {
            pattern: LinePattern::Dashed {
                dash: 6.0,
                gap: 4.0,
            },
            ..HiddenLines::default()
        }),
        ..Style::default()
    };
    let edges = EdgeSelection::Feature(30.0);
    let scene = common::TestScene::new(&fandisk, framing(&fandisk, size), style, size, edges);
    let shot = scene.shot();
    let up = Uploaded::new(&ctx.device, &ctx.queue, shot.world).unwrap();
    let frames = [None, Some(cache.clone())].map(|pipeline_cache| {
        let options = PassOptions {
            pipeline_cache,
            ..PassOptions::default()
        };
        let pass = DeferredPass::new(&ctx.device, options)
            .unwrap()
            .with_diagnostics();
        draw_deferred_on(ctx, &shot, &up, pass, Canvas::new(shot.size)).unwrap()
    });
    assert!(frames[0].rgba == frames[1].rgba && frames[0].ids == frames[1].ids);
    // What a host saves for the next run.
    assert!(cache.get_data().is_some_and(|d| !d.is_empty()));
}
