//! glTF 2.0 scenes (`.gltf` with external or embedded base64 buffers, and `.glb`) through
//! the `gltf` crate: the meshes of the default scene (scene 0 without one; every root node
//! without any scene), each loaded once and placed by every node that uses it, the
//! scene's cameras, and the CAD edge extensions.
//!
//! **Geometry.** A glTF mesh's triangle primitives (`TRIANGLES`, `TRIANGLE_STRIP`,
//! `TRIANGLE_FAN`, indexed by unsigned bytes, shorts or ints, or not indexed) become one
//! [`Mesh`], primitives concatenated in order, their triangles in the order of the glTF
//! specification (§3.7.2.1), which the edge extensions count by. Positions and normals are
//! floats or, as `KHR_mesh_quantization` allows, normalized or plain integers; sparse
//! accessors are applied. A primitive without normals gets smooth ones. Points and lines
//! are skipped with a note, as are skins and morph targets (the mesh is drawn as it
//! stands). Node transforms (matrices, or translation · rotation · scale) are read from the
//! JSON in f64 and composed down the hierarchy in f64.
//!
//! **Edges.** `EXT_mesh_primitive_edge_visibility` gives each triangle edge 2 bits (edges
//! `v0:v1`, `v1:v2`, `v2:v0`, packed from the low bits up): 0 hidden, 1 silhouette (drawn
//! only where it separates a front-facing from a back-facing triangle), 2 hard (always
//! drawn), 3 hard, repeated (its other occurrence says 2). Its `lineStrings` add hard
//! edges. `CESIUM_primitive_outline` lists hard edges as vertex pairs. The specification
//! encodes a shared edge once (a silhouette as 1 on one side and 0 on the other; a hard
//! edge as 2 and 3), while wirepass's passes read each edge from the triangles on both
//! sides, so an edge takes the most visible of its occurrences across the mesh's own
//! adjacency (vertices welded by position): the silhouette mate is found that way rather
//! than through `silhouetteMates`. Then the authored drawn mask
//! ([`Mesh::with_authored_edges`]) holds the hard edges, and the outline mask
//! ([`Mesh::with_outline_mask`]) every edge that is not hidden: a hidden edge is never
//! drawn, not even as a silhouette or a boundary. Primitives without either extension
//! draw all their edges and allow every outline.
//!
//! **Line width.** `BENTLEY_materials_line_style`'s `width` (pixels), on the material of the
//! edges (`EXT_mesh_primitive_edge_visibility`'s `material`, else the primitive's), becomes
//! [`GltfMesh::line_width`], and its 16-bit `pattern` (one bit a pixel)
//! [`GltfMesh::line_pattern`] ([`LinePattern::from_bits`](crate::LinePattern::from_bits):
//! a repeat of one dash or dot; others are drawn solid, with a note). wirepass draws one
//! width and pattern per object, so a mesh whose primitives disagree takes the first and
//! says so in a note.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod buffers;
mod primitives;

use buffers::Buffers;
use primitives::build_mesh;

use super::read::{file_error, io_error, open};
use crate::camera::{DepthRange, View};
use crate::error::{Error, Result};
use crate::mesh::{EdgeSelection, Mesh};
use glam::dcamera::rh::{proj::directx as proj, view::look_at_mat4};
use glam::{DMat3, DMat4, DQuat, DVec3, DVec4};
use std::borrow::Cow;
use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

/// A glTF file's scene: its meshes (each once), their placements and its cameras.
#[derive(Clone, Debug)]
pub struct Document {
    /// The meshes the scene uses, in the order nodes first use them.
    pub meshes: Vec<GltfMesh>,
    /// Placements, in node order (depth first, as the scene lists them): an index into
    /// [`Document::meshes`] and the node's model → world transform.
    pub instances: Vec<(usize, DMat4)>,
    /// The cameras of the scene's nodes, in node order.
    pub cameras: Vec<GltfCamera>,
    /// What was left out or read leniently (points and lines, skins, a camera that cannot
    /// be used, …), one sentence each, for the command line to print.
    pub notes: Vec<String>,
}

