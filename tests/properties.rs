//! Property tests (proptest), bounded to a few seconds in debug builds:
//! - random OBJ-ish text never panics the loader, and every mesh it accepts has finite
//!   positions and normals and in-range indices;
//! - random bytes, and random mutations of valid binary and ASCII STL and PLY files (ASCII,
//!   little and big endian) and of glTF files (GLB and base64 JSON, with edge extensions, a
//!   camera and instances), never panic their loaders, and what they accept is as valid;
//! - `edge_math::edge_eval` on random triangles seen by random valid cameras (vertices behind
//!   the eye included) at random pixels never gives a NaN distance, and its barycentrics sum
//!   to 1 whenever the triangle's screen area is not degenerate.
//!
//! CPU/WGSL agreement of the edge math on random triangles is in `tests/edge_math_gpu.rs`.

use glam::{DVec2, Vec3};
use proptest::prelude::*;
use std::path::PathBuf;
use wirepass::{edge_math, Camera};

#[path = "common/gltf_file.rs"]
mod gltf_file;

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 256,
        // Shrinking writes files too; keep a failure's report quick.
        max_shrink_iters: 256,
        // No regression files: the cases are cheap to find again, and the tree stays clean.
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// A number as it might appear in an OBJ file, good or bad.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (-100i32..100).prop_map(|i| i.to_string()),
        4 => (-1e3f32..1e3).prop_map(|f| f.to_string()),
        1 => prop::sample::select(vec![
            "nan", "NaN", "inf", "-inf", "infinity", "1e39", "-1e39", "3.4e38", "1e-45", "-0",
            "0x10", "1,5", "", "x", "1e", ".", "-", "+1",
        ])
        .prop_map(str::to_owned),
        1 => any::<f32>().prop_map(|f| f.to_string()),
    ]
}

/// A face index, good or bad: small positive and negative ones, 0, huge ones, garbage.
fn index() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => (-8i64..12).prop_map(|i| i.to_string()),
        1 => prop::sample::select(vec![
            "0", "99999999999", "-99999999999", "18446744073709551616", "a", "1.5", "", "--1",
        ])
        .prop_map(str::to_owned),
    ]
}

fn corner() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => index(),
        1 => (index(), index()).prop_map(|(v, t)| format!("{v}/{t}")),
        1 => (index(), index()).prop_map(|(v, n)| format!("{v}//{n}")),
        1 => (index(), index(), index()).prop_map(|(v, t, n)| format!("{v}/{t}/{n}")),
    ]
}

fn line() -> impl Strategy<Value = String> {
    prop_oneof![
        8 => prop::collection::vec(number(), 2..7).prop_map(|n| format!("v {}", n.join(" "))),
        2 => prop::collection::vec(number(), 3..4).prop_map(|n| format!("vn {}", n.join(" "))),
        1 => prop::collection::vec(number(), 2..3).prop_map(|n| format!("vt {}", n.join(" "))),
        6 => prop::collection::vec(corner(), 0..7).prop_map(|c| format!("f {}", c.join(" "))),
        1 => prop::collection::vec(index(), 2..4).prop_map(|c| format!("l {}", c.join(" "))),
        1 => prop::sample::select(vec![
            "", "# comment", "o thing", "g group", "s 1", "usemtl m", "mtllib m.mtl", "vp 1 2",
            "\u{feff}", "f", "v", "\0", "\t", "?",
        ])
        .prop_map(str::to_owned),
    ]
}

/// A line that is valid after three vertices: a vertex, a normal or a face using the first
/// three vertices (by positive or negative index).
fn good_line() -> impl Strategy<Value = String> {
    let index = prop_oneof![1i32..4, -3i32..0];
    prop_oneof![
        3 => prop::array::uniform3(-1e3f32..1e3).prop_map(|[x, y, z]| format!("v {x} {y} {z}")),
        1 => prop::array::uniform3(-1f32..1.0).prop_map(|[x, y, z]| format!("vn {x} {y} {z}")),
        4 => prop::collection::vec(index, 3..7).prop_map(|c| {
            let c: Vec<_> = c.iter().map(i32::to_string).collect();
            format!("f {}", c.join(" "))
        }),
    ]
}

/// Three good vertices, then a mix of good lines and lines of any kind, so that a fair share
/// of the files load and the accepted meshes get checked too.
fn obj_text() -> impl Strategy<Value = String> {
    (
        prop::collection::vec(good_line(), 0..4),
        prop::collection::vec(prop_oneof![4 => good_line(), 1 => line()], 0..20),
        prop::sample::select(vec!["\n", "\r\n"]),
    )
        .prop_map(|(head, body, end)| {
            let mut lines = vec!["v 0 0 0".to_owned(), "v 1 0 0".into(), "v 0 1 0".into()];
            lines.extend(head);
            lines.extend(body);
            lines.join(end)
        })
}

