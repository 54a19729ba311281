//! STL and PLY files load the same mesh as their OBJ twins: meshes are written here in
//! every encoding (binary and ASCII STL; ASCII, binary little and big endian PLY), loaded
//! back through `wirepass::mesh::load`, and compared triangle by triangle. Also: the
//! extension picks the loader, and polygons of a million corners load.

mod common;

use glam::Vec3;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use wirepass::mesh::{adjacency, load, load_obj, smooth_normals};
use wirepass::{EdgeSelection, Mesh};

fn temp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("wirepass-formats-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(name: &str, bytes: &[u8]) -> PathBuf {
    let path = temp_dir().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn loaded(path: &Path) -> Mesh {
    load(path).unwrap_or_else(|e| panic!("{e}"))
}

/// The positions of each triangle's corners.
fn corners(mesh: &Mesh) -> Vec<[Vec3; 3]> {
    mesh.triangles()
        .iter()
        .map(|t| t.map(|v| mesh.positions()[v as usize]))
        .collect()
}

/// A binary STL of `mesh`'s triangles, with `header` at the start of its 80 bytes.
fn binary_stl(mesh: &Mesh, header: &[u8]) -> Vec<u8> {
    let mut bytes = vec![0u8; 80];
    bytes[..header.len()].copy_from_slice(header);
    bytes.extend((mesh.triangle_count() as u32).to_le_bytes());
    for [a, b, c] in corners(mesh) {
        let normal = (b - a).cross(c - a).normalize_or_zero();
        for v in [normal, a, b, c] {
            for x in v.to_array() {
                bytes.extend(x.to_le_bytes());
            }
        }
        bytes.extend([0, 0]);
    }
    bytes
}

/// An ASCII STL of `mesh`'s triangles; `name` follows `solid`, and may be empty.
fn ascii_stl(mesh: &Mesh, name: &str) -> Vec<u8> {
    let mut text = if name.is_empty() {
        "solid\n".to_owned()
    } else {
        format!("solid {name}\n")
    };
    for [a, b, c] in corners(mesh) {
        // A zero facet normal, as some writers leave it: the loader ignores it anyway.
        text.push_str("  facet normal 0 0 0\n    outer loop\n");
        for v in [a, b, c] {
            // `{}` on f32 prints the shortest text that reads back to the same value.
            writeln!(text, "      vertex {} {} {}", v.x, v.y, v.z).unwrap();
        }
        text.push_str("    endloop\n  endfacet\n");
    }
    writeln!(text, "endsolid {name}").unwrap();
    text.into_bytes()
}

/// A torus with vertices shared between triangles, so its STL twin welds back to it.
fn torus() -> Mesh {
    wirepass::mesh::torus(800).unwrap()
}

/// Checks that `stl`, loaded from an STL of `original`, is `original` welded: the same
/// corner positions per triangle, the same adjacency, every edge a polygon edge, and
/// smooth normals.
fn check_stl_twin(stl: &Mesh, original: &Mesh) {
    assert_eq!(corners(stl), corners(original));
    let unique = adjacency::weld_by_position(original.positions());
    let distinct = unique
        .iter()
        .enumerate()
        .filter(|&(i, &w)| i == w as usize)
        .count();
    assert_eq!(stl.positions().len(), distinct, "corners are welded");
    assert_eq!(
        stl.edge_neighbours(),
        adjacency::edge_neighbours(original.positions(), original.triangles())
    );
    assert!(stl
        .edge_neighbours()
        .iter()
        .flatten()
        .all(|&n| n != adjacency::NO_NEIGHBOUR));
    assert_eq!(
        stl.edge_mask(EdgeSelection::Polygon),
        vec![wirepass::mesh::ALL_EDGES; stl.triangle_count()]
    );
    assert_eq!(
        stl.normals(),
        smooth_normals(stl.positions(), stl.triangles()).as_slice()
    );
}

#[test]
fn stl_binary_and_ascii_load_the_torus_welded() {
    let torus = torus();
    for (name, bytes) in [
        ("torus.stl", binary_stl(&torus, b"binary torus")),
        // A binary header that starts like ASCII: the size decides.
        (
            "solid-header.stl",
            binary_stl(&torus, b"solid torus, but binary"),
        ),
        ("ascii.stl", ascii_stl(&torus, "torus")),
        ("no-name.STL", ascii_stl(&torus, "")),
        ("no-endsolid.stl", {
            let text = ascii_stl(&torus, "torus");
            text[..text.len() - "endsolid torus\n".len()].to_vec()
        }),
    ] {
        let stl = loaded(&write(name, &bytes));
        check_stl_twin(&stl, &torus);
    }
}

#[test]
fn stl_welds_signed_zeros_and_keeps_degenerate_triangles() {
    let p = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(-0.0, 0.0, -0.0),
        Vec3::new(0.0, -1.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(5.0, 5.0, 5.0),
    ];
    let m = Mesh::new(p, None, vec![[0, 1, 2], [3, 4, 5], [6, 6, 2]], None).unwrap();
    let stl = loaded(&write("zeros.stl", &binary_stl(&m, b"")));
    assert_eq!(stl.positions().len(), 5);
    assert_eq!(stl.triangles(), [[0, 1, 2], [0, 3, 1], [4, 4, 2]]);
    assert_eq!(
        stl.edge_neighbours()[0][0],
        1,
        "the shared edge joins the halves"
    );
}

/// Positions, normals (one `vn` per `v`) and polygons (0-based vertex lists).
type Polygons = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<Vec<u32>>);