/// One glTF mesh: its triangle primitives as one [`Mesh`], and how the file says to draw it.
#[derive(Clone, Debug)]
pub struct GltfMesh {
    /// The triangles, with the file's drawn edges and outline mask where it has them.
    pub mesh: Mesh,
    /// The mesh's name in the file, or `mesh N`.
    pub name: String,
    /// [`EdgeSelection::Authored`] where the file says which edges to draw; draw it
    /// through [`Mesh::resolve_edges`] so that another selection drops the outline mask.
    pub edges: Option<EdgeSelection>,
    /// The line width the file asks for, in pixels (`BENTLEY_materials_line_style`).
    pub line_width: Option<f32>,
    /// The pattern of the drawn edges the file asks for (`BENTLEY_materials_line_style`).
    pub line_pattern: Option<crate::style::LinePattern>,
}

/// A glTF camera where its node puts it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfCamera {
    /// The camera node's model → world transform: the camera looks down its −Z axis with
    /// +Y up. Scale and shear are ignored (only position and orientation are used).
    pub transform: DMat4,
    /// The projection the file gives.
    pub projection: GltfProjection,
}

/// A glTF camera's projection, as the file gives it (distances in the camera node's
/// units, angles in radians).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GltfProjection {
    /// `perspective`.
    Perspective {
        /// Vertical field of view.
        yfov: f64,
        /// Width / height; `None` means the image's.
        aspect_ratio: Option<f64>,
        /// Near plane distance, > 0.
        znear: f64,
        /// Far plane distance; `None` means infinite.
        zfar: Option<f64>,
    },
    /// `orthographic`: the view volume is `2 xmag` wide and `2 ymag` tall.
    Orthographic {
        /// Half the width of the view volume.
        xmag: f64,
        /// Half the height of the view volume.
        ymag: f64,
        /// Near plane distance, ≥ 0.
        znear: f64,
        /// Far plane distance.
        zfar: f64,
    },
}

impl GltfCamera {
    /// The aspect ratio (width / height) the file fixes, if it does: a perspective camera's
    /// `aspectRatio`, an orthographic camera's `xmag / ymag`.
    pub fn aspect(&self) -> Option<f64> {
        match self.projection {
            GltfProjection::Perspective { aspect_ratio, .. } => aspect_ratio,
            GltfProjection::Orthographic { xmag, ymag, .. } => Some(xmag / ymag),
        }
    }

    /// The view for an image of aspect `aspect` (width / height).
    ///
    /// The projection is the one the glTF specification defines: where the file fixes the
    /// aspect ratio (a perspective `aspectRatio`, an orthographic `xmag`/`ymag`), exactly
    /// the authored view volume fills the image, stretched if the image's aspect differs
    /// (the command line notes when it does); a perspective camera without `aspectRatio`
    /// takes the image's. A missing perspective `zfar` is an infinite far plane.
    pub fn view(&self, aspect: f64) -> View {
        let t = self.transform;
        let eye = t.w_axis.truncate();
        let forward = -t.z_axis.truncate().normalize_or_zero();
        let up = t.y_axis.truncate().normalize_or_zero();
        let view = look_at_mat4(eye, eye + forward, up);
        let projection = match self.projection {
            GltfProjection::Perspective {
                yfov,
                aspect_ratio,
                znear,
                zfar,
            } => {
                let aspect = aspect_ratio.unwrap_or(aspect);
                match zfar {
                    Some(zfar) => proj::perspective(yfov, aspect, znear, zfar),
                    None => proj::perspective_infinite(yfov, aspect, znear),
                }
            }
            GltfProjection::Orthographic {
                xmag,
                ymag,
                znear,
                zfar,
            } => proj::orthographic(-xmag, xmag, -ymag, ymag, znear, zfar),
        };
        View::new(view, projection, DepthRange::Standard)
    }
}

