//! glTF 2.0 scenes, written here (JSON with base64 or external buffers, and GLB): they load
//! the same triangles and edges as their OBJ twins and render the same; node hierarchies
//! place instances as the specification composes them (against the ray-cast ground truth);
//! cameras give the views the specification defines; every primitive layout the loader
//! reads gives the triangles the specification lists; and the CAD edge extensions draw what
//! they say, checked against the ground truth and pixel by pixel.

mod common;

use common::gltf_file::{
    codes_for, visibility_bits, GltfFile, FLOAT, LINES, SHORT, TRIANGLE_FAN, TRIANGLE_STRIP,
    UNSIGNED_BYTE, UNSIGNED_SHORT,
};
use common::shoot_world;
use glam::{DMat4, DQuat, DVec3, Vec3};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::process::Command;
use wirepass::mesh::formats::gltf::{load_gltf, Document, GltfProjection};
use wirepass::tools::compare::metrics;
use wirepass::tools::offline::Method;
use wirepass::world::{Rendering, World, BACKGROUND};
use wirepass::{Camera, EdgeSelection, Mesh, Style, View};

const SIZE: (u32, u32) = (320, 240);

fn temp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("wirepass-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(name: &str, bytes: &[u8]) -> PathBuf {
    let path = temp_dir().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn load(path: &Path) -> Document {
    load_gltf(path).unwrap_or_else(|e| panic!("{e}"))
}

/// A file with one mesh of `primitives` at the origin (the default scene).
fn one_mesh(file: &mut GltfFile, primitives: Vec<serde_json::Value>) {
    let m = file.mesh(primitives);
    let n = file.node(json!({"mesh": m}));
    file.scene(&[n]);
}

/// The corners of each triangle.
fn corners(mesh: &Mesh) -> Vec<[Vec3; 3]> {
    mesh.triangles()
        .iter()
        .map(|t| t.map(|v| mesh.positions()[v as usize]))
        .collect()
}

fn camera(eye: Vec3) -> Camera {
    Camera {
        eye,
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_deg: 40.0,
        near: 0.5,
        far: 30.0,
    }
}

fn aspect() -> f64 {
    f64::from(SIZE.0) / f64::from(SIZE.1)
}

/// Renders `world` with the ray-cast ground truth and the deferred pass and checks the
/// deferred one within the bounds of tests/ground_truth.rs: id agreement ≥ 0.999, distance
/// error p99 ≤ 0.01 px and max ≤ 0.1 px. Returns both frames.
fn against_truth(label: &str, world: &World, view: View, style: &Style) -> (Rendering, Rendering) {
    let truth = shoot_world(world, view, style, SIZE, Method::Raycast);
    let frame = shoot_world(world, view, style, SIZE, Method::Deferred);
    let m = metrics(&truth, &frame).unwrap_or_else(|e| panic!("{e}"));
    let d = m.distance_error_px;
    println!(
        "{label}: id {:.5} distance p99 {:?} max {:?} ({} px)",
        m.id_agreement, d.p99, d.max, d.pixels
    );
    assert!(
        m.id_agreement >= 0.999,
        "{label}: id agreement {}",
        m.id_agreement
    );
    assert!(d.pixels > 0, "{label}: no pixel to measure");
    assert!(d.p99.is_some_and(|v| v <= 0.01), "{label}: p99 {:?}", d.p99);
    assert!(d.max.is_some_and(|v| v <= 0.1), "{label}: max {:?}", d.max);
    (truth, frame)
}

/// The pixel (column, row) where world point `p` projects.
fn pixel(view: &View, p: DVec3) -> (usize, usize) {
    let c = view.view_projection() * p.extend(1.0);
    let (x, y) = (c.x / c.w, c.y / c.w);
    let px = (x + 1.0) * 0.5 * f64::from(SIZE.0);
    let py = (1.0 - y) * 0.5 * f64::from(SIZE.1);
    (px as usize, py as usize)
}

fn distance_at(frame: &Rendering, (x, y): (usize, usize)) -> f32 {
    frame.edge_distance[y * frame.size.0 as usize + x]
}

// ---------------------------------------------------------------------------------------
// Geometry.

/// Positions, normals and triangles.
type Cube = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[u32; 3]>);

/// A cube of side 2 about the origin, 4 vertices per face (flat normals, as CAD exports
/// have it), each face two triangles (0, 1, 2) and (0, 2, 3) whose shared edge 0–2 is the
/// face diagonal.
fn cube() -> Cube {
    let (mut p, mut n, mut t) = (Vec::new(), Vec::new(), Vec::new());
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = p.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let mut q = [0.0; 3];
                q[axis] = sign;
                q[u] = a;
                q[v] = b;
                p.push(q);
                let mut normal = [0.0; 3];
                normal[axis] = sign;
                n.push(normal);
            }
            t.push([base, base + 1, base + 2]);
            t.push([base, base + 2, base + 3]);
        }
    }
    (p, n, t)
}

/// 2 for an edge of the cube (its corners differ in one coordinate), 0 for a diagonal.
fn cube_level(p: &[[f32; 3]], t: &[[u32; 3]]) -> impl Fn(usize, usize) -> u8 {
    let (p, t) = (p.to_vec(), t.to_vec());
    move |tri, k| {
        let (a, b) = (p[t[tri][k] as usize], p[t[tri][(k + 1) % 3] as usize]);
        let differ = (0..3).filter(|&i| a[i] != b[i]).count();
        if differ == 1 {
            2
        } else {
            0
        }
    }
}