fn temp_obj(text: &str) -> PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!("wirepass-prop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{}.obj", NEXT.fetch_add(1, Ordering::Relaxed)));
    std::fs::write(&path, text).unwrap();
    path
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn random_obj_text_never_panics_and_accepted_meshes_are_valid(text in obj_text()) {
        let path = temp_obj(&text);
        let result = wirepass::mesh::load_obj(&path);
        std::fs::remove_file(&path).unwrap();
        match result {
            Ok(mesh) => {
                let n = mesh.positions().len();
                prop_assert!(mesh.triangle_count() > 0);
                prop_assert!(mesh.positions().iter().all(|p| p.is_finite()));
                prop_assert!(mesh.normals().iter().all(|p| p.is_finite()));
                prop_assert_eq!(mesh.normals().len(), n);
                for t in mesh.triangles() {
                    prop_assert!(t.iter().all(|&v| (v as usize) < n), "{:?} of {}", t, n);
                }
            }
            Err(e) => {
                let msg = e.to_string();
                prop_assert!(msg.contains(&path.display().to_string()), "{}", msg);
            }
        }
    }
}

/// Checks a mesh that a loader accepted: triangles, finite positions and normals, indices
/// in range; or that an error names the file.
fn check_loaded(path: &std::path::Path) -> Result<(), TestCaseError> {
    let result = wirepass::mesh::load(path);
    std::fs::remove_file(path).unwrap();
    match result {
        Ok(mesh) => {
            let n = mesh.positions().len();
            prop_assert!(mesh.triangle_count() > 0);
            prop_assert!(mesh.positions().iter().all(|p| p.is_finite()));
            prop_assert!(mesh.normals().iter().all(|p| p.is_finite()));
            prop_assert_eq!(mesh.normals().len(), n);
            for t in mesh.triangles() {
                prop_assert!(t.iter().all(|&v| (v as usize) < n), "{:?} of {}", t, n);
            }
        }
        Err(e) => {
            let msg = e.to_string();
            prop_assert!(msg.contains(&path.display().to_string()), "{}", msg);
            prop_assert!(!msg.contains('\n'), "{}", msg);
        }
    }
    Ok(())
}

fn temp_file(extension: &str, bytes: &[u8]) -> PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!("wirepass-prop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let path = dir.join(format!("file-{n}.{extension}"));
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Valid files to mutate, with their extensions: a small sphere (quads and triangles) as
/// binary and ASCII STL, and as PLY in all three encodings with quads kept whole.
fn valid_files() -> &'static [(&'static str, Vec<u8>)] {
    static FILES: std::sync::OnceLock<Vec<(&str, Vec<u8>)>> = std::sync::OnceLock::new();
    FILES.get_or_init(|| {
        let mesh = wirepass::mesh::sphere(24).unwrap();
        let p = mesh.positions();
        let tris = mesh.triangles();
        let mut binary = vec![0u8; 80];
        binary.extend((tris.len() as u32).to_le_bytes());
        let mut ascii = "solid sphere\n".to_owned();
        for t in tris {
            binary.extend([0u8; 12]);
            ascii.push_str("facet normal 0 0 1\nouter loop\n");
            for &v in t {
                let q = p[v as usize];
                for x in q.to_array() {
                    binary.extend(x.to_le_bytes());
                }
                ascii.push_str(&format!("vertex {} {} {}\n", q.x, q.y, q.z));
            }
            binary.extend([0, 0]);
            ascii.push_str("endloop\nendfacet\n");
        }
        ascii.push_str("endsolid sphere\n");
        // Faces: the sphere's triangles, the first two joined into a quad.
        let [a, b, c] = tris[0];
        let d = tris[1]
            .into_iter()
            .find(|v| ![a, b, c].contains(v))
            .unwrap();
        let mut faces: Vec<Vec<u32>> = vec![vec![a, b, c, d]];
        faces.extend(tris[2..].iter().map(|t| t.to_vec()));
        let header = |format: &str| {
            format!(
                "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\n\
                 property float y\nproperty float z\nelement face {}\n\
                 property list uchar int vertex_indices\nend_header\n",
                p.len(),
                faces.len()
            )
        };
        let mut ply_ascii = header("ascii");
        for q in p {
            ply_ascii.push_str(&format!("{} {} {}\n", q.x, q.y, q.z));
        }
        for f in &faces {
            let f: Vec<String> = f.iter().map(u32::to_string).collect();
            ply_ascii.push_str(&format!("{} {}\n", f.len(), f.join(" ")));
        }
        let binary_ply = |big: bool| {
            let mut out = header(if big {
                "binary_big_endian"
            } else {
                "binary_little_endian"
            })
            .into_bytes();
            let word = |out: &mut Vec<u8>, w: [u8; 4]| {
                out.extend(if big { [w[3], w[2], w[1], w[0]] } else { w })
            };
            for q in p {
                for x in q.to_array() {
                    word(&mut out, x.to_le_bytes());
                }
            }
            for f in &faces {
                out.push(f.len() as u8);
                for &v in f {
                    word(&mut out, (v as i32).to_le_bytes());
                }
            }
            out
        };
        let gltf = sphere_gltf(&mesh);
        vec![
            ("stl", binary),
            ("stl", ascii.into_bytes()),
            ("ply", ply_ascii.into_bytes()),
            ("ply", binary_ply(false)),
            ("ply", binary_ply(true)),
            ("glb", gltf.glb()),
            ("gltf", gltf.embedded()),
        ]
    })
}