/// Extensions a file may require: the ones read here, and ones that change only how
/// surfaces are shaded, which wirepass does not do.
fn supported_requirement(name: &str) -> bool {
    [
        "KHR_mesh_quantization",
        "EXT_mesh_primitive_edge_visibility",
        "CESIUM_primitive_outline",
        "BENTLEY_materials_line_style",
        "KHR_lights_punctual",
    ]
    .contains(&name)
        || ["KHR_materials_", "KHR_texture_", "EXT_texture_"]
            .iter()
            .any(|p| name.starts_with(p))
}

/// A problem of the file, in words; the loader adds the file's name.
type FileResult<T> = std::result::Result<T, String>;

/// Gives the bytes of an external buffer a glTF file names by a relative reference (its
/// URI, percent-decoded: `"scene.bin"`, `"buffers/a b.bin"`), or says why it cannot.
pub type Resolver<'r> = &'r mut dyn FnMut(&str) -> std::result::Result<Vec<u8>, String>;

/// Loads a glTF file's scene. Every problem of the file is an [`Error::MeshFile`] naming
/// it (a missing external buffer too); a scene without a triangle to draw is one as well.
pub fn load_gltf(path: &Path) -> Result<Document> {
    let (mut file, len) = open(path, "a glTF")?;
    // The length only sizes the read: a file that grows or shrinks meanwhile still reads.
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    file.read_to_end(&mut bytes)
        .map_err(|e| io_error(path, e))?;
    let folder = path.parent().unwrap_or(Path::new("."));
    let mut beside = |name: &str| {
        let file = folder.join(name);
        std::fs::read(&file).map_err(|e| format!("cannot read '{}': {e}", file.display()))
    };
    load_gltf_bytes(path, &bytes, &mut beside)
}

/// [`load_gltf`] from the bytes of a `.gltf` or `.glb` file (a browser has no file system:
/// its files come by drag and drop or `fetch`); `name` names the file in errors. `resolve`
/// gives the external buffers a `.gltf` names (a `.glb`, or a `.gltf` with its buffers in
/// `data:` URIs, asks for none); its error message becomes the file's error.
pub fn load_gltf_bytes(name: &Path, bytes: &[u8], resolve: Resolver<'_>) -> Result<Document> {
    parse(bytes, resolve).map_err(|message| file_error(name, None, message))
}

/// Loads a glTF file as one mesh, for where one mesh is wanted (`mesh::load`, scene
/// files): a scene of one untransformed instance is its mesh; otherwise every instance is
/// moved to where its node puts it and the copies are concatenated in node order (edges,
/// outline masks and all). Cameras, notes and line widths are left out: load the file with
/// [`load_gltf`] for them.
pub fn load_gltf_mesh(path: &Path) -> Result<Mesh> {
    one_mesh(path, load_gltf(path)?)
}

/// [`load_gltf_mesh`] from the bytes of a file, as [`load_gltf_bytes`] reads them.
pub fn load_gltf_mesh_bytes(name: &Path, bytes: &[u8], resolve: Resolver<'_>) -> Result<Mesh> {
    one_mesh(name, load_gltf_bytes(name, bytes, resolve)?)
}

/// A document's scene as one mesh: see [`load_gltf_mesh`].
fn one_mesh(path: &Path, mut doc: Document) -> Result<Mesh> {
    if let [(m, t)] = doc.instances[..] {
        if t == DMat4::IDENTITY {
            return Ok(doc.meshes.swap_remove(m).mesh);
        }
    }
    let placed = doc
        .instances
        .iter()
        .map(|&(m, t)| transformed(&doc.meshes[m].mesh, t))
        .collect::<Result<Vec<_>>>()?;
    Mesh::merge(&placed).map_err(|e| match e {
        Error::InvalidMesh(message) => file_error(path, None, message),
        e => e,
    })
}