/// Suzanne's polygons (468 quads, 32 triangles), read from the OBJ text.
fn suzanne_polygons() -> Polygons {
    let text = std::fs::read_to_string(common::test_mesh("suzanne.obj")).unwrap();
    let (mut v, mut vn, mut f) = (Vec::new(), Vec::new(), Vec::new());
    for line in text.lines() {
        let mut words = line.split_whitespace();
        let numbers = |w: std::str::SplitWhitespace| {
            let n: Vec<f32> = w.map(|x| x.parse().unwrap()).collect();
            [n[0], n[1], n[2]]
        };
        match words.next() {
            Some("v") => v.push(numbers(words)),
            Some("vn") => vn.push(numbers(words)),
            Some("f") => f.push(
                words
                    .map(|c| c.split('/').next().unwrap().parse::<u32>().unwrap() - 1)
                    .collect(),
            ),
            _ => {}
        }
    }
    assert_eq!(v.len(), vn.len());
    (v, vn, f)
}

/// How a test PLY is encoded and laid out.
#[derive(Clone, Copy, Debug)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// A PLY of `positions` and `polygons`. Positions are written as `double` when
/// `doubles`, else `float`; with `normals`, nx ny nz follow; a colour and an `edge`
/// element that the loader must read past are added; the index list is `list COUNT INDEX`
/// of the given types, named `index_name`. `faces_first` puts the faces before the vertices.
struct PlySpec<'a> {
    encoding: Encoding,
    doubles: bool,
    normals: Option<&'a [[f32; 3]]>,
    count_type: &'a str,
    index_type: &'a str,
    index_name: &'a str,
    faces_first: bool,
}

