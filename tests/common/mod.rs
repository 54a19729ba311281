//! Helpers shared by the GPU integration tests.
#![allow(dead_code)]

pub mod gltf_file;

use glam::{DVec2, Vec3};
use std::path::PathBuf;
use std::sync::OnceLock;
use wirepass::gpu::{DeferredPass, EdgeWork, GpuContext, MeshStore, PassOptions, TriangleIds};
use wirepass::tools::offline::{draw, Method};
use wirepass::truth::accuracy::{
    distance_error, hidden_distance_error, hidden_distance_errors, id_agreement, DistanceError,
};
use wirepass::world::{Rendering, Shot, World};
use wirepass::{edge_math, Camera, EdgeSelection, Mesh, Scene, Style};

/// What the pass took on (`PreparedFrame::edge_work`) for one frame of `scene`, drawn shaded
/// into a storage texture of `size`.
pub fn frame_work(
    pass: &mut DeferredPass,
    store: &MeshStore,
    scene: &Scene<'_>,
    style: &Style,
    size: (u32, u32),
) -> EdgeWork {
    let ctx = gpu();
    let (device, queue) = (&ctx.device, &ctx.queue);
    let frame = pass.prepare(device, store, scene, style, size).unwrap();
    let usage = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT;
    let output = wirepass::gpu::texture_2d(device, "out", size, pass.output_format(), usage);
    let view = output.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    let target = wirepass::gpu::OutputTarget::Shaded(&view);
    pass.encode(device, &mut encoder, store, &frame, target)
        .unwrap();
    queue.submit([encoder.finish()]);
    frame.edge_work(device, queue).unwrap()
}

/// One device for the whole test binary. A missing adapter fails loudly: GPU tests never
/// pass by skipping.
pub fn gpu() -> &'static GpuContext {
    static CTX: OnceLock<GpuContext> = OnceLock::new();
    CTX.get_or_init(|| match GpuContext::new() {
        Ok(ctx) => ctx,
        Err(e) => panic!(
            "GPU tests need an adapter (lavapipe: apt-get install mesa-vulkan-drivers, or \
             WGPU_BACKEND=gl for llvmpipe): {e}"
        ),
    })
}

/// Path of a test mesh in `tests/data/meshes` (see its README for their origins).
pub fn test_mesh(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/meshes")
        .join(name)
}