/// `mesh` moved by the affine transform `t` (normals by its inverse transpose).
fn transformed(mesh: &Mesh, t: DMat4) -> Result<Mesh> {
    let normal = DMat3::from_mat4(t).inverse().transpose();
    let positions = mesh
        .positions
        .iter()
        .map(|p| t.transform_point3(p.as_dvec3()).as_vec3())
        .collect();
    let normals = mesh
        .normals
        .iter()
        .map(|n| (normal * n.as_dvec3()).as_vec3())
        .collect();
    let mut moved = Mesh::new(
        positions,
        Some(normals),
        mesh.triangles.clone(),
        Some(mesh.polygon_edges.clone()),
    )?;
    moved.outline_mask = mesh.outline_mask.clone();
    moved.authored_edges = mesh.authored_edges.clone();
    Ok(moved)
}

/// A GLB file's JSON chunk and binary chunk, borrowed from the file's bytes.
type Chunks<'a> = (Cow<'a, [u8]>, Option<Cow<'a, [u8]>>);

/// The GLB container's JSON chunk and binary chunk. The header is checked here before the
/// `gltf` crate splits the chunks: it subtracts the header size from the declared length
/// without checking it first.
fn split_glb(bytes: &[u8]) -> FileResult<Chunks<'_>> {
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(format!(
            "GLB file of {} bytes, shorter than its 12-byte header",
            bytes.len()
        ));
    };
    if version != 2 {
        return Err(format!("GLB version {version}; wirepass reads glTF 2.0"));
    }
    if length < 20 {
        return Err(format!(
            "the GLB header declares {length} bytes, too few for a JSON chunk"
        ));
    }
    if length as usize > bytes.len() {
        return Err(format!(
            "the GLB header declares {length} bytes, but the file has {} (truncated)",
            bytes.len()
        ));
    }
    let glb = gltf::Glb::from_slice(bytes).map_err(|e| format!("not a valid GLB file: {e}"))?;
    Ok((glb.json, glb.bin))
}

/// Node transforms as the JSON writes them, in f64 (the `gltf` crate keeps f32).
#[derive(serde::Deserialize)]
struct RawRoot {
    #[serde(default)]
    nodes: Vec<RawNode>,
}

#[derive(serde::Deserialize)]
struct RawNode {
    matrix: Option<[f64; 16]>,
    translation: Option<[f64; 3]>,
    rotation: Option<[f64; 4]>,
    scale: Option<[f64; 3]>,
}

impl RawNode {
    /// The node's local transform: its matrix, or T · R · S.
    fn local(&self) -> FileResult<DMat4> {
        if let Some(m) = self.matrix {
            return Ok(DMat4::from_cols_array(&m));
        }
        let t = DVec3::from(self.translation.unwrap_or([0.0; 3]));
        let s = DVec3::from(self.scale.unwrap_or([1.0; 3]));
        let [x, y, z, w] = self.rotation.unwrap_or([0.0, 0.0, 0.0, 1.0]);
        let q = DQuat::from_xyzw(x, y, z, w);
        if !(q.length() > 0.0) {
            return Err(format!("rotation {:?} is not a quaternion", [x, y, z, w]));
        }
        Ok(DMat4::from_scale_rotation_translation(s, q.normalize(), t))
    }
}

