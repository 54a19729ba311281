//! The catalogue of bad mesh files in `tests/data/bad/` (OBJ, STL, PLY, glTF and an
//! unknown extension), and binary ones written here (STL, PLY, GLB): each one is an `Err` from
//! `wirepass::mesh::load` that names the file, says what is wrong and where (the line in
//! text formats, the byte offset in binary ones); and on the command line it is a non-zero
//! exit with exactly one error line naming the file, never a panic. Headers that declare
//! billions of elements over a few bytes fail at once, without reserving for them. A
//! 10,000-corner polygon, a valid face, loads quickly.

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use wirepass::mesh::{load, load_obj};

#[path = "../../tests/common/gltf_file.rs"]
mod gltf_file;

/// The system allocator, recording the largest single request: a loader that reserves for
/// a count that a header declares shows up here long before it runs out of memory.
struct Recording;

static LARGEST: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Recording {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Recording = Recording;

fn bad(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/bad")
        .join(name)
}

fn temp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("wirepass-bad-input-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Each file, the line the error points at (None where the problem is the whole file), and
/// words the message must contain.
const CATALOGUE: &[(&str, Option<usize>, &[&str])] = &[
    ("empty.obj", None, &["no vertices and no faces"]),
    ("binary_garbage.obj", Some(2), &["not a text OBJ file"]),
    (
        "truncated_vertex.obj",
        Some(5),
        &["vertex has 2 values, needs 3"],
    ),
    (
        "truncated_face.obj",
        Some(6),
        &["face has 2 vertices", "at least 3"],
    ),
    (
        "two_vertex_face.obj",
        Some(5),
        &["face has 2 vertices", "at least 3"],
    ),
    ("zero_index.obj", Some(4), &["vertex 0", "start at 1"]),
    (
        "out_of_range_index.obj",
        Some(5),
        &["vertex 40 but only 3 vertices are defined"],
    ),
    (
        "negative_index.obj",
        Some(4),
        &["vertex -4 (counting back) but only 3"],
    ),
    ("nan_coordinate.obj", Some(2), &["NaN", "not finite"]),
    ("infinite_coordinate.obj", Some(3), &["inf", "not finite"]),
    ("overflowing_coordinate.obj", Some(4), &["not finite"]),
    ("vertices_no_faces.obj", None, &["no faces"]),
    ("empty.stl", None, &["empty file", "not an STL file"]),
    (
        "malformed_facet.stl",
        Some(12),
        &["facet 2", "expected 'vertex X Y Z', found 'vertex 1 0'"],
    ),
    (
        "nan_coordinate.stl",
        Some(5),
        &["facet 1", "vertex coordinate 'nan' is not finite"],
    ),
    ("empty.ply", None, &["empty file", "not a PLY file"]),
    (
        "out_of_range_index.ply",
        Some(14),
        &["face 2", "vertex index 7, but there are only 3 vertices"],
    ),
    (
        "unknown_property_type.ply",
        Some(5),
        &["unknown property type 'int128'"],
    ),
    (
        "huge_vertex_count.ply",
        None,
        &[
            "declares 4000000000 vertex elements",
            "only 26 bytes follow",
        ],
    ),
    ("no_faces.ply", None, &["no face element", "no faces"]),
    (
        "infinite_coordinate.ply",
        Some(11),
        &["vertex 2", "y = inf is not finite"],
    ),
    (
        "unknown_extension.xyz",
        None,
        &[
            "unknown mesh file extension '.xyz'",
            ".obj, .stl, .ply, .gltf, .glb",
        ],
    ),
    ("empty.gltf", None, &["empty file, not a glTF file"]),
    ("empty.glb", None, &["empty file, not a glTF file"]),
    (
        "invalid_json.gltf",
        None,
        &["not glTF JSON", "EOF while parsing", "line 5"],
    ),
    (
        "accessor_past_buffer.gltf",
        None,
        &[
            "mesh 0, primitive 0: accessor 0: 4 elements of 12 bytes",
            "run past the 36 bytes of buffer view 0",
        ],
    ),
    (
        "huge_accessor_count.gltf",
        None,
        &["accessor 0: 4000000000 elements", "run past the 36 bytes"],
    ),
    (
        "missing_buffer.gltf",
        None,
        &["buffer 0: cannot read", "missing.bin", "No such file"],
    ),
    (
        "out_of_range_index.gltf",
        None,
        &["index 2 refers to vertex 7, but the primitive has 3 vertices"],
    ),
    (
        "missing_accessor.gltf",
        None,
        &["invalid glTF: meshes[0].primitives[0].attributes: accessor 5 does not exist"],
    ),
    (
        "nan_position.gltf",
        None,
        &["mesh 0: vertex 1 has a non-finite coordinate"],
    ),
];

/// A valid GLB of one triangle, to break.
fn glb() -> Vec<u8> {
    let mut file = gltf_file::GltfFile::new();
    let prim = file.triangles(
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[0, 1, 2],
        None,
    );
    let m = file.mesh(vec![prim]);
    let n = file.node(serde_json::json!({"mesh": m}));
    file.scene(&[n]);
    file.glb()
}

/// A binary STL: an 80-byte header, the declared `count`, then `triangles`.
fn binary_stl(count: u32, triangles: &[[f32; 9]]) -> Vec<u8> {
    let mut bytes = b"solid looks like text, but is binary".to_vec();
    bytes.resize(80, b' ');
    bytes.extend(count.to_le_bytes());
    for t in triangles {
        bytes.extend([0u8; 12]);
        for x in t {
            bytes.extend(x.to_le_bytes());
        }
        bytes.extend([0, 0]);
    }
    bytes
}

/// A binary little-endian PLY header for `vertices` float vertices and `faces` faces.
fn ply_header(vertices: u64, faces: u64) -> Vec<u8> {
    format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {vertices}\nproperty float x\n\
         property float y\nproperty float z\nelement face {faces}\n\
         property list uchar uint vertex_indices\nend_header\n"
    )
    .into_bytes()
}

/// Binary bad files, written here rather than kept in the repository: each one's bytes, the
/// line of its error (None: binary files have none), and words its message must contain.
fn binary_cases() -> Vec<(PathBuf, Option<usize>, Vec<String>)> {
    let tri = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let mut nan = tri;
    nan[7] = f32::NAN;
    let mut ply_nan = ply_header(3, 1);
    let data_start = ply_nan.len();
    for v in [[0.0, 0.0, 0.0], [1.0, f32::INFINITY, 0.0], [0.0, 1.0, 0.0]] {
        for x in v {
            ply_nan.extend(x.to_le_bytes());
        }
    }
    ply_nan.push(3);
    for i in [0u32, 1, 2] {
        ply_nan.extend(i.to_le_bytes());
    }
    let mut ply_huge = ply_header(4_000_000_000, 1);
    ply_huge.extend([0u8; 40]);
    let valid_glb = glb();
    let word = |bytes: &mut Vec<u8>, at: usize, w: u32| {
        bytes[at..at + 4].copy_from_slice(&w.to_le_bytes());
    };
    let mut short_header = valid_glb.clone();
    word(&mut short_header, 8, 8);
    let mut version_1 = valid_glb.clone();
    word(&mut version_1, 4, 1);
    let mut long_chunk = valid_glb.clone();
    word(&mut long_chunk, 12, 1 << 30);
    let cases: Vec<(&str, Vec<u8>, Vec<String>)> = vec![
        (
            "truncated.stl",
            binary_stl(1000, &[tri]),
            vec![
                "binary STL header declares 1000 triangles, 50084 bytes".into(),
                "the file has 134 bytes (truncated)".into(),
            ],
        ),
        (
            "huge_count.stl",
            binary_stl(u32::MAX, &[tri, tri]),
            vec!["declares 4294967295 triangles".into(), "truncated".into()],
        ),
        (
            "nan_coordinate.stl",
            binary_stl(2, &[tri, nan]),
            vec![
                // Triangle 2 at 134, its corners from 146, the third's y at 146 + 24 + 4.
                "at byte 174: triangle 2 of 2 has coordinate y = NaN, which is not finite".into(),
            ],
        ),
        (
            "infinite_coordinate.ply",
            ply_nan,
            vec![format!(
                "at byte {}: vertex 2: y = inf is not finite",
                data_start + 12
            )],
        ),
        (
            "huge_vertex_count.ply",
            ply_huge,
            vec![
                "declares 4000000000 vertex elements, at least 48000000000 bytes".into(),
                "only 40 bytes follow".into(),
            ],
        ),
        (
            "truncated.glb",
            valid_glb[..valid_glb.len() / 2].to_vec(),
            vec![format!(
                "the GLB header declares {} bytes, but the file has {} (truncated)",
                valid_glb.len(),
                valid_glb.len() / 2
            )],
        ),
        (
            "short_header.glb",
            short_header,
            vec!["the GLB header declares 8 bytes, too few for a JSON chunk".into()],
        ),
        (
            "version_1.glb",
            version_1,
            vec!["GLB version 1; wirepass reads glTF 2.0".into()],
        ),
        (
            "long_json_chunk.glb",
            long_chunk,
            vec!["not a valid GLB file".into(), "JSON chunk length".into()],
        ),
        (
            "tiny.glb",
            b"glTF\x02\0".to_vec(),
            vec!["shorter than its 12-byte header".into()],
        ),
    ];
    let dir = temp_dir().join("binary");
    std::fs::create_dir_all(&dir).unwrap();
    cases
        .into_iter()
        .map(|(name, bytes, words)| {
            let path = dir.join(name);
            std::fs::write(&path, bytes).unwrap();
            (path, None, words)
        })
        .collect()
}

/// Every bad file: the catalogue's and the binary ones.
fn all_cases() -> Vec<(PathBuf, Option<usize>, Vec<String>)> {
    CATALOGUE
        .iter()
        .map(|&(name, line, words)| {
            (
                bad(name),
                line,
                words.iter().map(|w| w.to_string()).collect(),
            )
        })
        .chain(binary_cases())
        .collect()
}

/// Runs `wirepass render FILE -o out.png`; returns success and the program's own error lines
/// (drivers may print notices of their own, which are ignored).
fn render_cli(mesh: &Path, size: &str) -> (bool, Vec<String>, String) {
    let out = temp_dir().join("out.png");
    let output = Command::new(env!("CARGO_BIN_EXE_wirepass"))
        .args(["render", "--size", size, "-o"])
        .arg(&out)
        .arg(mesh)
        .output()
        .expect("the wirepass binary runs");
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(
        !stderr.contains("panicked"),
        "{}: panic: {stderr}",
        mesh.display()
    );
    let lines = stderr
        .lines()
        .filter(|l| l.starts_with("wirepass: error:"))
        .map(str::to_owned)
        .collect();
    (output.status.success(), lines, stderr)
}

#[test]
fn catalogue_files_are_errors_that_name_file_line_and_problem() {
    let listed: Vec<_> = std::fs::read_dir(bad(""))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    for name in &listed {
        assert!(
            CATALOGUE.iter().any(|(n, ..)| n == name),
            "tests/data/bad/{name} is not in the catalogue"
        );
    }
    for (path, line, words) in all_cases() {
        let name = path.display();
        let e = match load(&path) {
            Ok(m) => panic!("{name} loaded {} triangles", m.triangle_count()),
            Err(e) => e,
        };
        assert!(
            matches!(e, wirepass::Error::MeshFile { .. }),
            "{name}: {e:?}"
        );
        let msg = e.to_string();
        assert!(!msg.contains('\n'), "{name}: '{msg}' is more than one line");
        let at = match line {
            Some(l) => format!("{name}:{l}: "),
            None => format!("{name}: "),
        };
        assert!(
            msg.starts_with(&at),
            "{name}: '{msg}' does not start '{at}'"
        );
        for w in &words {
            assert!(msg.contains(w.as_str()), "{name}: '{msg}' lacks '{w}'");
        }
    }
}

#[test]
fn catalogue_files_give_one_cli_error_line_naming_the_file() {
    for (path, line, _) in all_cases() {
        let name = path.display();
        let (ok, lines, stderr) = render_cli(&path, "32x24");
        assert!(!ok, "{name}: the render succeeded");
        assert_eq!(lines.len(), 1, "{name}: {stderr}");
        let expected = format!("wirepass: error: {}", load(&path).unwrap_err());
        assert_eq!(lines[0], expected, "{name}");
        let at = match line {
            Some(l) => format!("{name}:{l}:"),
            None => format!("{name}:"),
        };
        assert!(lines[0].contains(&at), "{name}: {}", lines[0]);
    }
}

/// Headers that declare billions of vertices or triangles over a few bytes: each load
/// fails at once, and no allocation along the way comes near the declared size.
#[test]
fn huge_declared_counts_fail_fast_without_reserving_them() {
    let huge: Vec<PathBuf> = all_cases()
        .into_iter()
        .map(|(path, ..)| path)
        .filter(|p| p.to_string_lossy().contains("huge"))
        .collect();
    assert_eq!(huge.len(), 4);
    for path in huge {
        LARGEST.store(0, Ordering::Relaxed);
        let start = std::time::Instant::now();
        assert!(load(&path).is_err(), "{}", path.display());
        let took = start.elapsed();
        let largest = LARGEST.load(Ordering::Relaxed);
        assert!(took.as_secs_f64() < 1.0, "{}: {took:?}", path.display());
        // Other tests run alongside, but none of theirs comes near this either.
        assert!(
            largest < 16 << 20,
            "{}: an allocation of {largest} bytes",
            path.display()
        );
    }
}

#[test]
fn missing_files_and_directories_are_one_clear_line() {
    let dir = temp_dir();
    let missing = dir.join("no-such-mesh.obj");
    let e = load(&missing).unwrap_err();
    assert!(matches!(e, wirepass::Error::Io { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(
        msg.starts_with(&format!("{}: ", missing.display())),
        "{msg}"
    );

    for (name, what) in [
        ("a-folder.obj", "an OBJ"),
        ("a-folder.stl", "an STL"),
        ("a-folder.ply", "a PLY"),
        ("a-folder.gltf", "a glTF"),
    ] {
        let folder = dir.join(name);
        std::fs::create_dir_all(&folder).unwrap();
        let msg = load(&folder).unwrap_err().to_string();
        let expected = format!("{}: is a directory, not {what} file", folder.display());
        assert_eq!(msg, expected);
    }
    let folder = dir.join("a-folder.obj");

    for (path, what) in [(&missing, "No such file"), (&folder, "is a directory")] {
        let (ok, lines, stderr) = render_cli(path, "32x24");
        assert!(!ok, "{}: the render succeeded", path.display());
        assert_eq!(lines.len(), 1, "{stderr}");
        assert!(
            lines[0].contains(&path.display().to_string()) && lines[0].contains(what),
            "{}",
            lines[0]
        );
    }
}

/// A 10,000-corner convex polygon: a valid face, generated here rather than committed.
fn write_big_polygon(path: &Path, n: usize) {
    use std::fmt::Write;
    let mut text = String::with_capacity(n * 40);
    for i in 0..n {
        let a = i as f64 * std::f64::consts::TAU / n as f64;
        writeln!(text, "v {:.7} {:.7} 0", a.cos(), a.sin()).unwrap();
    }
    text.push('f');
    for i in 1..=n {
        write!(text, " {i}").unwrap();
    }
    text.push('\n');
    std::fs::write(path, text).unwrap();
}

#[test]
fn a_10k_vertex_polygon_loads_quickly_and_renders() {
    let n = 10_000;
    let path = temp_dir().join("polygon-10k.obj");
    write_big_polygon(&path, n);
    let start = std::time::Instant::now();
    let mesh = load_obj(&path).unwrap_or_else(|e| panic!("{e}"));
    let took = start.elapsed();
    assert_eq!(mesh.triangle_count(), n - 2);
    assert_eq!(mesh.positions().len(), n);
    let outline: u32 = mesh
        .edge_mask(wirepass::EdgeSelection::Polygon)
        .iter()
        .map(|m| m.count_ones())
        .sum();
    assert_eq!(outline, n as u32, "only the outline is drawn");
    assert!(took.as_secs_f64() < 5.0, "loading took {took:?}");

    let (ok, lines, stderr) = render_cli(&path, "64x48");
    assert!(ok && lines.is_empty(), "{stderr}");
}