/// The triangle masks of a cube whose diagonals are hidden: edges 0 and 1 of the first
/// triangle of each face, edges 1 and 2 of the second.
const CUBE_MASK: [u8; 2] = [0b011, 0b110];

/// A closed cylinder about the Y axis, radius 1, from y = −1 to 1, of `n` side quads (two
/// triangles each, vertices shared around the side) and two caps fanned from their centres;
/// the rims of the caps and of the side have the same positions, so they weld.
fn cylinder(n: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let ring = |i: u32, y: f32| {
        let a = i as f64 * std::f64::consts::TAU / f64::from(n);
        [a.sin() as f32, y, a.cos() as f32]
    };
    let (mut p, mut t) = (Vec::new(), Vec::new());
    for i in 0..n {
        p.push(ring(i, -1.0));
        p.push(ring(i, 1.0));
    }
    for i in 0..n {
        let j = (i + 1) % n;
        let (b0, t0, b1, t1) = (2 * i, 2 * i + 1, 2 * j, 2 * j + 1);
        t.push([b0, b1, t1]);
        t.push([b0, t1, t0]);
    }
    for y in [-1.0f32, 1.0] {
        let centre = p.len() as u32;
        p.push([0.0, y, 0.0]);
        for i in 0..n {
            p.push(ring(i, y));
        }
        for i in 0..n {
            t.push([centre, centre + 1 + i, centre + 1 + (i + 1) % n]);
        }
    }
    (p, t)
}

/// The cylinder's edges: vertical side edges are silhouette edges (1), the rims hard (2),
/// side diagonals and cap spokes hidden (0).
fn cylinder_level(p: &[[f32; 3]], t: &[[u32; 3]]) -> impl Fn(usize, usize) -> u8 {
    let (p, t) = (p.to_vec(), t.to_vec());
    move |tri, k| {
        let (a, b) = (p[t[tri][k] as usize], p[t[tri][(k + 1) % 3] as usize]);
        let on_rim = |q: [f32; 3]| (q[0] * q[0] + q[2] * q[2] - 1.0).abs() < 1e-4;
        if !on_rim(a) || !on_rim(b) {
            0 // a cap spoke
        } else if a[0] == b[0] && a[2] == b[2] {
            1 // a vertical side edge
        } else if a[1] == b[1] {
            2 // a rim
        } else {
            0 // a side diagonal
        }
    }
}

fn edge_visibility(file: &mut GltfFile, codes: &[[u8; 3]]) -> serde_json::Value {
    let v = file.bytes(&visibility_bits(codes));
    json!({"EXT_mesh_primitive_edge_visibility": {"visibility": v}})
}

// ---------------------------------------------------------------------------------------
// OBJ twins.

/// Suzanne (468 quads and 32 triangles) as glTF: her triangles, as the OBJ loader
/// triangulates them, with the polygon edges written as hard edges and the triangulation
/// diagonals as hidden ones. The glTF mesh has the OBJ mesh's triangles and positions, its
/// authored edges are the OBJ's polygon edges, and the two render the same.
#[test]
fn suzanne_as_gltf_matches_her_obj_twin() {
    let obj = wirepass::mesh::load_obj(&common::test_mesh("suzanne.obj")).unwrap();
    let p: Vec<[f32; 3]> = obj.positions().iter().map(|v| v.to_array()).collect();
    let n: Vec<[f32; 3]> = obj.normals().iter().map(|v| v.to_array()).collect();
    let t = obj.triangles().to_vec();
    let polygon = obj.edge_mask(EdgeSelection::Polygon);
    let codes = codes_for(&p, &t, |tri, k| 2 * (polygon[tri] >> k & 1));
    let mut file = GltfFile::new();
    let idx: Vec<u32> = t.iter().flatten().copied().collect();
    let mut prim = file.triangles(&p, &idx, None);
    prim["attributes"]["NORMAL"] = json!(file.normals(&n));
    prim["extensions"] = edge_visibility(&mut file, &codes);
    one_mesh(&mut file, vec![prim]);

    for (name, bytes) in [
        ("suzanne.glb", file.glb()),
        ("suzanne.gltf", file.embedded()),
    ] {
        let doc = load(&write(name, &bytes));
        assert_eq!(doc.meshes.len(), 1);
        assert_eq!(doc.instances, vec![(0, DMat4::IDENTITY)]);
        let m = &doc.meshes[0];
        assert_eq!(m.edges, Some(EdgeSelection::Authored));
        assert_eq!(m.mesh.positions(), obj.positions(), "{name}");
        assert_eq!(m.mesh.triangles(), obj.triangles(), "{name}");
        assert_eq!(m.mesh.edge_mask(EdgeSelection::Authored), polygon, "{name}");
        assert_eq!(
            m.mesh.edge_mask(EdgeSelection::All),
            obj.edge_mask(EdgeSelection::All)
        );
        for (a, b) in m.mesh.normals().iter().zip(obj.normals()) {
            assert!((*a - *b).length() < 1e-6, "{name}: normal {a} vs {b}");
        }
    }

    // Drawn the same, outlines off: with them on, the glTF would leave its hidden
    // diagonals out of the outline, where the OBJ may draw one.
    let doc = load(&write("suzanne-render.glb", &file.glb()));
    let gltf_world = World::from_gltf(doc, None);
    let obj_world = World::single(obj.clone(), EdgeSelection::Polygon);
    let style = Style {
        outlines: false,
        ..Style::default()
    };
    let view = camera(Vec3::new(1.5, 1.0, 3.5)).to_view(aspect());
    let a = shoot_world(&gltf_world, view, &style, SIZE, Method::Deferred);
    let b = shoot_world(&obj_world, view, &style, SIZE, Method::Deferred);
    assert_eq!(a.ids, b.ids);
    let worst = a
        .rgba
        .iter()
        .zip(&b.rgba)
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap();
    assert!(worst <= 1, "pixels differ by {worst}");
}