fn parse(bytes: &[u8], resolve: Resolver<'_>) -> FileResult<Document> {
    if bytes.is_empty() {
        return Err("empty file, not a glTF file".into());
    }
    let (json, blob) = if bytes.starts_with(b"glTF") {
        split_glb(bytes)?
    } else {
        (Cow::Borrowed(bytes), None)
    };
    let gltf = gltf::Gltf::from_slice_without_validation(&json).map_err(|e| match e {
        gltf::Error::Deserialize(e) => format!("not glTF JSON: {e}"),
        e => format!("not a glTF file: {e}"),
    })?;
    // The `gltf` crate refuses every required extension it does not itself implement
    // (KHR_mesh_quantization among them); required extensions are checked here instead.
    let mut root = gltf.document.into_json();
    if let Some(name) = root
        .extensions_required
        .iter()
        .find(|e| !supported_requirement(e))
    {
        return Err(format!(
            "the file requires the extension {name}, which wirepass does not read"
        ));
    }
    root.extensions_required.clear();
    // The crate's own validation indexes the accessors by POSITION before it checks the
    // index (and panics on a bad one): every attribute's accessor is checked first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (k, p) in mesh.primitives.iter().enumerate() {
            if let Some(a) = p
                .attributes
                .values()
                .find(|a| a.value() >= root.accessors.len())
            {
                return Err(format!(
                    "invalid glTF: meshes[{m}].primitives[{k}].attributes: accessor {} does not exist",
                    a.value()
                ));
            }
        }
    }
    let doc = gltf::Document::from_json(root).map_err(|e| e.to_string())?;
    let raw: RawRoot = serde_json::from_slice(&json).map_err(|e| format!("not glTF JSON: {e}"))?;
    let buffers = Buffers::load(&doc, blob, resolve)?;
    let mut notes = Vec::new();

    let (roots, scene_name) = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => (
            scene.nodes().map(|n| n.index()).collect::<Vec<_>>(),
            format!("scene {}", scene.index()),
        ),
        None => {
            let mut child = vec![false; doc.nodes().len()];
            for n in doc.nodes() {
                for c in n.children() {
                    child[c.index()] = true;
                }
            }
            notes.push("the file has no scene: every root node is drawn".to_owned());
            let roots = (0..child.len()).filter(|&i| !child[i]).collect();
            (roots, "the root nodes".to_owned())
        }
    };

    // Depth first, in the order the file lists nodes and children.
    let nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut reached = vec![false; nodes.len()];
    let mut stack: Vec<(usize, DMat4)> =
        roots.iter().rev().map(|&n| (n, DMat4::IDENTITY)).collect();
    let mut placements: Vec<(usize, usize, DMat4)> = Vec::new();
    let mut cameras = Vec::new();
    let mut skinned = false;
    while let Some((n, parent)) = stack.pop() {
        if std::mem::replace(&mut reached[n], true) {
            return Err(format!(
                "node {n} is reached twice in {scene_name}: glTF nodes must form a tree"
            ));
        }
        let node = &nodes[n];
        let local = raw
            .nodes
            .get(n)
            .ok_or_else(|| format!("node {n} is missing from the JSON"))?
            .local()
            .map_err(|m| format!("node {n}: {m}"))?;
        let world = parent * local;
        for c in node.children().collect::<Vec<_>>().iter().rev() {
            stack.push((c.index(), world));
        }
        if let Some(mesh) = node.mesh() {
            skinned |= node.skin().is_some();
            match check_placement(&world) {
                Ok(()) => placements.push((n, mesh.index(), world)),
                Err(why) => notes.push(format!(
                    "node {n}{}: {why}; its mesh is not drawn",
                    named(node.name())
                )),
            }
        }
        if let Some(camera) = node.camera() {
            match camera_of(&doc, camera.index(), world) {
                Ok(c) => cameras.push(c),
                Err(why) => notes.push(format!(
                    "camera {} (node {n}{}) is left out: {why}",
                    camera.index(),
                    named(node.name())
                )),
            }
        }
    }
    if skinned {
        notes.push("skins are not applied: skinned meshes are drawn as they stand".into());
    }

    let mut meshes = Vec::new();
    let mut index_of: HashMap<usize, Option<usize>> = HashMap::new();
    let mut instances = Vec::new();
    for (_, m, world) in placements {
        let ours = match index_of.get(&m) {
            Some(&ours) => ours,
            None => {
                let built = build_mesh(&doc, &buffers, m, &mut notes)?;
                let ours = built.map(|b| {
                    meshes.push(b);
                    meshes.len() - 1
                });
                index_of.insert(m, ours);
                ours
            }
        };
        if let Some(ours) = ours {
            instances.push((ours, world));
        }
    }
    if instances.is_empty() {
        return Err(format!(
            "{scene_name} has no triangles to draw (no node with a mesh of triangle primitives)"
        ));
    }
    Ok(Document {
        meshes,
        instances,
        cameras,
        notes,
    })
}

