//! Wavefront OBJ loading. Every object and group of a file becomes part of one mesh, and
//! polygons are triangulated here (not by tobj, whose fan breaks concave faces) so that the
//! diagonals the triangulation adds can be left out of the polygon edge mask.

use super::read::{build, file_error, io_error, open};
use crate::error::Result;
use crate::mesh::polygon::{polygon_edges, triangulate};
use crate::mesh::Mesh;
use glam::Vec3;
use std::io::Read;
use std::path::Path;

/// Loads an OBJ file as one mesh: all objects and groups merged in file order, polygons
/// ear-clipped, normals taken from the file when every vertex has one (otherwise smooth
/// normals are computed). Lines, points, materials and texture coordinates are ignored.
pub fn load_obj(path: &Path) -> Result<Mesh> {
    let (mut file, len) = open(path, "an OBJ")?;
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    file.read_to_end(&mut bytes)
        .map_err(|e| io_error(path, e))?;
    parse_obj(path, &bytes)
}

/// [`load_obj`] from the bytes of a file (a browser's files come as bytes); `name` names
/// the file in errors, which are the same as from a file.
pub fn load_obj_bytes(name: &Path, bytes: &[u8]) -> Result<Mesh> {
    parse_obj(name, bytes)
}

/// Parses the bytes of an OBJ file; `path` only names the file in errors.
fn parse_obj(path: &Path, bytes: &[u8]) -> Result<Mesh> {
    let fail = |line, message| file_error(path, line, message);
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let ok = &bytes[..e.valid_up_to()];
        let line = ok.iter().filter(|&&b| b == b'\n').count() + 1;
        fail(Some(line), "not a text OBJ file: invalid UTF-8".into())
    })?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let text = prescan(text).map_err(|(line, message)| fail(line, message))?;

    // The update covers tobj's optional `merge_identical_points` and `reorder_data`.
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // `prescan` removed `mtllib`, so the material loader is never called.
    let (models, _materials) = tobj::load_obj_buf(&mut text.as_bytes(), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| fail(None, format!("OBJ parse error: {e}")))?;

    let mut positions = Vec::new();
    let mut normals = Some(Vec::new());
    let mut triangles = Vec::new();
    let mut edges = Vec::new();
    let (mut local, mut corners, mut points) = (Vec::new(), Vec::new(), Vec::new());
    let inconsistent = || fail(None, "tobj returned inconsistent face data".into());
    for model in &models {
        let m = &model.mesh;
        let count = m.positions.len() / 3;
        let base = positions.len();
        let global = |i: u32| {
            let i = i as usize;
            (i < count)
                .then(|| u32::try_from(base + i).ok())
                .flatten()
                .ok_or_else(inconsistent)
        };
        let xyz = |c: &[f32]| Vec3::new(c[0], c[1], c[2]);
        positions.extend(m.positions.chunks_exact(3).map(xyz));
        // tobj pushes a normal only for corners that name one, so equal lengths mean all.
        normals = normals
            .filter(|_| m.normals.len() == m.positions.len())
            .map(|mut n| {
                n.extend(m.normals.chunks_exact(3).map(xyz));
                n
            });

        if m.face_arities.is_empty() {
            // All faces are triangles.
            if m.indices.len() % 3 != 0 {
                return Err(inconsistent());
            }
            for t in m.indices.chunks_exact(3) {
                triangles.push([global(t[0])?, global(t[1])?, global(t[2])?]);
                edges.push(crate::mesh::ALL_EDGES);
            }
            continue;
        }
        let mut start = 0;
        for &arity in &m.face_arities {
            let end = start + arity as usize;
            let face = m.indices.get(start..end).ok_or_else(inconsistent)?;
            start = end;
            corners.clear();
            for &i in face {
                corners.push(global(i)?);
            }
            points.clear();
            points.extend(corners.iter().map(|&v| positions[v as usize]));
            local.clear();
            triangulate(&points, &mut local);
            for &t in &local {
                triangles.push(t.map(|k| corners[k]));
                edges.push(polygon_edges(t, face.len()));
            }
        }
    }
    build(path, positions, normals, triangles, Some(edges))
}

/// The three kinds of face index, singular and plural, in the order of `v/vt/vn`.
const KINDS: [(&str, &str); 3] = [
    ("vertex", "vertices"),
    ("texture coordinate", "texture coordinates"),
    ("normal", "normals"),
];

