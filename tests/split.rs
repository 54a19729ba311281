//! A mesh store whose vertex or per-triangle buffers exceed `max_storage_buffer_binding_size`
//! is bound as two ranges of each buffer (src/gpu/mesh_store.rs). On a device with a lowered
//! limit, every method must render such a mesh exactly as a device that binds it whole does.

mod common;

use common::gpu;
use glam::{DMat4, DVec3, Vec3};
use std::sync::{Arc, Mutex, MutexGuard};
use wirepass::gpu::{DeferredPass, GpuContext, MeshStore, OutputTarget, PassOptions};
use wirepass::mesh::Procedural;
use wirepass::tools::load::CameraPlacement;
use wirepass::tools::offline::{draw, Method, Uploaded};
use wirepass::world::{Object, Shot, World, WorldMesh, BACKGROUND};
use wirepass::{Color, EdgeSelection, Error, Instance, InstanceStyle, Scene, Style};

/// 64 KiB: 5440 triangles of indices in the first binding (a multiple of 64 triangles, so
/// the second binding's offset is 256-byte aligned).
const SMALL: u32 = 1 << 16;
const FIRST_BINDING_TRIANGLES: u32 = 5440;

/// The tests here hold a second device beside the shared one. wgpu's GL backend gives both
/// devices one EGL context, and using them from two threads at once loses draws, so these
/// tests take turns.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

fn small_device() -> (GpuContext, MutexGuard<'static, ()>) {
    let turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let ctx = gpu();
    let limits = wgpu::Limits {
        max_storage_buffer_binding_size: SMALL.into(),
        ..ctx.adapter.limits()
    };
    let small = GpuContext::with_limits(ctx.adapter.clone(), limits);
    (small.expect("a device with a lowered limit"), turn)
}

#[test]
fn a_mesh_split_over_two_bindings_renders_as_if_whole() {
    let (small, _turn) = small_device();
    // 8000 triangles (96 000 bytes of indices), 4002 vertices (48 024 bytes of positions).
    let mesh = Procedural::Sphere(8000).build().unwrap();
    assert!(mesh.triangle_count() as u32 * 12 > SMALL);
    assert!(mesh.positions().len() as u32 * 12 <= SMALL);
    let size = (96, 64);
    // From below, where the triangles past the split lie.
    let below = CameraPlacement {
        eye: Some(Vec3::new(0.6, -2.5, 1.2)),
        ..CameraPlacement::default()
    };
    let camera = below.camera(mesh.bounds_f64(), size).unwrap();
    // The mesh's triangles are stored in cluster order: where each file triangle is stored.
    let order = &mesh.traced_clusters().order;
    let mut stored = vec![0u32; order.len()];
    for (s, &t) in order.iter().enumerate() {
        stored[t as usize] = s as u32;
    }
    let world = World::single(mesh.clone(), EdgeSelection::All);
    let style = Style::default();
    let shot = Shot {
        world: &world,
        view: camera.to_view(96.0 / 64.0),
        style: &style,
        size,
    };
    for method in [Method::Deferred, Method::Forward, Method::TwoPass] {
        let whole = draw(gpu(), &shot, method).unwrap();
        let split = draw(&small, &shot, method).unwrap();
        assert!(whole.ids.iter().filter(|&&id| id != BACKGROUND).count() > 2000);
        // Both halves are drawn: triangles on either side of the split appear.
        let high = split
            .ids
            .iter()
            .filter(|&&id| id != BACKGROUND && stored[id as usize] >= FIRST_BINDING_TRIANGLES)
            .count();
        assert!(
            high > 1000,
            "{method:?}: {high} pixels from the second binding"
        );
        assert_eq!(whole.ids, split.ids, "{method:?} ids");
        assert_eq!(whole.rgba, split.rgba, "{method:?} image");
        let same = |a: f32, b: f32| a == b || (a.is_nan() && b.is_nan());
        let distances = whole.edge_distance.iter().zip(&split.edge_distance);
        assert!(
            distances.clone().all(|(&a, &b)| same(a, b)),
            "{method:?} distances"
        );
    }
    small.finish().unwrap();
}

/// A store on `ctx` holding `mesh`, and a scene of one instance of it.
fn stored(
    ctx: &GpuContext,
    mesh: &wirepass::Mesh,
    size: (u32, u32),
) -> (MeshStore, Scene<'static>) {
    let mut store = MeshStore::new(&ctx.device);
    let id = store
        .insert(&ctx.device, &ctx.queue, mesh, EdgeSelection::All)
        .unwrap();
    let camera = CameraPlacement::default()
        .camera(mesh.bounds_f64(), size)
        .unwrap();
    let view = camera.to_view(f64::from(size.0) / f64::from(size.1));
    (
        store,
        Scene::new(view, vec![Instance::new(id, DMat4::IDENTITY)]),
    )
}

#[test]
fn the_pulled_visibility_pass_reads_both_halves() {
    let (small, _turn) = small_device();
    let device = &small.device;
    let mesh = Procedural::Sphere(8000).build().unwrap();
    let size = (96, 64);
    let (store, scene) = stored(&small, &mesh, size);
    let ids = |pulled: bool| {
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
        small.queue.submit([encoder.finish()]);
        small.finish().unwrap();
        let t = frame.id_texture();
        wirepass::gpu::read_texture(device, &small.queue, t, wgpu::TextureAspect::All).unwrap()
    };
    assert_eq!(ids(true), ids(false));
}