/// ` 'name'` for messages, or nothing.
fn named(name: Option<&str>) -> String {
    name.map(|n| format!(" '{n}'")).unwrap_or_default()
}

/// Whether a node's world transform can place a mesh: finite, affine and not singular.
fn check_placement(t: &DMat4) -> FileResult<()> {
    if !t.is_finite() {
        return Err("its transform has a non-finite entry".into());
    }
    if t.row(3) != DVec4::W {
        return Err("its transform is not affine".into());
    }
    if !(t.determinant().abs() > 0.0) {
        return Err("its transform is singular (a zero scale)".into());
    }
    Ok(())
}

/// Camera `index` of the file, placed by `world`, checked.
fn camera_of(doc: &gltf::Document, index: usize, world: DMat4) -> FileResult<GltfCamera> {
    use gltf::json::camera::Type;
    use gltf::json::validation::Checked;
    let json = &doc.as_json().cameras[index];
    let projection = match (&json.type_, &json.perspective, &json.orthographic) {
        (Checked::Valid(Type::Perspective), Some(p), _) => GltfProjection::Perspective {
            yfov: f64::from(p.yfov),
            aspect_ratio: p.aspect_ratio.map(f64::from),
            znear: f64::from(p.znear),
            zfar: p.zfar.map(f64::from),
        },
        (Checked::Valid(Type::Orthographic), _, Some(o)) => GltfProjection::Orthographic {
            // The specification says the magnifications should not be negative; a
            // negative one would mirror the image, so its size is what is used.
            xmag: f64::from(o.xmag).abs(),
            ymag: f64::from(o.ymag).abs(),
            znear: f64::from(o.znear),
            zfar: f64::from(o.zfar),
        },
        _ => return Err("its type has no matching perspective or orthographic object".into()),
    };
    match projection {
        GltfProjection::Perspective {
            yfov,
            aspect_ratio,
            znear,
            zfar,
        } => {
            if !(yfov > 0.0 && yfov < std::f64::consts::PI) {
                return Err(format!("yfov {yfov} is not in (0, π)"));
            }
            if let Some(a) = aspect_ratio {
                if !(a > 0.0 && a.is_finite()) {
                    return Err(format!("aspectRatio {a} is not > 0"));
                }
            }
            if !(znear > 0.0 && znear.is_finite()) {
                return Err(format!("znear {znear} is not > 0"));
            }
            if let Some(f) = zfar {
                if !(f > znear && f.is_finite()) {
                    return Err(format!("zfar {f} is not > znear {znear}"));
                }
            }
        }
        GltfProjection::Orthographic {
            xmag,
            ymag,
            znear,
            zfar,
        } => {
            for (name, v) in [("xmag", xmag), ("ymag", ymag)] {
                if !(v > 0.0 && v.is_finite()) {
                    return Err(format!("{name} {v} is not a non-zero number"));
                }
            }
            if !(znear >= 0.0 && zfar > znear && zfar.is_finite()) {
                return Err(format!(
                    "znear {znear} and zfar {zfar} are not 0 <= znear < zfar"
                ));
            }
        }
    }
    let forward = world.z_axis.truncate();
    let up = world.y_axis.truncate();
    if !world.is_finite() || forward.cross(up).length() <= 1e-12 * forward.length() * up.length() {
        return Err("its node's transform gives no view direction".into());
    }
    let camera = GltfCamera {
        transform: world,
        projection,
    };
    camera.view(1.0).validate().map_err(|e| e.to_string())?;
    Ok(camera)
}
