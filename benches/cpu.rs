//! CPU parts: OBJ loading, edge adjacency, BVH build and the ray-cast ground truth; loading
//! a 2M-triangle mesh as binary STL, binary PLY, OBJ and GLB (with each load's peak heap
//! use, printed once, since criterion only times), and OBJ faces of a million corners.
//! `cargo bench --bench cpu`

use criterion::{criterion_group, criterion_main, Criterion};
use std::alloc::{GlobalAlloc, Layout, System};
use std::fmt::Write as _;
use std::hint::black_box;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;
use wirepass::mesh::{adjacency, load, load_obj};
use wirepass::truth::{draw_raycast, RayCaster};
use wirepass::world::{Shot, World};
use wirepass::{Camera, EdgeSelection, Style};

#[path = "../tests/common/gltf_file.rs"]
mod gltf_file;

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
        b.iter(|| draw_raycast(black_box(&shot)))
    });
    group.finish();
}

/// The system allocator, counting the bytes in use and their peak.
struct Counting;

static IN_USE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(bytes: usize) {
    let now = IN_USE.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        grew(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        grew(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        IN_USE.fetch_sub(layout.size(), Ordering::Relaxed);
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > layout.size() {
            grew(new_size - layout.size());
        } else {
            IN_USE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Loads `path` once and prints the heap it took at its peak and what the mesh keeps.
fn report_memory(label: &str, path: &Path) {
    let before = IN_USE.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    let mesh = load(path).expect("the generated file loads");
    let kept = IN_USE.load(Ordering::Relaxed) - before;
    let peak = PEAK.load(Ordering::Relaxed) - before;
    let file = std::fs::metadata(path).map_or(0, |m| m.len());
    let mb = |b: u64| b as f64 / (1 << 20) as f64;
    eprintln!(
        "{label}: {} triangles, file {:.0} MiB, peak heap {:.0} MiB, mesh {:.0} MiB",
        mesh.triangle_count(),
        mb(file),
        mb(peak as u64),
        mb(kept as u64)
    );
}

/// Writes `mesh` as a binary STL, a binary little-endian PLY, an OBJ and a GLB (u32
/// indices, float positions, no normals) into `dir`.
fn write_formats(mesh: &wirepass::Mesh, dir: &Path) -> [(&'static str, PathBuf); 4] {
    let p = mesh.positions();
    let tris = mesh.triangles();
    let stl = dir.join("mesh.stl");
    let mut out = std::io::BufWriter::new(std::fs::File::create(&stl).unwrap());
    out.write_all(&[0u8; 80]).unwrap();
    out.write_all(&(tris.len() as u32).to_le_bytes()).unwrap();
    for t in tris {
        out.write_all(&[0u8; 12]).unwrap();
        for &v in t {
            for x in p[v as usize].to_array() {
                out.write_all(&x.to_le_bytes()).unwrap();
            }
        }
        out.write_all(&[0, 0]).unwrap();
    }
    out.flush().unwrap();

    let ply = dir.join("mesh.ply");
    let mut out = std::io::BufWriter::new(std::fs::File::create(&ply).unwrap());
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n\
         property float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        p.len(),
        tris.len()
    )
    .unwrap();
    for q in p {
        for x in q.to_array() {
            out.write_all(&x.to_le_bytes()).unwrap();
        }
    }
    for t in tris {
        out.write_all(&[3]).unwrap();
        for &v in t {
            out.write_all(&(v as i32).to_le_bytes()).unwrap();
        }
    }
    out.flush().unwrap();

    let obj = dir.join("mesh.obj");
    let mut out = std::io::BufWriter::new(std::fs::File::create(&obj).unwrap());
    for q in p {
        writeln!(out, "v {} {} {}", q.x, q.y, q.z).unwrap();
    }
    for t in tris {
        writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
    out.flush().unwrap();

    let glb = dir.join("mesh.glb");
    let mut file = gltf_file::GltfFile::new();
    let positions: Vec<[f32; 3]> = p.iter().map(|v| v.to_array()).collect();
    let indices: Vec<u32> = tris.iter().flatten().copied().collect();
    let primitive = file.triangles(&positions, &indices, None);
    let m = file.mesh(vec![primitive]);
    let node = file.node(serde_json::json!({ "mesh": m }));
    file.scene(&[node]);
    std::fs::write(&glb, file.glb()).unwrap();
    [
        ("binary STL", stl),
        ("binary PLY", ply),
        ("OBJ", obj),
        ("GLB", glb),
    ]
}

/// An OBJ of one polygon with the given corners.
fn polygon_obj(path: &Path, corners: impl Iterator<Item = [f64; 2]>) {
    let mut text = String::new();
    let mut n = 0;
    for [x, y] in corners {
        writeln!(text, "v {x:.7} {y:.7} 0").unwrap();
        n += 1;
    }
    text.push('f');
    for i in 1..=n {
        write!(text, " {i}").unwrap();
    }
    text.push('\n');
    std::fs::write(path, text).unwrap();
}

fn loading(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("wirepass-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = wirepass::mesh::sphere(2_000_000).expect("the sphere builds");
    let files = write_formats(&mesh, &dir);
    drop(mesh);
    for (label, path) in &files {
        report_memory(label, path);
    }
    let mut group = c.benchmark_group("load a 2M-triangle sphere");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(20));
    for (label, path) in &files {
        group.bench_function(*label, |b| b.iter(|| load(black_box(path))));
    }
    group.finish();

    let n = 1_000_000;
    let circle = dir.join("circle-1m.obj");
    polygon_obj(
        &circle,
        (0..n).map(|i| {
            let a = i as f64 * std::f64::consts::TAU / n as f64;
            [a.cos(), a.sin()]
        }),
    );
    let n = 200_000;
    let star = dir.join("star-200k.obj");
    polygon_obj(
        &star,
        (0..n).map(|i| {
            let r = if i % 2 == 0 { 1.0 } else { 0.4 };
            let a = i as f64 * std::f64::consts::TAU / n as f64;
            [r * a.cos(), r * a.sin()]
        }),
    );
    let mut group = c.benchmark_group("OBJ with one huge face");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(1));
    group.bench_function("1M-corner circle", |b| b.iter(|| load(black_box(&circle))));
    group.bench_function("200k-corner star", |b| b.iter(|| load(black_box(&star))));
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, cpu, loading);
criterion_main!(benches);