fn ply(spec: &PlySpec, positions: &[[f32; 3]], polygons: &[Vec<u32>]) -> Vec<u8> {
    let format = match spec.encoding {
        Encoding::Ascii => "ascii",
        Encoding::Little => "binary_little_endian",
        Encoding::Big => "binary_big_endian",
    };
    let coord = if spec.doubles { "double" } else { "float" };
    let mut vertex_header = format!("element vertex {}\n", positions.len());
    for axis in ["x", "y", "z"] {
        writeln!(vertex_header, "property {coord} {axis}").unwrap();
    }
    if spec.normals.is_some() {
        vertex_header.push_str("property float nx\nproperty float ny\nproperty float nz\n");
    }
    vertex_header.push_str("property uchar red\n");
    let face_header = format!(
        "element face {}\nproperty list {} {} {}\nproperty float quality\n",
        polygons.len(),
        spec.count_type,
        spec.index_type,
        spec.index_name
    );
    let edge_header = "element edge 2\nproperty int vertex1\nproperty int vertex2\n";
    let (first, second) = if spec.faces_first {
        (&face_header, &vertex_header)
    } else {
        (&vertex_header, &face_header)
    };
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment written by the wirepass tests\n{first}{second}\
         {edge_header}end_header\n"
    )
    .into_bytes();

    // One value of a PLY type, in the file's encoding.
    let put = |out: &mut Vec<u8>, ty: &str, value: f64, last: bool| {
        if let Encoding::Ascii = spec.encoding {
            let text = match ty {
                "float" => format!("{}", value as f32),
                _ => format!("{value}"),
            };
            out.extend(text.as_bytes());
            out.push(if last { b'\n' } else { b' ' });
            return;
        }
        let big = matches!(spec.encoding, Encoding::Big);
        macro_rules! bytes {
            ($v:expr) => {
                if big {
                    out.extend($v.to_be_bytes())
                } else {
                    out.extend($v.to_le_bytes())
                }
            };
        }
        match ty {
            "char" | "int8" => bytes!(value as i8),
            "uchar" | "uint8" => bytes!(value as u8),
            "short" | "int16" => bytes!(value as i16),
            "ushort" | "uint16" => bytes!(value as u16),
            "int" | "int32" => bytes!(value as i32),
            "uint" | "uint32" => bytes!(value as u32),
            "float" | "float32" => bytes!(value as f32),
            "double" | "float64" => bytes!(value),
            _ => panic!("{ty}"),
        }
    };
    let vertices = |out: &mut Vec<u8>| {
        for (i, p) in positions.iter().enumerate() {
            for &x in p {
                put(out, coord, f64::from(x), false);
            }
            if let Some(n) = spec.normals {
                for &x in &n[i] {
                    put(out, "float", f64::from(x), false);
                }
            }
            put(out, "uchar", (i % 256) as f64, true);
        }
    };
    let faces = |out: &mut Vec<u8>| {
        for f in polygons {
            put(out, spec.count_type, f.len() as f64, false);
            for &v in f {
                put(out, spec.index_type, f64::from(v), false);
            }
            put(out, "float", 0.5, true);
        }
    };
    if spec.faces_first {
        faces(&mut out);
        vertices(&mut out);
    } else {
        vertices(&mut out);
        faces(&mut out);
    }
    for e in [[0.0, 1.0], [1.0, 2.0]] {
        put(&mut out, "int", e[0], false);
        put(&mut out, "int", e[1], true);
    }
    out
}

#[test]
fn ply_polygons_load_like_their_obj_twin() {
    let obj = load_obj(&common::test_mesh("suzanne.obj")).unwrap();
    let (positions, normals, polygons) = suzanne_polygons();
    assert_eq!(polygons.iter().filter(|f| f.len() == 4).count(), 468);
    let base = PlySpec {
        encoding: Encoding::Ascii,
        doubles: false,
        normals: None,
        count_type: "uchar",
        index_type: "int",
        index_name: "vertex_indices",
        faces_first: false,
    };
    let specs = [
        PlySpec { ..base },
        PlySpec {
            encoding: Encoding::Little,
            doubles: true,
            normals: Some(&normals),
            index_type: "uint",
            ..base
        },
        PlySpec {
            encoding: Encoding::Big,
            count_type: "int",
            index_type: "ushort",
            index_name: "vertex_index",
            ..base
        },
        PlySpec {
            encoding: Encoding::Little,
            count_type: "uint8",
            index_type: "int32",
            faces_first: true,
            ..base
        },
        PlySpec {
            encoding: Encoding::Ascii,
            normals: Some(&normals),
            faces_first: true,
            ..base
        },
    ];
    for (k, spec) in specs.iter().enumerate() {
        let name = format!("suzanne-{k}-{:?}.ply", spec.encoding);
        let ply_mesh = loaded(&write(&name, &ply(spec, &positions, &polygons)));
        assert_eq!(corners(&ply_mesh), corners(&obj), "{name}");
        assert_eq!(
            ply_mesh.edge_mask(EdgeSelection::Polygon),
            obj.edge_mask(EdgeSelection::Polygon),
            "{name}: polygon edges"
        );
        assert_eq!(ply_mesh.edge_neighbours(), obj.edge_neighbours(), "{name}");
        let normals_of = |m: &Mesh| -> Vec<Vec3> {
            m.triangles()
                .iter()
                .flat_map(|t| t.map(|v| m.normals()[v as usize]))
                .collect()
        };
        if spec.normals.is_some() {
            // The file's normals, as the OBJ's `vn`.
            assert_eq!(normals_of(&ply_mesh), normals_of(&obj), "{name}");
        } else {
            assert_eq!(
                ply_mesh.normals(),
                smooth_normals(ply_mesh.positions(), ply_mesh.triangles()).as_slice()
            );
        }
    }
}