/// Checks every line that tobj would accept silently or reject without a line number, and
/// returns the text for tobj with what wirepass does not use removed, keeping line numbers:
/// lines (tobj would turn `l` with three points into a triangle), materials, vertex colours
/// (tobj fails on a file that colours only some vertices) and texture coordinates (so that
/// UV seams do not split vertices and their smooth normals).
fn prescan(text: &str) -> std::result::Result<String, (Option<usize>, String)> {
    let mut counts = [0usize; 3];
    let mut faces = 0usize;
    let mut out = String::with_capacity(text.len());
    for (i, line) in text.lines().enumerate() {
        let at = |message: String| (Some(i + 1), message);
        if line.contains('\0') {
            return Err(at("not a text OBJ file: contains NUL bytes".into()));
        }
        let mut words = line.split_whitespace();
        let keyword = words.next();
        let args: Vec<&str> = words.collect();
        match keyword {
            Some("v") => {
                let xyz = vertex(&args).map_err(at)?;
                counts[0] += 1;
                if args.len() == 6 {
                    // Drop the colour, which wirepass does not use.
                    out.push_str(&format!("v {} {} {}\n", xyz.x, xyz.y, xyz.z));
                    continue;
                }
            }
            Some("vt") => {
                numbers(&args, 2, "texture coordinate").map_err(at)?;
                counts[1] += 1;
                out.push('\n');
                continue;
            }
            Some("vn") => {
                let n = numbers(&args, 3, "normal").map_err(at)?;
                if let Some(x) = n.iter().find(|x| !x.is_finite()) {
                    return Err(at(format!("normal component {x} is not finite")));
                }
                counts[2] += 1;
            }
            Some("f") => {
                face(&args, counts).map_err(at)?;
                faces += 1;
                if line.contains('/') {
                    // `v/vt/vn` → `v//vn`, `v/vt` → `v`.
                    out.push('f');
                    for corner in &args {
                        let mut parts = corner.split('/');
                        out.push(' ');
                        out.push_str(parts.next().unwrap_or_default());
                        if let Some(vn) = parts.nth(1).filter(|vn| !vn.is_empty()) {
                            out.push_str("//");
                            out.push_str(vn);
                        }
                    }
                    out.push('\n');
                    continue;
                }
            }
            Some("l" | "p" | "mtllib" | "usemtl") => {
                out.push('\n');
                continue;
            }
            _ => {}
        }
        out.push_str(line);
        out.push('\n');
    }
    if faces == 0 {
        let what = if counts[0] == 0 {
            "no vertices and "
        } else {
            ""
        };
        return Err((None, format!("{what}no faces: nothing to draw")));
    }
    Ok(out)
}

/// Parses the first `n` arguments as numbers (tobj reads `f32`).
fn numbers(args: &[&str], n: usize, what: &str) -> std::result::Result<Vec<f32>, String> {
    if args.len() < n {
        return Err(format!("{what} has {} values, needs {n}", args.len()));
    }
    args[..n]
        .iter()
        .map(|a| {
            a.parse::<f32>()
                .map_err(|_| format!("{what} value '{a}' is not a number"))
        })
        .collect()
}

/// Checks a `v` line: `x y z`, `x y z w` or `x y z r g b`, giving a finite position.
fn vertex(args: &[&str]) -> std::result::Result<Vec3, String> {
    let c = numbers(args, 3, "vertex")?;
    let mut p = Vec3::new(c[0], c[1], c[2]);
    match args.len() {
        3 | 6 => {}
        4 => {
            let w = numbers(&args[3..], 1, "vertex")?[0];
            if w == 0.0 || !w.is_finite() {
                return Err(format!("vertex weight w = {w} must be finite and non-zero"));
            }
            p /= w;
        }
        n => {
            return Err(format!(
                "vertex has {n} values; expected x y z, x y z w or x y z r g b"
            ))
        }
    }
    if args.len() == 6 {
        numbers(&args[3..], 3, "vertex colour")?;
    }
    match p.to_array().iter().find(|x| !x.is_finite()) {
        Some(x) => Err(format!("vertex coordinate {x} is not finite")),
        None => Ok(p),
    }
}