#[test]
fn a_mesh_past_two_bindings_is_a_clear_error() {
    let (small, _turn) = small_device();
    // 12 000 triangles (144 000 bytes of indices, more than two 64 KiB bindings) over 100
    // vertices, so the indices are the one buffer past the limit.
    let positions: Vec<Vec3> = (0..100)
        .map(|i| Vec3::new((i % 10) as f32, (i / 10) as f32, (i % 7) as f32))
        .collect();
    let triangles: Vec<[u32; 3]> = (0..12_000u32)
        .map(|t| [t % 100, (t * 7 + 1) % 100, (t * 13 + 5) % 100])
        .filter(|[a, b, c]| a != b && b != c && a != c)
        .collect();
    assert!(triangles.len() * 12 > 2 * SMALL as usize);
    let mesh = wirepass::Mesh::new(positions, None, triangles, None).unwrap();
    let mut store = MeshStore::new(&small.device);
    let e = match store.insert(&small.device, &small.queue, &mesh, EdgeSelection::All) {
        Ok(_) => panic!("{} triangles fit", mesh.triangle_count()),
        Err(e) => e,
    };
    assert!(matches!(e, Error::OverLimit { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(
        msg.contains("max_storage_buffer_binding_size × 2 = 131072") && msg.contains("(by "),
        "{msg}"
    );
}

#[test]
fn an_image_past_the_trace_buffer_limit_is_a_clear_error() {
    let (small, _turn) = small_device();
    let device = &small.device;
    let mesh = Procedural::Sphere(200).build().unwrap();
    // 4 bytes a pixel: 160 × 120 needs 76 800 bytes, over 64 KiB.
    let size = (160, 120);
    let (store, scene) = stored(&small, &mesh, size);
    let mut pass = DeferredPass::new(device, PassOptions::default()).unwrap();
    let e = pass
        .prepare(device, &store, &scene, &Style::default(), size)
        .err()
        .unwrap();
    let msg = e.to_string();
    assert!(
        msg.contains("trace buffer") && msg.contains("max_storage_buffer_binding_size = 65536"),
        "{msg}"
    );
    small.finish().unwrap();
}

/// The trace pass lists the pieces of outline edges after the lines (and their tiles) in its
/// buffer; where the buffer has no room left for them, the piece dispatch draws the
/// clusters it could not list in lanes of their own, to the same image.
#[test]
fn traced_pieces_past_the_list_s_room_are_drawn_all_the_same() {
    let (small, _turn) = small_device();
    let mesh = Arc::new(Procedural::Sphere(2000).build().unwrap());
    // Two spheres with lines of different colours keep two words a target pixel: at 82 × 81
    // (90 × 89 with the guard band) the lines take 64 080 of the 65 536 bytes, the tiles
    // they reach 984.
    let size = (82, 81);
    let object = |x: f64, color: &str| Object {
        mesh: 0,
        transform: DMat4::from_translation(DVec3::new(x, 0.0, 0.0)),
        style: InstanceStyle {
            wire_color: Some(Color::from_hex(color).unwrap()),
            ..InstanceStyle::default()
        },
    };
    let world = World {
        sections: Vec::new(),
        meshes: vec![WorldMesh {
            mesh,
            edges: EdgeSelection::All,
            name: "sphere".into(),
        }],
        objects: vec![object(-1.05, "#c03020"), object(1.05, "#2030c0")],
    };
    let camera = CameraPlacement::default()
        .camera(world.bounds(), size)
        .unwrap();
    let style = Style::default();
    let shot = Shot {
        world: &world,
        view: camera.to_view(82.0 / 81.0),
        style: &style,
        size,
    };
    // What the trace pass listed on the small device, and its room.
    let up = Uploaded::new(&small.device, &small.queue, &world).unwrap();
    let mut pass = DeferredPass::new(&small.device, PassOptions::default()).unwrap();
    let frame = pass
        .prepare(
            &small.device,
            &up.store,
            &up.scene(&world, shot.view),
            &style,
            size,
        )
        .unwrap();
    let output = wirepass::gpu::texture_2d(
        &small.device,
        "output",
        size,
        pass.output_format(),
        wgpu::TextureUsages::STORAGE_BINDING,
    );
    let view = output.create_view(&Default::default());
    let mut encoder = small.device.create_command_encoder(&Default::default());
    pass.encode(
        &small.device,
        &mut encoder,
        &up.store,
        &frame,
        OutputTarget::Shaded(&view),
    )
    .unwrap();
    small.queue.submit([encoder.finish()]);
    let work = frame.edge_work(&small.device, &small.queue).unwrap();
    assert!(
        work.piece_room < 64 && work.traced_pieces > 2 * work.piece_room && work.overflowed > 0,
        "{work:?}"
    );

    let whole = draw(gpu(), &shot, Method::Deferred).unwrap();
    let cramped = draw(&small, &shot, Method::Deferred).unwrap();
    let lines = whole.edge_distance.iter().filter(|&&d| d < 2.0).count();
    assert!(lines > 1500, "{lines} pixels near a line");
    let differ = |a: &[u8], b: &[u8]| a.iter().zip(b).filter(|(x, y)| x != y).count();
    assert_eq!(
        differ(&whole.rgba, &cramped.rgba),
        0,
        "image bytes that differ"
    );
    assert!(whole.ids == cramped.ids, "ids differ");
    let same = |a: f32, b: f32| a == b || (a.is_nan() && b.is_nan());
    let distances = whole.edge_distance.iter().zip(&cramped.edge_distance);
    let off = distances.filter(|(&a, &b)| !same(a, b)).count();
    assert_eq!(off, 0, "distances that differ");
    small.finish().unwrap();
}