#[test]
fn ply_vertex_types_and_concave_faces() {
    // An L-shaped hexagon with integer (short) coordinates: the ear clipper keeps it inside
    // its outline, and only its six sides are polygon edges.
    let text = "ply\r\nformat ascii 1.0\r\nelement vertex 6\r\nproperty short x\r\n\
                property short y\r\nproperty char z\r\nelement face 1\r\n\
                property list uchar uchar vertex_indices\r\nend_header\r\n\
                0 0 0\r\n2 0 0\r\n2 1 0\r\n1 1 0\r\n1 2 0\r\n0 2 0\r\n6 0 1 2 3 4 5\r\n";
    let m = loaded(&write("l-shape.ply", text.as_bytes()));
    assert_eq!(m.triangle_count(), 4);
    let marked: u32 = m
        .edge_mask(EdgeSelection::Polygon)
        .iter()
        .map(|k| k.count_ones())
        .sum();
    assert_eq!(marked, 6);
    let area: f32 = corners(&m)
        .iter()
        .map(|[a, b, c]| (*b - *a).cross(*c - *a).z / 2.0)
        .sum();
    assert_eq!(area, 3.0);
}

#[test]
fn the_extension_picks_the_loader_in_any_case() {
    let torus = torus();
    let bytes = binary_stl(&torus, b"");
    for name in ["upper.STL", "mixed.Stl"] {
        assert_eq!(
            loaded(&write(name, &bytes)).triangle_count(),
            torus.triangle_count()
        );
    }
    let ply_text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
                    property float y\nproperty float z\nelement face 1\n\
                    property list uchar int vertex_indices\nend_header\n\
                    0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_eq!(
        loaded(&write("tri.PLY", ply_text.as_bytes())).triangle_count(),
        1
    );
    let obj_text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert_eq!(
        loaded(&write("tri.Obj", obj_text.as_bytes())).triangle_count(),
        1
    );

    // The wrong loader for the content is an error, not a mesh.
    let e = load(&write("binary.obj", &bytes)).unwrap_err().to_string();
    assert!(e.contains("binary.obj"), "{e}");
    for (name, words) in [
        (
            "mesh.3ds",
            &["unknown mesh file extension '.3ds'", ".obj, .stl, .ply"][..],
        ),
        ("mesh", &["no file extension", ".obj, .stl, .ply"][..]),
    ] {
        let path = write(name, obj_text.as_bytes());
        let e = load(&path).unwrap_err();
        assert!(
            matches!(e, wirepass::Error::MeshFile { line: None, .. }),
            "{e:?}"
        );
        let e = e.to_string();
        for w in words {
            assert!(e.contains(w), "{name}: '{e}' lacks '{w}'");
        }
    }
    let e = load(&temp_dir().join("missing.3ds")).unwrap_err();
    assert!(matches!(e, wirepass::Error::Io { .. }), "{e:?}");
}

/// An OBJ of one polygon with the given corners.
fn polygon_obj(points: impl Iterator<Item = [f64; 2]>) -> Vec<u8> {
    let mut text = String::new();
    let mut n = 0;
    for [x, y] in points {
        writeln!(text, "v {x:.7} {y:.7} 0").unwrap();
        n += 1;
    }
    text.push('f');
    for i in 1..=n {
        write!(text, " {i}").unwrap();
    }
    text.push('\n');
    text.into_bytes()
}