/// Checks an `f` line against the counts of `v`, `vt` and `vn` defined before it: OBJ
/// indices are 1-based, and negative ones count back from the last element defined.
fn face(args: &[&str], counts: [usize; 3]) -> std::result::Result<(), String> {
    if args.len() < 3 {
        return Err(format!(
            "face has {} vertices; a face needs at least 3",
            args.len()
        ));
    }
    for corner in args {
        for (k, part) in corner.split('/').enumerate() {
            let Some(&(one, many)) = KINDS.get(k) else {
                return Err(format!("face corner '{corner}' has more than v/vt/vn"));
            };
            if part.is_empty() {
                if k == 0 {
                    return Err(format!("face corner '{corner}' has no vertex index"));
                }
                continue;
            }
            let index: i64 = part
                .parse()
                .map_err(|_| format!("face index '{part}' is not an integer"))?;
            let n = counts[k];
            if index == 0 {
                return Err(format!(
                    "face refers to {one} 0, but OBJ indices start at 1"
                ));
            }
            if index.unsigned_abs() > n as u64 {
                let how = if index < 0 { " (counting back)" } else { "" };
                return Err(format!(
                    "face refers to {one} {index}{how} but only {n} {many} are defined"
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{EdgeSelection, ALL_EDGES};
    use std::path::PathBuf;

    fn test_mesh(name: &str) -> PathBuf {
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/meshes")).join(name)
    }

    /// Writes `bytes` to a fresh temporary file, loads it, and removes the file.
    fn load_bytes(bytes: &[u8]) -> Result<Mesh> {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let path =
            std::env::temp_dir().join(format!("wirepass-obj-test-{}-{n}.obj", std::process::id()));
        std::fs::write(&path, bytes).unwrap();
        let result = load_obj(&path);
        std::fs::remove_file(&path).unwrap();
        result
    }

    fn error_of(text: &str) -> String {
        match load_bytes(text.as_bytes()) {
            Ok(m) => panic!("{text:?} loaded {} triangles", m.triangle_count()),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn suzanne_quads_have_one_masked_diagonal() {
        // 468 quads × 2 + 32 triangles (the README's 936 counts the quads' triangles only).
        let m = load_obj(&test_mesh("suzanne.obj")).unwrap();
        assert_eq!(m.triangle_count(), 968);
        let mask = m.edge_mask(EdgeSelection::Polygon);
        let cleared: u32 = mask.iter().map(|m| 3 - m.count_ones()).sum();
        assert_eq!(
            cleared,
            2 * 468,
            "each quad diagonal is cleared in both its triangles"
        );
        assert_eq!(mask.iter().filter(|&&m| m == ALL_EDGES).count(), 32);
        assert!(mask.iter().all(|m| m.count_ones() >= 2));
        // suzanne has `vn` for every vertex: the file's normals are used.
        assert!(m.normals().iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
    }

    #[test]
    fn test_meshes_load_with_their_triangle_counts() {
        for (name, count) in [
            ("teapot.obj", 6320),
            ("spot.obj", 5856),
            ("suzanne.obj", 968),
            ("fandisk.obj", 12946),
            ("stanford-bunny.obj", 69451),
        ] {
            let m = load_obj(&test_mesh(name)).unwrap();
            assert_eq!(m.triangle_count(), count, "{name}");
            if name == "spot.obj" {
                // Texture coordinates are dropped, so UV seams do not split vertices.
                assert_eq!(m.positions().len(), 2930);
            }
        }
    }

    #[test]
    fn objects_and_groups_merge_in_file_order() {
        let text = "o a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n\
                    g b\nv 0 0 1\nv 1 0 1\nv 0 1 1\nl 5 6 7\nf -3 -2 -1\n";
        let m = load_bytes(text.as_bytes()).unwrap();
        assert_eq!(m.triangle_count(), 3);
        assert_eq!(m.positions().len(), 7);
        assert_eq!(m.positions()[m.triangles()[2][0] as usize], Vec3::Z);
        let mask = m.edge_mask(EdgeSelection::Polygon);
        assert_eq!(mask[0].count_ones() + mask[1].count_ones(), 4);
        assert_eq!(mask[2], ALL_EDGES);
    }

    #[test]
    fn concave_face_in_a_file_keeps_its_outline() {
        let text = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n\
                    vn 0 0 1\nf 1//1 2//1 3//1 4//1 5//1 6//1\n";
        let m = load_bytes(text.as_bytes()).unwrap();
        assert_eq!(m.triangle_count(), 4);
        let marked: u32 = m
            .edge_mask(EdgeSelection::Polygon)
            .iter()
            .map(|m| m.count_ones())
            .sum();
        assert_eq!(marked, 6);
        for t in m.triangles() {
            let p = t.map(|v| m.positions()[v as usize]);
            assert!((p[1] - p[0]).cross(p[2] - p[0]).z > 0.0, "winding kept");
        }
        assert!(m.normals().iter().all(|&n| n == Vec3::Z));
    }

    #[test]
    fn common_variants_are_accepted() {
        // A byte-order mark, CRLF, a vertex colour, a weight, texture coordinates, a material.
        let text = "\u{feff}mtllib none.mtl\r\nv 0 0 0 1 0 0\r\nv 2 0 0 2\r\nv 0 1 0\r\n\
                    vt 0 0\r\nusemtl x\r\nf 1/1 2/1 3/1\r\n";
        let m = load_bytes(text.as_bytes()).unwrap();
        assert_eq!(m.positions()[1], Vec3::X);
    }

    #[test]
    fn bad_files_are_reported_with_their_line() {
        let cases: &[(&str, &[&str])] = &[
            ("", &["no faces"]),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", &["no faces"]),
            ("# nothing\n", &["no faces"]),
            ("v 0 0 0\nv 1 0 0\nf 1 2\n", &[":3:", "at least 3"]),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", &[":4:", "vertex 0"]),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 120\n",
                &[":5:", "vertex 120 but only 3 vertices are defined"],
            ),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", &[":4:", "-4"]),
            (
                "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n",
                &[":1:", "only 0 vertices"],
            ),
            (
                "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n",
                &[":2:", "not finite"],
            ),
            (
                "v 0 0 0\nv 1 inf 0\nv 0 1 0\nf 1 2 3\n",
                &[":2:", "not finite"],
            ),
            (
                "v 0 0 0\nv 1 0 1e39\nv 0 1 0\nf 1 2 3\n",
                &[":2:", "not finite"],
            ),
            (
                "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n",
                &[":2:", "'x' is not a number"],
            ),
            ("v 0 0\n", &[":1:", "needs 3"]),
            ("v 0 0 0 0\n", &[":1:", "w = 0"]),
            ("v 0 0 0 1 1\n", &[":1:", "5 values"]),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n",
                &[":4:", "texture coordinate 1"],
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n",
                &[":5:", "normal 2"],
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1 2 3/1/1/1\n",
                &[":6:", "more than"],
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3x\n",
                &[":4:", "not an integer"],
            ),
            ("v 0 0 0\nvn 0 nan 1\n", &[":2:", "not finite"]),
        ];
        for (text, wanted) in cases {
            let e = error_of(text);
            for w in *wanted {
                assert!(e.contains(w), "{text:?}: '{e}' lacks '{w}'");
            }
            assert!(
                e.contains("wirepass-obj-test-"),
                "the message names the file: {e}"
            );
        }
    }

    #[test]
    fn binary_garbage_is_not_an_obj_file() {
        let e = load_bytes(&[b'v', b' ', b'1', b'\n', 0xff, 0xfe, 0x00, 0x9c, 0x12])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(":2:") && e.contains("not a text OBJ file"),
            "{e}"
        );
        let e = load_bytes(b"v 0 0 0\n\0\0\0\x01\x02")
            .unwrap_err()
            .to_string();
        assert!(e.contains(":2:") && e.contains("NUL"), "{e}");
    }

    #[test]
    fn missing_files_and_directories_are_io_errors() {
        let missing = std::env::temp_dir().join("wirepass-no-such-file-4711.obj");
        let e = load_obj(&missing).unwrap_err();
        assert!(matches!(e, crate::Error::Io { .. }), "{e:?}");
        assert!(e.to_string().contains("wirepass-no-such-file-4711.obj"));
        let e = load_obj(&std::env::temp_dir()).unwrap_err();
        assert!(e.to_string().contains("is a directory"), "{e}");
    }

    #[test]
    fn mutated_files_never_panic() {
        let base = std::fs::read(test_mesh("suzanne.obj")).unwrap();
        let base = &base[..base.len().min(6000)];
        let alphabet = b"vfnlto/-0123456789.e \n#\0\xff";
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut rand = |n: usize| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n as u64) as usize
        };
        for _ in 0..300 {
            let mut bytes = base.to_vec();
            for _ in 0..1 + rand(8) {
                let at = rand(bytes.len());
                match rand(3) {
                    0 => bytes[at] = alphabet[rand(alphabet.len())],
                    1 => {
                        bytes.remove(at);
                    }
                    _ => bytes.insert(at, alphabet[rand(alphabet.len())]),
                }
            }
            let _ = parse_obj(Path::new("mutated.obj"), &bytes);
        }
    }
}
