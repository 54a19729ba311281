//! CPU parts: OBJ loading, edge adjacency, BVH build and the ray-cast ground truth.
//! `cargo bench --bench cpu`

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::PathBuf;
use wirepass::mesh::{adjacency, load_obj};
use wirepass::raycast::{render_raycast, RayCaster};
use wirepass::render::{Shot, World};
use wirepass::{Camera, EdgeSelection, Style};

fn bunny_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes/stanford-bunny.obj")
}

fn cpu(c: &mut Criterion) {
    let path = bunny_path();
    let mesh = load_obj(&path).expect("the test bunny loads");
    let mut group = c.benchmark_group("bunny (69,451 triangles)");
    group.sample_size(10);
    group.bench_function("load_obj", |b| b.iter(|| load_obj(black_box(&path))));
    group.bench_function("edge adjacency", |b| {
        b.iter(|| adjacency::edge_neighbours(black_box(mesh.positions()), mesh.triangles()))
    });
    let world = World::single(mesh.clone(), EdgeSelection::All);
    group.bench_function("BVH build", |b| {
        b.iter(|| RayCaster::new(black_box(&world)))
    });
    let (lo, hi) = mesh.bounds_f64();
    let style = Style::default();
    let shot = Shot {
        world: &world,
        view: Camera::framing(lo, hi, 4.0 / 3.0).to_view(4.0 / 3.0),
        style: &style,
        size: (320, 240),
    };
    group.bench_function("ray cast 320x240", |b| {
        b.iter(|| render_raycast(black_box(&shot)))
    });
    group.finish();
}

criterion_group!(benches, cpu);
criterion_main!(benches);