/// Loads a one-polygon OBJ and checks it: `n - 2` triangles, only the outline marked, and,
/// in the polygon's plane, the triangles' areas adding up to the polygon's, all of one sign
/// (so none lies outside the outline).
fn check_polygon_file(name: &str, bytes: &[u8], n: usize) {
    let path = write(name, bytes);
    let m = loaded(&path);
    std::fs::remove_file(&path).unwrap();
    assert_eq!(m.triangle_count(), n - 2, "{name}");
    let marked: usize = m
        .edge_mask(EdgeSelection::Polygon)
        .iter()
        .map(|k| k.count_ones() as usize)
        .sum();
    assert_eq!(marked, n, "{name}: only the outline is marked");
    let p = m.positions();
    let outline: f64 = (0..n)
        .map(|i| {
            p[i].as_dvec3()
                .truncate()
                .perp_dot(p[(i + 1) % n].as_dvec3().truncate())
        })
        .sum();
    let mut sum = 0.0f64;
    for t in m.triangles() {
        let [a, b, c] = t.map(|v| p[v as usize].as_dvec3());
        let z = (b - a).cross(c - a).z;
        assert!(z * outline >= 0.0, "{name}: triangle {t:?} flips");
        sum += z;
    }
    assert!(
        (sum - outline).abs() <= 1e-9 * outline.abs(),
        "{name}: {sum} != {outline}"
    );
}

/// A million-corner convex polygon and a 200,000-corner star, each one OBJ face. Ear
/// clipping that tests every reflex corner took about a minute for the star; timings are
/// in `benches/cpu.rs`. The bound here only catches a return to quadratic time.
#[test]
fn polygons_of_a_million_corners_load() {
    let start = std::time::Instant::now();
    let n = 1_000_000;
    let circle = (0..n).map(|i| {
        let a = i as f64 * std::f64::consts::TAU / n as f64;
        [a.cos(), a.sin()]
    });
    check_polygon_file("circle-1m.obj", &polygon_obj(circle), n);
    let n = 200_000;
    let star = (0..n).map(|i| {
        let r = if i % 2 == 0 { 1.0 } else { 0.4 };
        let a = i as f64 * std::f64::consts::TAU / n as f64;
        [r * a.cos(), r * a.sin()]
    });
    check_polygon_file("star-200k.obj", &polygon_obj(star), n);
    let teeth = 100_000;
    let comb = (0..teeth)
        .flat_map(|i| [[i as f64, 3.0], [i as f64 + 0.5, 0.5]])
        .chain([[teeth as f64, 3.0], [teeth as f64, 0.0], [0.0, 0.0]]);
    check_polygon_file("comb-200k.obj", &polygon_obj(comb), 2 * teeth + 3);
    assert!(start.elapsed().as_secs() < 300, "{:?}", start.elapsed());
}

/// The STL twin of an OBJ renders pixel for pixel the same: same triangles in the same
/// order, welded the same way, so the same smooth normals.
#[test]
fn stl_and_obj_twins_render_identically() {
    use wirepass::tools::offline::Method;
    let torus = torus();
    // The OBJ has one vertex per distinct position and no normals, like the welded STL.
    let mut obj = String::new();
    for p in torus.positions() {
        writeln!(obj, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    for t in torus.triangles() {
        writeln!(obj, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
    let from_obj = loaded(&write("twin.obj", obj.as_bytes()));
    let from_stl = loaded(&write("twin.stl", &binary_stl(&torus, b"solid twin")));
    assert_eq!(corners(&from_obj), corners(&from_stl));
    let size = (128, 96);
    let camera = common::framing(&from_obj, size);
    let style = wirepass::Style::default();
    let frame = |mesh: &Mesh| {
        common::shoot(
            mesh,
            camera,
            &style,
            size,
            EdgeSelection::All,
            Method::Deferred,
        )
    };
    let (a, b) = (frame(&from_obj), frame(&from_stl));
    assert!(
        a.ids.iter().any(|&id| id != u32::MAX),
        "the torus is in view"
    );
    assert_eq!(a.ids, b.ids);
    assert_eq!(a.rgba, b.rgba);
}
