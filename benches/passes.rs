//! Whole frames of the deferred method and the floor, submitted and waited for: wall-clock
//! time as the CPU sees it (per-pass GPU times come from timestamp queries in
//! `wirepass bench`), and what moving an instance costs: a new instance buffer, never a mesh
//! upload. `cargo bench --bench passes`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;
use wirepass::glam::{DMat4, DVec3};
use wirepass::gpu::{DeferredPass, GpuContext, MeshStore, OutputTarget, PassOptions};
use wirepass::mesh::sphere;
use wirepass::{Camera, EdgeSelection, Instance, Scene, Style};

fn frames(c: &mut Criterion) {
    let ctx = GpuContext::new().expect("a GPU adapter (lavapipe or llvmpipe will do)");
    let device = &ctx.device;
    let size = (640, 360);
    let mut group = c.benchmark_group("deferred frame 640x360");
    group.sample_size(10);
    for triangles in [20_000, 200_000] {
        let mesh = sphere(triangles).expect("a valid sphere");
        let mut store = MeshStore::new(device);
        let id = store
            .insert(device, &ctx.queue, &mesh, EdgeSelection::Polygon)
            .expect("upload");
        let (lo, hi) = mesh.bounds_f64();
        let aspect = f64::from(size.0) / f64::from(size.1);
        let view = Camera::framing(lo, hi, aspect).to_view(aspect);
        let scene = Scene::new(view, vec![Instance::new(id, DMat4::IDENTITY)]);
        let mut pass = DeferredPass::new(device, PassOptions::default()).expect("pipelines");
        let frame = pass
            .prepare(device, &store, &scene, &Style::default(), size)
            .expect("prepare");
        let usage = wgpu::TextureUsages::STORAGE_BINDING;
        let output = wirepass::gpu::texture_2d(
            device,
            "bench output",
            size,
            wgpu::TextureFormat::Rgba8Unorm,
            usage,
        );
        let view = output.create_view(&Default::default());
        for (name, floor) in [("deferred", false), ("floor", true)] {
            group.bench_function(BenchmarkId::new(name, triangles), |b| {
                b.iter(|| {
                    let mut encoder = device.create_command_encoder(&Default::default());
                    let target = if floor {
                        OutputTarget::Floor(&view)
                    } else {
                        OutputTarget::Shaded(&view)
                    };
                    pass.encode(device, &mut encoder, &store, &frame, target)
                        .expect("encode");
                    ctx.queue.submit([encoder.finish()]);
                    ctx.finish().expect("frame");
                })
            });
        }
    }
    group.finish();
}

/// 1000 moves of one instance of a 1 M-triangle mesh, each followed by the `prepare` that
/// makes it take effect: the cost is the frame's uniforms and instance records, whatever
/// the mesh's size.
fn instance_moves(c: &mut Criterion) {
    let ctx = GpuContext::new().expect("a GPU adapter (lavapipe or llvmpipe will do)");
    let device = &ctx.device;
    let mesh = sphere(1_000_000).expect("a valid sphere");
    let mut store = MeshStore::new(device);
    let id = store
        .insert(device, &ctx.queue, &mesh, EdgeSelection::Polygon)
        .expect("upload");
    let (lo, hi) = mesh.bounds_f64();
    let view = Camera::framing(lo * 3.0, hi * 3.0, 1.0).to_view(1.0);
    let mut pass = DeferredPass::new(device, PassOptions::default()).expect("pipelines");
    let style = Style::default();
    let mut group = c.benchmark_group("instance moves, 1 M-triangle mesh");
    group.sample_size(10);
    for instances in [1usize, 1000] {
        let mut list: Vec<Instance> = (0..instances)
            .map(|i| {
                let offset = DVec3::new(i as f64 % 10.0, (i / 10) as f64 % 10.0, 0.0);
                Instance::new(id, DMat4::from_translation(offset))
            })
            .collect();
        group.bench_function(
            BenchmarkId::new("1000 moves of one instance, then prepare", instances),
            |b| {
                b.iter(|| {
                    for k in 0..1000 {
                        let a = k as f64 * 1e-3;
                        list[0].transform = DMat4::from_rotation_y(a);
                        let scene = Scene::borrowed(view, &list);
                        let frame = pass
                            .prepare(device, &store, &scene, &style, (320, 240))
                            .expect("prepare");
                        black_box(frame);
                    }
                    ctx.finish().expect("uploads");
                })
            },
        );
    }
    group.finish();
}

criterion_group!(benches, frames, instance_moves);
criterion_main!(benches);