/// A glTF without edge extensions is an OBJ of triangles: every edge drawn, smooth normals
/// computed the same way, the same image outlines and all; with external buffers too.
#[test]
fn plain_gltf_matches_an_obj_of_triangles() {
    let torus = wirepass::mesh::torus(600).unwrap();
    let mut obj = String::new();
    for v in torus.positions() {
        obj.push_str(&format!("v {} {} {}\n", v.x, v.y, v.z));
    }
    for t in torus.triangles() {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    let obj = wirepass::mesh::load(&write("torus.obj", obj.as_bytes())).unwrap();
    let p: Vec<[f32; 3]> = obj.positions().iter().map(|v| v.to_array()).collect();
    let idx: Vec<u32> = obj.triangles().iter().flatten().copied().collect();
    let mut file = GltfFile::new();
    let prim = file.triangles(&p, &idx, None);
    one_mesh(&mut file, vec![prim]);
    let (json, bin) = file.external("torus%20data.bin");
    write("torus data.bin", &bin);
    let path = write("torus.gltf", &json);
    let doc = load(&path);
    let m = &doc.meshes[0];
    assert_eq!(m.edges, None, "no authored edges");
    assert_eq!(corners(&m.mesh), corners(&obj));
    assert_eq!(m.mesh.normals(), obj.normals());
    assert_eq!(
        m.mesh.edge_mask(EdgeSelection::Polygon),
        obj.edge_mask(EdgeSelection::Polygon)
    );
    assert!(m.mesh.outline_mask().iter().all(|&b| b == 0b111));
    // `mesh::load` gives the same mesh.
    assert_eq!(
        wirepass::mesh::load(&path).unwrap().triangles(),
        obj.triangles()
    );

    let view = camera(Vec3::new(0.5, 2.0, 2.5)).to_view(aspect());
    let style = Style::default();
    let a = shoot_world(
        &World::from_gltf(doc, None),
        view,
        &style,
        SIZE,
        Method::Deferred,
    );
    let b = shoot_world(
        &World::single(obj, EdgeSelection::Polygon),
        view,
        &style,
        SIZE,
        Method::Deferred,
    );
    assert_eq!(a.ids, b.ids);
    assert_eq!(a.rgba, b.rgba);
}

// ---------------------------------------------------------------------------------------
// Scenes and cameras.

/// A parent node scaled, rotated and moved, with three children: the cube twice (once
/// mirrored by a negative scale) and a torus placed by a matrix. The cube is loaded once and
/// instanced; each instance's transform is the parent's times the child's; loaded as one
/// mesh, the instances are moved into place; and the scene, outlines on, renders within the
/// ground truth's bounds.
#[test]
fn node_hierarchy_instances_meshes_against_the_ground_truth() {
    let (p, n, t) = cube();
    let torus = wirepass::mesh::torus(800).unwrap();
    let mut file = GltfFile::new();
    let idx: Vec<u32> = t.iter().flatten().copied().collect();
    let mut prim = file.triangles(&p, &idx, None);
    prim["attributes"]["NORMAL"] = json!(file.normals(&n));
    let cube_mesh = file.mesh(vec![prim]);
    let tp: Vec<[f32; 3]> = torus.positions().iter().map(|v| v.to_array()).collect();
    let ti: Vec<u32> = torus.triangles().iter().flatten().copied().collect();
    let prim = file.triangles(&tp, &ti, None);
    let torus_mesh = file.mesh(vec![prim]);

    let q = DQuat::from_rotation_y(30f64.to_radians()) * DQuat::from_rotation_x(0.2);
    let child_matrix = DMat4::from_translation(DVec3::new(0.0, 0.2, -2.5))
        * DMat4::from_rotation_x(90f64.to_radians())
        * DMat4::from_scale(DVec3::splat(1.2));
    let left = file.node(json!({"mesh": cube_mesh, "translation": [-1.6, 0.0, 0.0],
        "scale": [0.5, 0.5, 0.5]}));
    let right = file.node(json!({"mesh": cube_mesh, "translation": [1.6, 0.0, 0.0],
        "scale": [-0.5, 0.7, 0.5], "rotation": [0.0, 0.3826834323650898, 0.0, 0.9238795325112867]}));
    let ring = file.node(json!({"mesh": torus_mesh, "matrix": child_matrix.to_cols_array()}));
    let parent = file.node(json!({
        "translation": [0.25, -0.5, 0.1],
        "rotation": [q.x, q.y, q.z, q.w],
        "scale": [1.5, 1.25, 1.5],
        "children": [left, right, ring],
    }));
    file.scene(&[parent]);
    let doc = load(&write("hierarchy.glb", &file.glb()));

    assert_eq!(doc.meshes.len(), 2, "the cube is loaded once");
    let parent_m = DMat4::from_scale_rotation_translation(
        DVec3::new(1.5, 1.25, 1.5),
        q,
        DVec3::new(0.25, -0.5, 0.1),
    );
    let expected = [
        (
            0,
            parent_m
                * DMat4::from_scale_rotation_translation(
                    DVec3::splat(0.5),
                    DQuat::IDENTITY,
                    DVec3::new(-1.6, 0.0, 0.0),
                ),
        ),
        (
            0,
            parent_m
                * DMat4::from_scale_rotation_translation(
                    DVec3::new(-0.5, 0.7, 0.5),
                    DQuat::from_rotation_y(45f64.to_radians()),
                    DVec3::new(1.6, 0.0, 0.0),
                ),
        ),
        (1, parent_m * child_matrix),
    ];
    assert_eq!(doc.instances.len(), 3);
    for ((m, t), (em, et)) in doc.instances.iter().zip(expected) {
        assert_eq!(*m, em);
        assert!(t.abs_diff_eq(et, 1e-12), "{t} vs {et}");
    }
    assert!(doc.instances[1].1.determinant() < 0.0, "mirrored");

    // As one mesh (`mesh::load`, scene files): every instance moved into place, in order.
    let path = write("hierarchy-baked.glb", &file.glb());
    let baked = wirepass::mesh::load(&path).unwrap();
    assert_eq!(baked.triangle_count(), 2 * 12 + torus.triangle_count());
    let p0 = doc.instances[1]
        .1
        .transform_point3(DVec3::from(p[0].map(f64::from)));
    assert!((baked.positions()[24].as_dvec3() - p0).length() < 1e-6);

    let world = World::from_gltf(doc, None);
    assert_eq!(world.objects.len(), 3);
    let (lo, hi) = world.bounds();
    let (blo, bhi) = baked.bounds_f64();
    // The world's bounds are its objects' boxes transformed: they hold the baked mesh.
    assert!(blo.cmpge(lo - 1e-5).all() && bhi.cmple(hi + 1e-5).all());
    let (lo, hi) = world.bounds();
    let view = Camera::framing(lo, hi, aspect()).to_view(aspect());
    against_truth("hierarchy", &world, view, &Style::default());
    let feature = World {
        sections: Vec::new(),
        meshes: world
            .meshes
            .iter()
            .map(|m| wirepass::world::WorldMesh {
                edges: EdgeSelection::Feature(30.0),
                ..m.clone()
            })
            .collect(),
        ..world.clone()
    };
    let style = Style {
        line_width: 3.0,
        ..Style::default()
    };
    against_truth("hierarchy, feature edges", &feature, view, &style);
}

/// An orthographic camera on a turned, moved node: the view looks down the node's −Z with
/// its +Y up, and the projection is the one the specification gives (x scaled by 1/xmag,
/// y by 1/ymag, whatever the image's aspect). A perspective camera without zfar has an
/// infinite far plane; one without aspectRatio takes the image's.
#[test]
fn cameras_give_the_views_the_specification_defines() {
    let (p, _, t) = cube();
    let mut file = GltfFile::new();
    let idx: Vec<u32> = t.iter().flatten().copied().collect();
    let prim = file.triangles(&p, &idx, None);
    let m = file.mesh(vec![prim]);
    let ortho = file.camera(json!({"type": "orthographic",
        "orthographic": {"xmag": 2.0, "ymag": 1.0, "znear": 0.125, "zfar": 20.0}}));
    let persp = file.camera(json!({"type": "perspective",
        "perspective": {"yfov": 0.7, "znear": 0.05}}));
    // Turned 60° about Y, then tipped 30° down: the node's −Z points at the origin from
    // 10 units away.
    let q = DQuat::from_rotation_y(60f64.to_radians()) * DQuat::from_rotation_x(-0.5);
    let forward = q * DVec3::NEG_Z;
    let eye = -10.0 * forward;
    let mesh_node = file.node(json!({"mesh": m}));
    let ortho_node = file.node(json!({"camera": ortho, "translation": eye.to_array(),
        "rotation": [q.x, q.y, q.z, q.w]}));
    let persp_node = file.node(json!({"camera": persp, "translation": [0.0, 0.0, 6.0]}));
    file.scene(&[mesh_node, ortho_node, persp_node]);
    let path = write("cameras.gltf", &file.embedded());
    let doc = load(&path);
    assert_eq!(doc.cameras.len(), 2);

    let c = doc.cameras[0];
    assert_eq!(c.aspect(), Some(2.0));
    let v = c.view(aspect());
    let expected = View::orthographic((eye, eye + forward, q * DVec3::Y), 2.0, 2.0, (0.125, 20.0));
    assert!(v.view.abs_diff_eq(expected.view, 1e-12), "{}", v.view);
    assert!(v.projection.abs_diff_eq(expected.projection, 1e-12));
    assert_eq!(
        c.view(2.5),
        v,
        "the file's xmag and ymag, whatever the image"
    );
    assert!(v.is_orthographic());
    let world = World::from_gltf(doc.clone(), None);
    against_truth("orthographic glTF camera", &world, v, &Style::default());

    let c = doc.cameras[1];
    assert!(matches!(
        c.projection,
        GltfProjection::Perspective {
            zfar: None,
            aspect_ratio: None,
            ..
        }
    ));
    let v = c.view(aspect());
    let cam = Camera {
        eye: Vec3::new(0.0, 0.0, 6.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_deg: 0.7f32.to_degrees(),
        near: 0.05,
        far: f32::INFINITY,
    };
    assert!(v.view.abs_diff_eq(cam.view(), 1e-12));
    assert!(v.projection.abs_diff_eq(cam.projection(aspect()), 1e-6));

    // The command line takes the first camera by default, the other with --camera 1.
    for (args, orthographic) in [(&[][..], true), (&["--camera", "1"][..], false)] {
        let dump = temp_dir().join(format!("dump-{}", args.len()));
        let (ok, stderr) = cli(&path, args, Some(&dump));
        assert!(ok, "{stderr}");
        let camera: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dump.join("camera.json")).unwrap()).unwrap();
        assert_eq!(camera["orthographic"], json!(orthographic), "{args:?}");
        if orthographic {
            let p = camera["projection"].as_array().unwrap();
            assert!((p[0].as_f64().unwrap() - 0.5).abs() < 1e-12, "1 / xmag");
            assert!((p[5].as_f64().unwrap() - 1.0).abs() < 1e-12, "1 / ymag");
            assert!(
                stderr.contains("aspect ratio"),
                "a note on the stretch: {stderr}"
            );
        }
    }
    let (ok, stderr) = cli(&path, &["--camera", "2"], None);
    assert!(!ok);
    let errors: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("wirepass: error:"))
        .collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    assert!(errors[0].contains("--camera 2") && errors[0].contains("2 cameras, 0 to 1"));
}

