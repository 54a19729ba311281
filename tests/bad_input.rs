//! The catalogue of bad mesh files in `tests/data/bad/`: each one is an `Err` from the
//! library that names the file, says what is wrong and, where the format has lines, where;
//! and on the command line it is a non-zero exit with exactly one error line naming the
//! file, never a panic. A 10,000-corner polygon, a valid face, loads quickly.

use std::path::{Path, PathBuf};
use std::process::Command;
use wirepass::mesh::load_obj;

fn bad(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bad")
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
];

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
    for &(name, line, words) in CATALOGUE {
        let path = bad(name);
        let e = match load_obj(&path) {
            Ok(m) => panic!("{name} loaded {} triangles", m.triangle_count()),
            Err(e) => e,
        };
        assert!(
            matches!(e, wirepass::Error::MeshFile { .. }),
            "{name}: {e:?}"
        );
        let msg = e.to_string();
        let at = match line {
            Some(l) => format!("{}:{l}: ", path.display()),
            None => format!("{}: ", path.display()),
        };
        assert!(
            msg.starts_with(&at),
            "{name}: '{msg}' does not start '{at}'"
        );
        for w in words {
            assert!(msg.contains(w), "{name}: '{msg}' lacks '{w}'");
        }
    }
}

#[test]
fn catalogue_files_give_one_cli_error_line_naming_the_file() {
    for &(name, line, _) in CATALOGUE {
        let path = bad(name);
        let (ok, lines, stderr) = render_cli(&path, "32x24");
        assert!(!ok, "{name}: the render succeeded");
        assert_eq!(lines.len(), 1, "{name}: {stderr}");
        let expected = format!("wirepass: error: {}", load_obj(&path).unwrap_err());
        assert_eq!(lines[0], expected, "{name}");
        let at = match line {
            Some(l) => format!("{}:{l}:", path.display()),
            None => format!("{}:", path.display()),
        };
        assert!(lines[0].contains(&at), "{name}: {}", lines[0]);
    }
}

#[test]
fn missing_files_and_directories_are_one_clear_line() {
    let dir = temp_dir();
    let missing = dir.join("no-such-mesh.obj");
    let e = load_obj(&missing).unwrap_err();
    assert!(matches!(e, wirepass::Error::Io { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(
        msg.starts_with(&format!("{}: ", missing.display())),
        "{msg}"
    );

    let folder = dir.join("a-folder.obj");
    std::fs::create_dir_all(&folder).unwrap();
    let msg = load_obj(&folder).unwrap_err().to_string();
    assert!(
        msg.starts_with(&format!("{}: ", folder.display())) && msg.contains("is a directory"),
        "{msg}"
    );

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