/// Loads a test mesh from `tests/data/meshes`.
pub fn load(name: &str) -> Mesh {
    wirepass::mesh::load_obj(&test_mesh(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// A camera at `eye` looking at `target`, with explicit planes.
pub fn camera(eye: Vec3, target: Vec3, near: f32, far: f32) -> Camera {
    Camera {
        eye,
        target,
        up: Vec3::Y,
        fov_y_deg: 50.0,
        near,
        far,
    }
}

/// The f64 edge distance of pixel (x, y) to triangle `id`, as the CPU definition gives it.
pub fn cpu_distance(
    mesh: &Mesh,
    camera: &Camera,
    size: (u32, u32),
    edges: EdgeSelection,
    id: u32,
    (x, y): (u32, u32),
) -> f64 {
    let vp = camera.view_projection(size.0, size.1);
    let tri = mesh.triangles()[id as usize];
    let clip = tri.map(|v| vp * mesh.positions()[v as usize].as_dvec3().extend(1.0));
    let mask = mesh.edge_mask(edges)[id as usize];
    let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
    let size = DVec2::new(f64::from(size.0), f64::from(size.1));
    edge_math::edge_eval(clip, mask, pixel, size).min_distance()
}

/// Renders one mesh, placed once at the origin, with `method`.
pub fn shoot(
    mesh: &Mesh,
    camera: Camera,
    style: &Style,
    size: (u32, u32),
    edges: EdgeSelection,
    method: Method,
) -> Rendering {
    let world = World::single(mesh.clone(), edges);
    shoot_world(
        &world,
        camera.to_view(f64::from(size.0) / f64::from(size.1)),
        style,
        size,
        method,
    )
}

/// Renders a world with `method`.
pub fn shoot_world(
    world: &World,
    view: wirepass::View,
    style: &Style,
    size: (u32, u32),
    method: Method,
) -> Rendering {
    let shot = Shot {
        world,
        view,
        style,
        size,
    };
    draw(gpu(), &shot, method).unwrap_or_else(|e| panic!("{}: {e}", method.name()))
}

/// The ground truth's and the deferred pass's frames of a world.
pub fn truth_and_frame(
    world: &World,
    view: wirepass::View,
    style: &Style,
    size: (u32, u32),
) -> (Rendering, Rendering) {
    (
        shoot_world(world, view, style, size, Method::Raycast),
        shoot_world(world, view, style, size, Method::Deferred),
    )
}

/// The accuracy bounds a frame is held to against the ground truth, over every pixel.
pub const MIN_ID_AGREEMENT: f64 = 0.999;
pub const MAX_P99_PX: f64 = 0.01;
pub const MAX_ERROR_PX: f64 = 0.1;

/// How a frame measures against the ground truth.
#[derive(Debug)]
pub struct Accuracy {
    /// The share of pixels showing the same triangle.
    pub ids: f64,
    /// The distance error of the lines, and of the hidden lines.
    pub lines: DistanceError,
    pub hidden: DistanceError,
}

/// Holds `frame` to the accuracy bounds against `truth` over every pixel: the id agreement,
/// and the distance error's p99 and max of the lines and of the hidden lines (where any pixel
/// of them is measured). Panics naming `name` and the worst pixels.
pub fn within_bounds(name: &str, truth: &Rendering, frame: &Rendering) -> Accuracy {
    let ids = id_agreement(truth, frame)
        .unwrap_or_else(|e| panic!("{e}"))
        .0;
    let lines = distance_error(truth, frame).unwrap_or_else(|e| panic!("{e}"));
    let hidden = hidden_distance_error(truth, frame).unwrap_or_else(|e| panic!("{e}"));
    println!("{name}: id {ids:.5}, lines {lines:?}, hidden {hidden:?}");
    assert!(ids >= MIN_ID_AGREEMENT, "{name}: id agreement {ids}");
    let within = |d: &DistanceError| {
        d.pixels == 0
            || (d.p99.is_some_and(|v| v <= MAX_P99_PX) && d.max.is_some_and(|v| v <= MAX_ERROR_PX))
    };
    assert!(
        within(&lines),
        "{name}: lines {lines:?}{}",
        worst_pixels(truth, frame, MAX_P99_PX, 8)
    );
    assert!(
        within(&hidden),
        "{name}: hidden lines {hidden:?}{}",
        worst_hidden(truth, frame)
    );
    Accuracy { ids, lines, hidden }
}

/// The 8 pixels with the largest hidden-line distance errors over 0.01 px.
pub fn worst_hidden(truth: &Rendering, frame: &Rendering) -> String {
    let errors = hidden_distance_errors(truth, frame).unwrap_or_else(|e| panic!("{e}"));
    worst_of(
        truth,
        frame,
        (&errors, |r| &r.hidden_distance),
        MAX_P99_PX,
        8,
    )
}

/// The camera that frames `mesh` for an image of `size`.
pub fn framing(mesh: &Mesh, size: (u32, u32)) -> Camera {
    let (lo, hi) = mesh.bounds_f64();
    Camera::framing(lo, hi, f64::from(size.0) / f64::from(size.1))
}

/// One mesh at the origin, a camera, a style and a size: what most tests render.
pub struct TestScene {
    pub world: World,
    pub view: wirepass::View,
    pub style: Style,
    pub size: (u32, u32),
}

impl TestScene {
    pub fn new(
        mesh: &Mesh,
        camera: Camera,
        style: Style,
        size: (u32, u32),
        edges: EdgeSelection,
    ) -> TestScene {
        TestScene {
            world: World::single(mesh.clone(), edges),
            view: camera.to_view(f64::from(size.0) / f64::from(size.1)),
            style,
            size,
        }
    }

    pub fn shot(&self) -> Shot<'_> {
        Shot {
            world: &self.world,
            view: self.view,
            style: &self.style,
            size: self.size,
        }
    }

    pub fn draw(&self, method: Method) -> Rendering {
        draw(gpu(), &self.shot(), method).unwrap_or_else(|e| panic!("{}: {e}", method.name()))
    }
}

/// The largest difference of pixel `i`'s four 8-bit channels between two renderings.
pub fn channel_difference(a: &Rendering, b: &Rendering, i: usize) -> u8 {
    (0..4)
        .map(|c| a.rgba[4 * i + c].abs_diff(b.rgba[4 * i + c]))
        .max()
        .unwrap_or(0)
}

/// The `n` pixels with the largest distance errors over `bound`, for failure messages.
pub fn worst_pixels(truth: &Rendering, frame: &Rendering, bound: f64, n: usize) -> String {
    let errors =
        wirepass::tools::compare::distance_errors(truth, frame).unwrap_or_else(|e| panic!("{e}"));
    worst_of(truth, frame, (&errors, |r| &r.edge_distance), bound, n)
}

/// A distance map of a rendering.
pub type DistanceMap = fn(&Rendering) -> &[f32];

/// [`worst_pixels`] of the given per-pixel errors of the distance map `map`.
pub fn worst_of(
    truth: &Rendering,
    frame: &Rendering,
    (errors, map): (&[Option<f64>], DistanceMap),
    bound: f64,
    n: usize,
) -> String {
    let mut worst: Vec<(usize, f64)> = errors
        .iter()
        .enumerate()
        .filter_map(|(i, e)| e.filter(|&e| e > bound).map(|e| (i, e)))
        .collect();
    worst.sort_by(|a, b| b.1.total_cmp(&a.1));
    let width = truth.size.0 as usize;
    worst
        .iter()
        .take(n)
        .map(|&(i, _)| {
            format!(
                "\n    pixel ({}, {}) id {}: truth {} measured {}",
                i % width,
                i / width,
                truth.ids[i] as i64,
                map(truth)[i],
                map(frame)[i]
            )
        })
        .collect()
}

/// A deferred pass with diagnostics on `device`, its visibility pass taking triangle ids
/// from pulled vertices (`pulled`) or from the primitive index.
pub fn diagnostic_pass(device: &wgpu::Device, pulled: bool) -> DeferredPass {
    let triangle_ids = if pulled {
        TriangleIds::VertexPulling
    } else {
        TriangleIds::PrimitiveIndex
    };
    let options = PassOptions {
        triangle_ids,
        ..PassOptions::default()
    };
    DeferredPass::new(device, options)
        .unwrap()
        .with_diagnostics()
}

/// A closed cylinder of `n` sides, radius 1, from y = -0.5 to 0.5: its rims are circles of
/// `n` short feature edges each, chains of drawn edges.
pub fn cylinder(n: u32) -> Mesh {
    let mut p = Vec::new();
    for y in [-0.5f32, 0.5] {
        p.extend((0..n).map(|k| {
            let a = k as f32 / n as f32 * std::f32::consts::TAU;
            Vec3::new(a.cos(), y, a.sin())
        }));
    }
    p.extend([Vec3::new(0.0, -0.5, 0.0), Vec3::new(0.0, 0.5, 0.0)]);
    let mut tris = Vec::new();
    for k in 0..n {
        let j = (k + 1) % n;
        tris.extend([
            [k, n + k, j],
            [j, n + k, n + j],
            [2 * n, k, j],
            [2 * n + 1, n + j, n + k],
        ]);
    }
    Mesh::new(p, None, tris, None).unwrap()
}

/// Per pixel of an image of `size` through `camera`, whether it lies within `radius` pixels
/// of a drawn edge (under `edges`) of a patch that crosses another surface of the mesh: the
/// lines of such patches are drawn by the trace pass where visible, over their neighbours
/// and the background too, not by the own-triangle definition the forward methods share
/// (`wirepass::mesh::patches::Patches::crossed`; `tests/crossings.rs` holds them to the
/// ground truth).
pub fn near_crossed(
    mesh: &Mesh,
    edges: EdgeSelection,
    camera: &Camera,
    size: (u32, u32),
    radius: f64,
) -> Vec<bool> {
    let masks = mesh.edge_mask(edges);
    let crossed = wirepass::mesh::patches::Patches::new(
        mesh.edge_neighbours(),
        &masks,
        mesh.crossed_triangles(),
    )
    .crossed;
    let vp = camera.view_projection(size.0, size.1);
    let extent = DVec2::new(f64::from(size.0), f64::from(size.1));
    let mut near = vec![false; size.0 as usize * size.1 as usize];
    for (t, tri) in mesh.triangles().iter().enumerate() {
        if !crossed[t] {
            continue;
        }
        let clip = tri.map(|v| vp * mesh.positions()[v as usize].as_dvec3().extend(1.0));
        for i in (0..3).filter(|i| masks[t] & (1 << i) != 0) {
            for (k, out) in near.iter_mut().enumerate() {
                let pixel = DVec2::new(
                    (k % size.0 as usize) as f64 + 0.5,
                    (k / size.0 as usize) as f64 + 0.5,
                );
                *out |=
                    edge_math::segment_distance(clip[i], clip[(i + 1) % 3], pixel, extent) < radius;
            }
        }
    }
    near
}

/// Suzanne's offset from Spot in [`spot_beside_suzanne`] where their placed bounds meet but
/// not their surfaces, and where she passes through the cow.
pub const SIDE_BY_SIDE: f64 = 0.8;
pub const THROUGH: f64 = 0.5;

/// Spot, and Suzanne `shift` to its side, halved and turned 0.8 rad about the vertical so
/// that their placed bounds reach across each other: two instances of two meshes, polygon
/// edges.
pub fn spot_beside_suzanne(shift: f64) -> World {
    use glam::{DMat4, DVec3};
    use wirepass::world::{Object, WorldMesh};
    let centred = |m: &Mesh| {
        let (lo, hi) = m.bounds_f64();
        DMat4::from_translation(-0.5 * (lo + hi))
    };
    let (spot, suzanne) = (load("spot.obj"), load("suzanne.obj"));
    let objects = vec![
        Object::new(0, centred(&spot)),
        Object::new(
            1,
            DMat4::from_translation(DVec3::new(shift, 0.1, 0.0))
                * DMat4::from_rotation_y(0.8)
                * DMat4::from_scale(DVec3::splat(0.5))
                * centred(&suzanne),
        ),
    ];
    let mesh = |mesh: Mesh, name: &str| WorldMesh {
        mesh: std::sync::Arc::new(mesh),
        edges: EdgeSelection::Polygon,
        name: name.into(),
    };
    World {
        meshes: vec![mesh(spot, "spot"), mesh(suzanne, "suzanne")],
        objects,
        sections: Vec::new(),
    }
}

/// The Utah teapot (its spout and handle pass through its body) behind a slab (a cube
/// scaled to 3.2 × 1.8 × 0.6, in front of the teapot's upper body), both drawing their
/// outlines and no edges.
pub fn teapot_behind_slab() -> World {
    use glam::{DMat4, DVec3};
    use std::sync::Arc;
    use wirepass::world::{Object, WorldMesh};
    let mesh = |mesh: Mesh, name: &str| WorldMesh {
        mesh: Arc::new(mesh),
        edges: EdgeSelection::Feature(30.0),
        name: name.into(),
    };
    let slab = wirepass::mesh::Procedural::Cube(300).build().unwrap();
    let mut world = World {
        sections: Vec::new(),
        meshes: vec![mesh(load("teapot.obj"), "teapot"), mesh(slab, "slab")],
        objects: vec![
            Object::new(0, DMat4::IDENTITY),
            Object::new(
                1,
                DMat4::from_translation(DVec3::new(0.3, 1.4, 2.2))
                    * DMat4::from_scale(DVec3::new(1.6, 0.9, 0.3)),
            ),
        ],
    };
    for object in &mut world.objects {
        object.style.edges = Some(false);
    }
    world
}