/// Runs `wirepass render FILE --size 64x48 ARGS`, with `--dump DIR` if given.
fn cli(file: &Path, args: &[&str], dump: Option<&Path>) -> (bool, String) {
    // The command is the workspace's `wirepass-cli` package; `cargo test` at the root builds
    // it beside this test's own binary.
    let exe = std::env::current_exe().unwrap();
    let bin = exe
        .parent()
        .and_then(Path::parent)
        .unwrap()
        .join(format!("wirepass{}", std::env::consts::EXE_SUFFIX));
    assert!(
        bin.exists(),
        "{} is missing: run the tests from the workspace root (cargo test), which builds it",
        bin.display()
    );
    let mut cmd = Command::new(bin);
    cmd.arg("render")
        .arg(file)
        .args(["--size", "64x48", "-o"])
        .arg(temp_dir().join("cli.png"))
        .args(args);
    if let Some(d) = dump {
        cmd.arg("--dump").arg(d);
    }
    let out = cmd.output().expect("the wirepass binary runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "{stderr}");
    (out.status.success(), stderr)
}

/// Strips alternate their winding and fans turn about their first vertex, as §3.7.2.1
/// lists them; unsigned byte and short indices, non-indexed primitives, quantized
/// positions (KHR_mesh_quantization, required) and sparse accessors all load, primitives
/// concatenated in order, normals where one primitive has them and smooth ones elsewhere;
/// a LINES primitive is skipped with a note.
#[test]
fn primitive_layouts_give_the_triangles_the_specification_lists() {
    let mut file = GltfFile::new();
    let sq: Vec<[f32; 3]> = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    let strip_p = file.positions(&sq);
    let strip_i = file.indices(&[0, 1, 2, 3], UNSIGNED_BYTE);
    let fan: Vec<[f32; 3]> = vec![
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    let fan_p = file.positions(&fan);
    let fan_i = file.indices(&[0, 1, 2, 3], UNSIGNED_SHORT);
    let fan_n = file.normals(&[[0.0, 0.0, 2.0]; 4]);
    // Shorts, not normalized: the values themselves.
    let quant: Vec<i16> = vec![0, 0, 2, 3, 0, 2, 0, 3, 2];
    let bytes: Vec<u8> = quant.iter().flat_map(|v| v.to_le_bytes()).collect();
    let quant_p = file.accessor(&bytes, SHORT, 3, "VEC3", false);
    file.bounds(quant_p, &[[0.0, 0.0, 2.0], [3.0, 3.0, 2.0]]);
    // A sparse accessor: the strip's positions with vertex 3 moved up.
    let sparse_i = file.view(&[3u8], None);
    let moved: Vec<u8> = [1.0f32, 2.0, 0.0]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let sparse_v = file.view(&moved, None);
    let view = file.json["accessors"][strip_p]["bufferView"].clone();
    let sparse = {
        let list = file.json["accessors"].as_array_mut().unwrap();
        list.push(json!({"bufferView": view, "componentType": FLOAT, "count": 4, "type": "VEC3",
            "min": [0.0, 0.0, 0.0], "max": [1.0, 2.0, 0.0],
            "sparse": {"count": 1, "indices": {"bufferView": sparse_i, "componentType": UNSIGNED_BYTE},
                "values": {"bufferView": sparse_v}}}));
        list.len() - 1
    };
    let lines_i = file.indices(&[0, 1], UNSIGNED_BYTE);
    one_mesh(
        &mut file,
        vec![
            json!({"attributes": {"POSITION": strip_p}, "indices": strip_i, "mode": TRIANGLE_STRIP}),
            json!({"attributes": {"POSITION": fan_p, "NORMAL": fan_n}, "indices": fan_i,
                "mode": TRIANGLE_FAN}),
            json!({"attributes": {"POSITION": strip_p}, "indices": lines_i, "mode": LINES}),
            json!({"attributes": {"POSITION": quant_p}}),
            json!({"attributes": {"POSITION": sparse}, "indices": strip_i, "mode": TRIANGLE_STRIP}),
        ],
    );
    file.json["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    file.json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    let doc = load(&write("layouts.glb", &file.glb()));
    let v = |a: [f32; 3]| Vec3::from(a);
    let expected: Vec<[Vec3; 3]> = vec![
        // Strip: (0, 1, 2), then (1, 3, 2).
        [v(sq[0]), v(sq[1]), v(sq[2])],
        [v(sq[1]), v(sq[3]), v(sq[2])],
        // Fan: (1, 2, 0), (2, 3, 0).
        [v(fan[1]), v(fan[2]), v(fan[0])],
        [v(fan[2]), v(fan[3]), v(fan[0])],
        // Quantized, not indexed.
        [
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(3.0, 0.0, 2.0),
            Vec3::new(0.0, 3.0, 2.0),
        ],
        // Sparse: vertex 3 at (1, 2, 0).
        [v(sq[0]), v(sq[1]), v(sq[2])],
        [v(sq[1]), Vec3::new(1.0, 2.0, 0.0), v(sq[2])],
    ];
    assert_eq!(corners(&doc.meshes[0].mesh), expected);
    // The fan's normals, made unit; smooth ones for the vertices of the others.
    let normals = doc.meshes[0].mesh.normals();
    assert_eq!(normals[4..8], [Vec3::Z; 4]);
    assert!(normals
        .iter()
        .all(|n| n.is_finite() && (n.length() - 1.0).abs() < 1e-6));
    assert_eq!(doc.notes.len(), 1, "{:?}", doc.notes);
    assert!(
        doc.notes[0].contains("primitive 2: mode LINES"),
        "{}",
        doc.notes[0]
    );

    // The command line draws it, printing the note.
    let path = write("layouts-cli.glb", &file.glb());
    let (ok, stderr) = cli(&path, &[], None);
    assert!(ok, "{stderr}");
    let notes: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("wirepass: note:"))
        .collect();
    assert_eq!(notes.len(), 1, "{stderr}");
    assert!(
        notes[0].contains("mode LINES is not triangles"),
        "{}",
        notes[0]
    );

    // A file requiring an extension wirepass cannot read is an error.
    file.json["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    let e = load_gltf(&write("draco.glb", &file.glb()))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("requires the extension KHR_draco_mesh_compression"),
        "{e}"
    );
}

// ---------------------------------------------------------------------------------------
// CAD edge extensions.

/// The cube with every face diagonal hidden (0) and every cube edge hard (2 once, 3 where
/// it repeats on the adjoining face). The extension says hard edges are always drawn and
/// hidden ones never: the twelve cube edges appear wherever they are visible, as lines
/// and as outlines, and no diagonal does — not even across the middle of a face. The same
/// cube through CESIUM_primitive_outline, listing the cube edges, loads the same masks.
#[test]
fn cube_with_hard_edges_draws_the_cube_edges_only() {
    let (p, n, t) = cube();
    let codes = codes_for(&p, &t, cube_level(&p, &t));
    assert!(
        codes.iter().flatten().any(|&c| c == 3),
        "repeated edges are coded 3"
    );
    let mut file = GltfFile::new();
    let idx: Vec<u32> = t.iter().flatten().copied().collect();
    let mut prim = file.triangles(&p, &idx, None);
    prim["attributes"]["NORMAL"] = json!(file.normals(&n));
    prim["extensions"] = edge_visibility(&mut file, &codes);
    one_mesh(&mut file, vec![prim.clone()]);
    let doc = load(&write("hard-cube.gltf", &file.embedded()));
    let mesh = &doc.meshes[0].mesh;
    let expected: Vec<u8> = (0..12).map(|i| CUBE_MASK[i % 2]).collect();
    assert_eq!(mesh.edge_mask(EdgeSelection::Authored), expected);
    assert_eq!(mesh.outline_mask().to_vec(), expected);

    // CESIUM_primitive_outline: the cube edges as vertex pairs of each face.
    let mut pairs = Vec::new();
    for face in 0..6u32 {
        for k in 0..4 {
            pairs.extend([4 * face + k, 4 * face + (k + 1) % 4]);
        }
    }
    let mut cesium = GltfFile::new();
    let mut prim2 = cesium.triangles(&p, &idx, None);
    let outline = cesium.indices(&pairs, UNSIGNED_SHORT);
    prim2["extensions"] = json!({"CESIUM_primitive_outline": {"indices": outline}});
    one_mesh(&mut cesium, vec![prim2]);
    let doc2 = load(&write("outlined-cube.glb", &cesium.glb()));
    assert_eq!(doc2.meshes[0].edges, Some(EdgeSelection::Authored));
    assert_eq!(
        doc2.meshes[0].mesh.edge_mask(EdgeSelection::Authored),
        expected
    );
    assert_eq!(doc2.meshes[0].mesh.outline_mask().to_vec(), expected);

    let world = World::from_gltf(doc, None);
    assert_eq!(world.meshes[0].edges, EdgeSelection::Authored);
    let eye = DVec3::new(3.0, 2.5, 4.0);
    let view = camera(eye.as_vec3()).to_view(aspect());
    let style = Style {
        line_width: 2.0,
        ..Style::default()
    };
    let (truth, frame) = against_truth("hard cube", &world, view, &style);
    for f in [&truth, &frame] {
        // The centres of the three visible faces lie on their diagonals: no line there.
        for c in [DVec3::Z, DVec3::X, DVec3::Y] {
            let d = distance_at(f, pixel(&view, c));
            assert!(d > 4.0, "a line at the centre of face {c}: {d}");
        }
        // The midpoints of the three visible edges that meet at the near corner: lines.
        for m in [
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 1.0),
            DVec3::new(1.0, 0.0, 1.0),
        ] {
            let d = distance_at(f, pixel(&view, m));
            assert!(d < 1.0, "no line at the edge midpoint {m}: {d}");
        }
    }
    // Every edge drawn instead: the diagonals appear.
    let all = World::from_gltf(
        load(&write("hard-cube-2.gltf", &file.embedded())),
        Some(EdgeSelection::All),
    );
    let f = shoot_world(&all, view, &style, SIZE, Method::Deferred);
    assert!(distance_at(&f, pixel(&view, DVec3::Z)) < 1.0);
}

/// A 24-sided cylinder whose vertical side edges are silhouette edges (1 once, 0 on the
/// other side), whose rims are hard and whose side diagonals and cap spokes are hidden.
/// The extension says a silhouette edge is drawn only where it separates a front-facing
/// from a back-facing triangle: seen from the side, the left and right contours are drawn,
/// the rims are drawn, and nothing is drawn across the middle of the side, where a
/// vertical edge lies every 15°.
#[test]
fn cylinder_with_silhouette_edges_draws_only_its_contours() {
    let (p, t) = cylinder(24);
    let codes = codes_for(&p, &t, cylinder_level(&p, &t));
    let mut file = GltfFile::new();
    let idx: Vec<u32> = t.iter().flatten().copied().collect();
    let mut prim = file.triangles(&p, &idx, None);
    prim["extensions"] = edge_visibility(&mut file, &codes);
    one_mesh(&mut file, vec![prim]);
    let doc = load(&write("cylinder.glb", &file.glb()));
    let mesh = &doc.meshes[0].mesh;
    // Side triangles (b0, b1, t1) and (b0, t1, t0): the vertical edges are 1–2 of the
    // first (b1–t1) and 2–0 of the second (t0–b0); neither is drawn, both may be outlines.
    let authored = mesh.edge_mask(EdgeSelection::Authored);
    let outline = mesh.outline_mask();
    for s in 0..24 {
        assert_eq!(authored[2 * s], 0b001, "the bottom rim only");
        assert_eq!(authored[2 * s + 1], 0b010, "the top rim only");
        assert_eq!(outline[2 * s], 0b011, "rim and vertical edge");
        assert_eq!(outline[2 * s + 1], 0b110, "rim and vertical edge");
    }

    let world = World::from_gltf(doc, None);
    let view = camera(Vec3::new(0.0, 1.6, 6.0)).to_view(aspect());
    let style = Style {
        line_width: 2.0,
        ..Style::default()
    };
    let (truth, frame) = against_truth("silhouette cylinder", &world, view, &style);
    let (_, row) = pixel(&view, DVec3::new(0.0, 0.0, 1.0));
    for f in [&truth, &frame] {
        let w = f.size.0 as usize;
        let cols: Vec<usize> = (0..w)
            .filter(|&x| f.ids[row * w + x] != BACKGROUND)
            .collect();
        let (left, right) = (cols[0], *cols.last().unwrap());
        assert!(right - left > 60, "the cylinder spans {left}..{right}");
        // The contours: outlines at both ends of the row.
        assert!(distance_at(f, (left, row)) < 1.5, "no left contour");
        assert!(distance_at(f, (right, row)) < 1.5, "no right contour");
        // The middle 80 % of the side: no line at all.
        let margin = (right - left) / 10;
        for x in left + margin..=right - margin {
            let d = distance_at(f, (x, row));
            assert!(
                d > 3.0,
                "a line at ({x}, {row}) in the middle of the side: {d}"
            );
        }
    }
    // Polygon edges instead: every vertical side edge is drawn.
    let polygon = World::from_gltf(
        load(&write("cylinder-2.glb", &file.glb())),
        Some(EdgeSelection::Polygon),
    );
    let f = shoot_world(&polygon, view, &style, SIZE, Method::Deferred);
    let lines = (0..f.size.0 as usize)
        .filter(|&x| distance_at(&f, (x, row)) < 0.5)
        .count();
    assert!(lines >= 10, "only {lines} line pixels across the side");
}

/// A square of two triangles, all four sides boundary edges: the bottom one hard, the
/// others and the diagonal hidden. A hidden edge is never drawn, so the three hidden
/// boundaries have no outline either, though every boundary is an outline by default;
/// `--edges polygon` (or any explicit selection but authored) brings the outlines back.
#[test]
fn hidden_boundary_edges_have_no_outline() {
    let p = vec![
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    // Edges: t0 = 0–1 (bottom, hard), 1–2 (right), 2–0 (diagonal); t1 = 0–2, 2–3 (top),
    // 3–0 (left).
    let codes = [[2, 0, 0], [0, 0, 0]];
    let mut file = GltfFile::new();
    let mut prim = file.triangles(&p, &[0, 1, 2, 0, 2, 3], None);
    prim["extensions"] = edge_visibility(&mut file, &codes);
    one_mesh(&mut file, vec![prim]);
    let path = write("hidden-boundary.glb", &file.glb());
    let doc = load(&path);
    assert_eq!(
        doc.meshes[0].mesh.edge_mask(EdgeSelection::Authored),
        vec![0b001, 0]
    );
    assert_eq!(doc.meshes[0].mesh.outline_mask().to_vec(), vec![0b001, 0]);

    let view = camera(Vec3::new(0.6, 0.4, 4.0)).to_view(aspect());
    let style = Style {
        line_width: 2.0,
        ..Style::default()
    };
    let world = World::from_gltf(doc, None);
    let (truth, frame) = against_truth("hidden boundary", &world, view, &style);
    let mid = |a: [f32; 3], b: [f32; 3]| (Vec3::from(a) + Vec3::from(b)).as_dvec3() * 0.5;
    for f in [&truth, &frame] {
        assert!(
            distance_at(f, pixel(&view, mid(p[0], p[1]))) < 1.0,
            "the hard edge"
        );
        for (a, b) in [(1, 2), (2, 3), (3, 0), (0, 2)] {
            let d = distance_at(f, pixel(&view, mid(p[a], p[b])));
            assert!(d > 3.0, "a line along hidden edge {a}–{b}: {d}");
        }
    }
    let polygon = World::from_gltf(load(&path), Some(EdgeSelection::Polygon));
    assert!(polygon.meshes[0]
        .mesh
        .outline_mask()
        .iter()
        .all(|&m| m == 0b111));
    let (truth, _) = against_truth("hidden boundary, polygon edges", &polygon, view, &style);
    for (a, b) in [(1, 2), (2, 3), (3, 0)] {
        let d = distance_at(&truth, pixel(&view, mid(p[a], p[b])));
        assert!(d < 1.0, "boundary {a}–{b} has no outline: {d}");
    }
}

/// Code 3 alone is a hard edge too ("already encoded as 2" elsewhere, but drawn all the
/// same), and lineStrings add hard edges; BENTLEY_materials_line_style's width on the
/// edges' material becomes the object's line width, unless the command line gives one, and
/// its pattern (0xf0f0: 4 px on, 4 off) the pattern of the object's edges.
#[test]
fn repeated_codes_line_strings_and_line_style() {
    let p = vec![
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    let mut file = GltfFile::new();
    let mut prim = file.triangles(&p, &[0, 1, 2, 0, 2, 3], None);
    // The diagonal coded 3 on both sides; the top edge (2–3) as a line string.
    let vis = file.bytes(&visibility_bits(&[[0, 0, 3], [3, 0, 0]]));
    let strings = file.indices(&[2, 3], UNSIGNED_BYTE);
    let material = file.material(json!({"extensions":
        {"BENTLEY_materials_line_style": {"width": 4, "pattern": 61680}}}));
    prim["extensions"] = json!({"EXT_mesh_primitive_edge_visibility":
        {"visibility": vis, "lineStrings": [{"indices": strings}], "material": material}});
    one_mesh(&mut file, vec![prim]);
    let path = write("line-style.gltf", &file.embedded());
    let doc = load(&path);
    assert_eq!(
        doc.meshes[0].mesh.edge_mask(EdgeSelection::Authored),
        vec![0b100, 0b011]
    );
    assert_eq!(doc.meshes[0].line_width, Some(4.0));
    let dashes = wirepass::LinePattern::Dashed {
        dash: 4.0,
        gap: 4.0,
    };
    assert_eq!(doc.meshes[0].line_pattern, Some(dashes));
    assert!(doc.notes.is_empty(), "{:?}", doc.notes);
    let world = World::from_gltf(doc, None);
    assert_eq!(world.objects[0].style.line_width, Some(4.0));
    assert_eq!(world.objects[0].style.edge_pattern, Some(dashes));

    // Two dashes in a repeat: drawn solid, and said so.
    let mut file = GltfFile::new();
    let mut prim = file.triangles(&p, &[0, 1, 2, 0, 2, 3], None);
    let material = file.material(json!({"extensions":
        {"BENTLEY_materials_line_style": {"width": 2, "pattern": 0x0505}}}));
    prim["material"] = json!(material);
    one_mesh(&mut file, vec![prim]);
    let doc = load(&write("line-style-two.gltf", &file.embedded()));
    assert_eq!(doc.meshes[0].line_pattern, None);
    assert!(
        doc.notes.iter().any(|n| n.contains("line pattern 1285")),
        "{:?}",
        doc.notes
    );

    let options = wirepass::tools::load::WorldOptions {
        line_width: Some(2.0),
        ..Default::default()
    };
    let loaded = wirepass::tools::load::load_world(path.to_str(), &options).unwrap();
    assert_eq!(
        loaded.world.objects[0].style.line_width, None,
        "the command line's width"
    );
    assert_eq!(loaded.world.meshes[0].edges, EdgeSelection::Authored);
    let loaded = wirepass::tools::load::load_world(path.to_str(), &Default::default()).unwrap();
    assert_eq!(loaded.world.objects[0].style.line_width, Some(4.0));
}

/// A scene file may name a glTF file as an object's mesh: without `edges` it draws the
/// file's own edges with their outline mask; with `edges` it draws those, every edge
/// allowed as an outline.
#[test]
fn scene_files_take_gltf_meshes_with_their_edges() {
    let (p, _, t) = cube();
    let codes = codes_for(&p, &t, cube_level(&p, &t));
    let mut file = GltfFile::new();
    let idx: Vec<u32> = t.iter().flatten().copied().collect();
    let mut prim = file.triangles(&p, &idx, None);
    prim["extensions"] = edge_visibility(&mut file, &codes);
    one_mesh(&mut file, vec![prim]);
    write("scene-cube.glb", &file.glb());
    let scene = write(
        "scene.json",
        br#"{"objects": [
            {"mesh": "scene-cube.glb"},
            {"mesh": "scene-cube.glb", "edges": "all", "transform": {"translate": [3, 0, 0]}}
        ]}"#,
    );
    let loaded = wirepass::tools::load::load_world(scene.to_str(), &Default::default()).unwrap();
    let meshes = &loaded.world.meshes;
    assert_eq!(meshes.len(), 2);
    assert_eq!(meshes[0].edges, EdgeSelection::Authored);
    let expected: Vec<u8> = (0..12).map(|i| CUBE_MASK[i % 2]).collect();
    assert_eq!(meshes[0].mesh.outline_mask().to_vec(), expected);
    assert_eq!(meshes[1].edges, EdgeSelection::All);
    assert!(meshes[1].mesh.outline_mask().iter().all(|&m| m == 0b111));
}