/// The sphere as a glTF scene: placed twice under a parent node (once mirrored), with a
/// camera, edge visibility codes and an outline list on its one primitive.
fn sphere_gltf(mesh: &wirepass::Mesh) -> gltf_file::GltfFile {
    use serde_json::json;
    let p: Vec<[f32; 3]> = mesh.positions().iter().map(|v| v.to_array()).collect();
    let idx: Vec<u32> = mesh.triangles().iter().flatten().copied().collect();
    let mut file = gltf_file::GltfFile::new();
    let mut prim = file.triangles(&p, &idx, None);
    let codes: Vec<[u8; 3]> = (0..mesh.triangle_count())
        .map(|t| [(t % 4) as u8, 2, 3])
        .collect();
    let vis = file.bytes(&gltf_file::visibility_bits(&codes));
    let outline = file.indices(&idx[..6], gltf_file::UNSIGNED_SHORT);
    prim["extensions"] = json!({
        "EXT_mesh_primitive_edge_visibility": {"visibility": vis},
        "CESIUM_primitive_outline": {"indices": outline},
    });
    let m = file.mesh(vec![prim]);
    let a = file.node(json!({"mesh": m, "translation": [2.0, 0.0, 0.0]}));
    let b = file.node(json!({"mesh": m, "scale": [-1.0, 1.0, 1.0]}));
    let c = file.camera(json!({"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}));
    let cam = file.node(json!({"camera": c, "translation": [0.0, 0.0, 5.0]}));
    let parent = file.node(json!({"children": [a, b, cam], "rotation": [0.0, 0.6, 0.0, 0.8]}));
    file.scene(&[parent]);
    file
}

/// One edit of a file: at a position (taken modulo the length), overwrite, insert or
/// delete a byte, or cut the file there.
fn edit() -> impl Strategy<Value = (usize, u8, u8)> {
    (any::<usize>(), 0u8..10, any::<u8>())
}

/// Starts that send random bytes past each loader's first checks.
fn start() -> impl Strategy<Value = &'static [u8]> {
    prop::sample::select(vec![
        &b""[..],
        b"solid ",
        b"solid x\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\n",
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
        b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
          property float y\nproperty float z\nelement face 1\n\
          property list uchar int vertex_indices\nend_header\n",
        b"ply\nformat binary_big_endian 1.0\n",
        b"glTF\x02\0\0\0",
        b"{\"asset\": {\"version\": \"2.0\"}, ",
    ])
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn random_bytes_never_panic_the_stl_ply_and_gltf_loaders(
        extension in prop::sample::select(vec!["stl", "ply", "glb", "gltf"]),
        start in start(),
        rest in prop::collection::vec(any::<u8>(), 0..600),
    ) {
        let mut bytes = start.to_vec();
        bytes.extend(rest);
        check_loaded(&temp_file(extension, &bytes))?;
    }

    #[test]
    fn mutated_stl_ply_and_gltf_files_never_panic(
        which in 0usize..7,
        edits in prop::collection::vec(edit(), 1..8),
    ) {
        let (extension, valid) = &valid_files()[which];
        let mut bytes = valid.clone();
        for (at, op, byte) in edits {
            let at = at % (bytes.len() + 1);
            match op {
                0..=4 if at < bytes.len() => bytes[at] = byte,
                5 | 6 => bytes.insert(at, byte),
                7 | 8 if at < bytes.len() => {
                    bytes.remove(at);
                }
                9 => bytes.truncate(at),
                _ => {}
            }
        }
        check_loaded(&temp_file(extension, &bytes))?;
    }
}

#[test]
fn the_valid_files_load() {
    for (k, (extension, bytes)) in valid_files().iter().enumerate() {
        let path = temp_file(extension, bytes);
        let mesh = wirepass::mesh::load(&path).unwrap_or_else(|e| panic!("file {k}: {e}"));
        std::fs::remove_file(&path).unwrap();
        // The glTF scene places the sphere twice.
        let copies = if extension.starts_with("gl") { 2 } else { 1 };
        let expected = copies * wirepass::mesh::sphere(24).unwrap().triangle_count();
        assert_eq!(mesh.triangle_count(), expected, "file {k}");
    }
}

/// A world point, sometimes exactly at the eye or just around it (w = 0 and w < 0 cases).
fn point(eye: Vec3) -> impl Strategy<Value = Vec3> {
    let near_eye = (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
        .prop_map(move |(x, y, z)| eye + Vec3::new(x, y, z) * 0.01);
    prop_oneof![
        12 => (-20.0f32..20.0, -20.0f32..20.0, -20.0f32..20.0)
            .prop_map(|(x, y, z)| Vec3::new(x, y, z)),
        1 => Just(eye),
        1 => near_eye,
    ]
}

fn camera() -> impl Strategy<Value = Camera> {
    (
        prop::array::uniform3(-10.0f32..10.0),
        prop::array::uniform3(-10.0f32..10.0),
        prop::array::uniform3(-1.0f32..1.0),
        1.0f32..170.0,
        (-4.0f32..0.0, 0.0f32..4.0),
    )
        .prop_map(|(eye, target, up, fov, (near_exp, depth_exp))| {
            let near = 10f32.powf(near_exp);
            Camera {
                eye: Vec3::from(eye),
                target: Vec3::from(target),
                up: Vec3::from(up),
                fov_y_deg: fov,
                near,
                far: near * 10f32.powf(depth_exp).max(1.001),
            }
        })
        .prop_filter("a valid camera", |c| c.validate().is_ok())
}

/// A camera, a triangle's world corners, an image size, a point in the image, an edge mask.
type Case = (Camera, [Vec3; 3], (u32, u32), (f64, f64), u8);

fn case() -> impl Strategy<Value = Case> {
    (camera(), 1u32..4000, 1u32..4000).prop_flat_map(|(cam, w, h)| {
        (
            Just(cam),
            [point(cam.eye), point(cam.eye), point(cam.eye)],
            Just((w, h)),
            (0.0..f64::from(w), 0.0..f64::from(h)),
            0u8..8,
        )
    })
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn edge_eval_gives_no_nan_and_barycentrics_sum_to_one(
        (cam, world, (w, h), (px, py), mask) in case()
    ) {
        let vp = cam.view_projection(w, h);
        let clip = world.map(|p| vp * p.as_dvec3().extend(1.0));
        let size = DVec2::new(f64::from(w), f64::from(h));
        let pixel = DVec2::new(px.floor() + 0.5, py.floor() + 0.5);
        for mask in [mask, 0b111] {
            let e = edge_math::edge_eval(clip, mask, pixel, size);
            prop_assert!(e.distance.iter().all(|d| !d.is_nan() && *d >= 0.0), "{:?}", e);
            prop_assert!(e.bary.iter().all(|b| !b.is_nan()), "{:?}", e);
            for i in 0..3 {
                if mask & (1 << i) == 0 {
                    prop_assert_eq!(e.distance[i], edge_math::NO_EDGE);
                }
            }
            // The three L·p values: their sum is the (pixel-independent) determinant of the
            // homogeneous screen corners, twice the screen area in homogeneous units. Away
            // from zero relative to the terms, the normalised weights sum to 1 to rounding.
            let p = clip.map(|c| edge_math::pixel_relative(c, pixel, size));
            let terms = [p[1].cross(p[2]).z, p[2].cross(p[0]).z, p[0].cross(p[1]).z];
            let sum: f64 = terms.iter().sum();
            let scale: f64 = terms.iter().map(|t| t.abs()).sum();
            if sum.abs() > 1e-6 * scale {
                let total: f64 = e.bary.iter().sum();
                prop_assert!((total - 1.0).abs() < 1e-9, "sum {} of {:?}", total, e.bary);
            }
        }
    }
}
