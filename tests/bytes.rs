//! Every loader reads a file's bytes as it reads the file (a browser has no file system:
//! files arrive by drag and drop or `fetch`): the same mesh from every good file, the same
//! error from every bad one, and a glTF's external buffers through the caller's resolver.

mod common;

use common::gltf_file::GltfFile;
use std::path::{Path, PathBuf};
use wirepass::mesh::formats::{load_gltf, load_gltf_bytes, load_gltf_mesh_bytes};
use wirepass::mesh::{load, load_bytes};
use wirepass::{EdgeSelection, Mesh};

fn data(folder: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(folder)
}

fn temp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("wirepass-bytes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn assert_same(a: &Mesh, b: &Mesh, what: &str) {
    assert_eq!(a.positions(), b.positions(), "{what}");
    assert_eq!(a.triangles(), b.triangles(), "{what}");
    for selection in [EdgeSelection::Polygon, EdgeSelection::Authored] {
        assert_eq!(a.edge_mask(selection), b.edge_mask(selection), "{what}");
    }
}

/// A binary STL, an ASCII STL and a binary PLY of one quad, beside the shared OBJ meshes.
fn written_files() -> Vec<PathBuf> {
    let dir = temp_dir();
    let corners = [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let triangles = [[0usize, 1, 2], [0, 2, 3]];
    let mut binary = vec![0u8; 80];
    binary.extend_from_slice(&2u32.to_le_bytes());
    let mut ascii = String::from("solid quad\n");
    for t in triangles {
        binary.extend_from_slice(&[0u8; 12]);
        ascii += "facet normal 0 0 1\nouter loop\n";
        for c in t {
            for x in corners[c] {
                binary.extend_from_slice(&x.to_le_bytes());
            }
            let [x, y, z] = corners[c];
            ascii += &format!("vertex {x} {y} {z}\n");
        }
        binary.extend_from_slice(&[0u8; 2]);
        ascii += "endloop\nendfacet\n";
    }
    ascii += "endsolid quad\n";
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\n\
        property float x\nproperty float y\nproperty float z\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for c in corners {
        for x in c {
            ply.extend_from_slice(&x.to_le_bytes());
        }
    }
    ply.push(4);
    for i in 0..4i32 {
        ply.extend_from_slice(&i.to_le_bytes());
    }
    let mut files = Vec::new();
    for (name, bytes) in [
        ("quad.stl", binary),
        ("quad_ascii.STL", ascii.into_bytes()),
        ("quad.ply", ply),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        files.push(path);
    }
    files
}

#[test]
fn every_good_file_loads_the_same_mesh_from_its_bytes() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(data("meshes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    files.extend(written_files());
    assert!(files.len() >= 8, "{files:?}");
    for path in files {
        let from_file = load(&path).unwrap_or_else(|e| panic!("{e}"));
        let bytes = std::fs::read(&path).unwrap();
        let from_bytes = load_bytes(&path, &bytes).unwrap_or_else(|e| panic!("{e}"));
        assert_same(&from_file, &from_bytes, &path.display().to_string());
    }
}

/// The catalogue of bad files (tests/data/bad): the bytes give the error the file gives,
/// word for word, naming the file and the line. A `.gltf` whose buffer is a separate file
/// is the one difference: from bytes alone there is nothing to read it from, and the error
/// says so.
#[test]
fn every_bad_file_gives_the_same_error_from_its_bytes() {
    let mut checked = 0;
    for entry in std::fs::read_dir(data("bad")).unwrap() {
        let path = entry.unwrap().path();
        let bytes = std::fs::read(&path).unwrap();
        let from_file = load(&path).unwrap_err().to_string();
        let from_bytes = load_bytes(&path, &bytes).unwrap_err().to_string();
        if path.file_name().unwrap() == "missing_buffer.gltf" {
            assert!(from_bytes.contains("separate file"), "{from_bytes}");
            assert!(from_bytes.starts_with(&path.display().to_string()));
            continue;
        }
        assert_eq!(from_file, from_bytes, "{}", path.display());
        checked += 1;
    }
    assert!(checked >= 25, "only {checked} bad files");
}

/// A `.gltf` with its buffer in a file beside it: read from a path, the buffer is read
/// beside it; read from bytes, it comes from the resolver, by the name the file gives (a
/// percent-encoded URI decoded), and a resolver's refusal is the file's error.
#[test]
fn gltf_external_buffers_come_from_the_resolver() {
    let mut file = GltfFile::new();
    let p = [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let prim = file.triangles(&p, &[0, 1, 2, 0, 2, 3], None);
    let m = file.mesh(vec![prim]);
    let node = file.node(serde_json::json!({ "mesh": m }));
    file.scene(&[node]);
    let dir = temp_dir();
    let (gltf, bin) = file.external("quad%20data.bin");
    let path = dir.join("quad.gltf");
    std::fs::write(&path, &gltf).unwrap();
    std::fs::write(dir.join("quad data.bin"), &bin).unwrap();

    let from_file = load_gltf(&path).unwrap_or_else(|e| panic!("{e}"));
    let mut asked = Vec::new();
    let mut resolve = |name: &str| {
        asked.push(name.to_owned());
        Ok(bin.clone())
    };
    let from_bytes = load_gltf_bytes(Path::new("dropped.gltf"), &gltf, &mut resolve).unwrap();
    assert_eq!(asked, ["quad data.bin"]);
    assert_eq!(from_file.meshes.len(), from_bytes.meshes.len());
    assert_same(
        &from_file.meshes[0].mesh,
        &from_bytes.meshes[0].mesh,
        "external",
    );

    let mut refuse = |name: &str| Err(format!("no file named '{name}' was dropped"));
    let e = load_gltf_mesh_bytes(Path::new("dropped.gltf"), &gltf, &mut refuse)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("dropped.gltf"), "{e}");
    assert!(
        e.contains("no file named 'quad data.bin' was dropped"),
        "{e}"
    );

    // A GLB and an embedded .gltf need no resolver.
    for (name, bytes) in [("quad.glb", file.glb()), ("quad.gltf", file.embedded())] {
        let mesh = load_bytes(Path::new(name), &bytes).unwrap_or_else(|e| panic!("{e}"));
        assert_same(&from_file.meshes[0].mesh, &mesh, name);
    }
}
