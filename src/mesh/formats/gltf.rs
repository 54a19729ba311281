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
//! [`GltfMesh::line_width`]; wirepass draws one width per object, so a mesh whose
//! primitives disagree takes the first and says so in a note. Dash patterns are not drawn.

// `!(a > b)` is deliberate throughout: NaN must take the rejecting branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::read::{file_error, io_error, open};
use crate::camera::{DepthRange, View};
use crate::error::{Error, Result};
use crate::mesh::adjacency::NO_NEIGHBOUR;
use crate::mesh::{EdgeSelection, Mesh};
use glam::dcamera::rh::{proj::directx as proj, view::look_at_mat4};
use glam::{DMat3, DMat4, DQuat, DVec3, DVec4, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::{Mode, Semantic};
use serde_json::Value;
use std::borrow::Cow;
use std::collections::{HashMap, HashSet};
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

type FileResult<T> = std::result::Result<T, String>;

/// Loads a glTF file's scene. Every problem of the file is an [`Error::MeshFile`] naming
/// it (a missing external buffer too); a scene without a triangle to draw is one as well.
pub fn load_gltf(path: &Path) -> Result<Document> {
    let (mut file, len) = open(path, "a glTF")?;
    // The length only sizes the read: a file that grows or shrinks meanwhile still reads.
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    file.read_to_end(&mut bytes)
        .map_err(|e| io_error(path, e))?;
    parse(path, &bytes).map_err(|message| file_error(path, None, message))
}

/// Loads a glTF file as one mesh, for where one mesh is wanted (`mesh::load`, scene
/// files): a scene of one untransformed instance is its mesh; otherwise every instance is
/// moved to where its node puts it and the copies are concatenated in node order (edges,
/// outline masks and all). Cameras, notes and line widths are left out: load the file with
/// [`load_gltf`] for them.
pub fn load_gltf_mesh(path: &Path) -> Result<Mesh> {
    let mut doc = load_gltf(path)?;
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

fn parse(path: &Path, bytes: &[u8]) -> FileResult<Document> {
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
    let buffers = Buffers::load(path, &doc, blob)?;
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

/// The bytes of every buffer of the file.
struct Buffers<'a> {
    data: Vec<Cow<'a, [u8]>>,
    /// All their bytes together: a bound for accessors without a buffer view.
    total: usize,
}

impl<'a> Buffers<'a> {
    fn load(
        path: &Path,
        doc: &gltf::Document,
        blob: Option<Cow<'a, [u8]>>,
    ) -> FileResult<Buffers<'a>> {
        let mut blob = blob;
        let mut data = Vec::new();
        for buffer in doc.buffers() {
            let i = buffer.index();
            let bytes: Cow<[u8]> = match buffer.source() {
                gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                    format!("buffer {i} is the GLB binary chunk, which the file lacks")
                })?,
                gltf::buffer::Source::Uri(uri) => {
                    Cow::Owned(read_uri(path, uri).map_err(|m| format!("buffer {i}: {m}"))?)
                }
            };
            if bytes.len() < buffer.length() {
                return Err(format!(
                    "buffer {i} declares {} bytes, but has {}",
                    buffer.length(),
                    bytes.len()
                ));
            }
            data.push(bytes);
        }
        let total = data.iter().map(|d| d.len()).sum();
        Ok(Buffers { data, total })
    }

    /// The bytes of a buffer view, checked against its buffer.
    fn view(&self, view: &gltf::buffer::View) -> FileResult<&[u8]> {
        let buffer = &self.data[view.buffer().index()];
        let (start, length) = (view.offset(), view.length());
        start
            .checked_add(length)
            .and_then(|end| buffer.get(start..end))
            .ok_or_else(|| {
                format!(
                    "buffer view {}: bytes {start} to {} run past buffer {}'s {} bytes",
                    view.index(),
                    start as u128 + length as u128,
                    view.buffer().index(),
                    buffer.len()
                )
            })
    }

    /// Every element of `accessor`, each through `convert` (given the element's bytes),
    /// with sparse substitutions applied. Sizes are checked before anything is allocated.
    fn read<T: Clone>(
        &self,
        accessor: &gltf::Accessor,
        convert: impl Fn(&[u8]) -> T,
    ) -> FileResult<Vec<T>> {
        let a = accessor.index();
        let count = accessor.count();
        let size = accessor.size();
        let mut out = match accessor.view() {
            Some(view) => {
                let bytes = self.view(&view)?;
                let stride = view.stride().unwrap_or(size);
                if stride < size {
                    return Err(format!(
                        "accessor {a}: buffer view {} has a stride of {stride} bytes, less than an element's {size}",
                        view.index()
                    ));
                }
                let offset = accessor.offset();
                let end = if count == 0 {
                    Some(offset)
                } else {
                    (count - 1)
                        .checked_mul(stride)
                        .and_then(|b| b.checked_add(size))
                        .and_then(|b| b.checked_add(offset))
                };
                let data = end.and_then(|end| bytes.get(offset..end)).ok_or_else(|| {
                    format!(
                        "accessor {a}: {count} elements of {size} bytes (stride {stride}) from byte {offset} run past the {} bytes of buffer view {}",
                        bytes.len(),
                        view.index()
                    )
                })?;
                (0..count)
                    .map(|i| convert(&data[i * stride..i * stride + size]))
                    .collect()
            }
            None => {
                // All zeros (then the sparse values): nothing bounds the count but the
                // file's own size, as every element is worth at least a byte somewhere.
                if count > self.total.max(1 << 16) {
                    return Err(format!(
                        "accessor {a} declares {count} elements without a buffer view, more than the file's {} buffer bytes",
                        self.total
                    ));
                }
                vec![convert(&vec![0u8; size]); count]
            }
        };
        if let Some(sparse) = accessor.sparse() {
            let n = sparse.count();
            let indices = sparse.indices();
            let index_size = indices.index_type().size();
            let index_bytes = self.view(&indices.view())?;
            let value_bytes = self.view(&sparse.values().view())?;
            let slice = |bytes: &'_ [u8], offset: usize, each: usize, what: &str| {
                n.checked_mul(each)
                    .and_then(|l| l.checked_add(offset))
                    .and_then(|end| bytes.get(offset..end).map(<[u8]>::to_vec))
                    .ok_or_else(|| {
                        format!("accessor {a}: {n} sparse {what} run past their buffer view")
                    })
            };
            let ib = slice(index_bytes, indices.offset(), index_size, "indices")?;
            let vb = slice(value_bytes, sparse.values().offset(), size, "values")?;
            for k in 0..n {
                let i = read_index(&ib[k * index_size..(k + 1) * index_size]);
                let slot = out.get_mut(i as usize).ok_or_else(|| {
                    format!("accessor {a}: sparse index {i} is past its {count} elements")
                })?;
                *slot = convert(&vb[k * size..(k + 1) * size]);
            }
        }
        Ok(out)
    }

    /// A vertex attribute of three components as f32: floats, or the integer types
    /// `KHR_mesh_quantization` allows, normalized or not.
    fn read_vec3(&self, accessor: &gltf::Accessor, what: &str) -> FileResult<Vec<Vec3>> {
        if accessor.dimensions() != Dimensions::Vec3 {
            return Err(format!(
                "{what} accessor {} is {:?}, not VEC3",
                accessor.index(),
                accessor.dimensions()
            ));
        }
        let component =
            component_reader(accessor.data_type(), accessor.normalized()).ok_or_else(|| {
                format!(
                    "{what} accessor {} has components of type {:?}{}, which glTF does not allow",
                    accessor.index(),
                    accessor.data_type(),
                    if accessor.normalized() {
                        " (normalized)"
                    } else {
                        ""
                    }
                )
            })?;
        let w = accessor.data_type().size();
        self.read(accessor, |e| {
            Vec3::new(
                component(&e[..w]),
                component(&e[w..2 * w]),
                component(&e[2 * w..]),
            )
        })
    }

    /// Unsigned integer scalars (indices), widened to u32.
    fn read_indices(&self, accessor: &gltf::Accessor, what: &str) -> FileResult<Vec<u32>> {
        let ok = accessor.dimensions() == Dimensions::Scalar
            && matches!(
                accessor.data_type(),
                DataType::U8 | DataType::U16 | DataType::U32
            );
        if !ok {
            return Err(format!(
                "{what} accessor {} is {:?} of {:?}, not unsigned byte, short or int scalars",
                accessor.index(),
                accessor.dimensions(),
                accessor.data_type()
            ));
        }
        self.read(accessor, read_index)
    }
}

/// A little-endian unsigned integer of 1, 2 or 4 bytes.
fn read_index(b: &[u8]) -> u32 {
    match *b {
        [x] => u32::from(x),
        [x, y] => u32::from(u16::from_le_bytes([x, y])),
        [x, y, z, w] => u32::from_le_bytes([x, y, z, w]),
        _ => 0,
    }
}

/// How to read one component of a vertex attribute as f32 (normalized integers as the glTF
/// specification maps them: signed ones to [−1, 1], unsigned ones to [0, 1]).
fn component_reader(ty: DataType, normalized: bool) -> Option<fn(&[u8]) -> f32> {
    Some(match (ty, normalized) {
        (DataType::F32, false) => |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (DataType::I8, false) => |b| f32::from(b[0] as i8),
        (DataType::I8, true) => |b| (f32::from(b[0] as i8) / 127.0).max(-1.0),
        (DataType::U8, false) => |b| f32::from(b[0]),
        (DataType::U8, true) => |b| f32::from(b[0]) / 255.0,
        (DataType::I16, false) => |b| f32::from(i16::from_le_bytes([b[0], b[1]])),
        (DataType::I16, true) => {
            |b| (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0)
        }
        (DataType::U16, false) => |b| f32::from(u16::from_le_bytes([b[0], b[1]])),
        (DataType::U16, true) => |b| f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0,
        _ => return None,
    })
}

/// Reads a buffer's URI: a base64 `data:` URI, or a file relative to the glTF file's
/// folder (percent-encoded, as URIs are).
fn read_uri(path: &Path, uri: &str) -> FileResult<Vec<u8>> {
    use base64::Engine as _;
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or("a data: URI that is not base64")?;
        let engine = base64::engine::GeneralPurpose::new(
            &base64::alphabet::STANDARD,
            base64::engine::GeneralPurposeConfig::new()
                .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
        );
        return engine
            .decode(data.trim_end())
            .map_err(|e| format!("its data: URI is not valid base64 ({e})"));
    }
    if let Some((scheme, _)) = uri.split_once(':') {
        // A scheme is letters and digits (and + - .) before the colon; a Windows drive
        // letter alone is a path.
        if scheme.len() > 1
            && scheme
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
        {
            return Err(format!(
                "'{uri}': {scheme}: URIs are not read, only files and data: URIs"
            ));
        }
    }
    let decoded = urlencoding::decode(uri)
        .map_err(|_| format!("'{uri}' is not UTF-8 once percent-decoded"))?;
    let file = path.parent().unwrap_or(Path::new(".")).join(&*decoded);
    std::fs::read(&file).map_err(|e| format!("cannot read '{}': {e}", file.display()))
}

/// An edge's visibility level, how much the file wants it drawn: 0 hidden, 1 silhouette
/// (the edge extension's own codes), 2 hard.
const HIDDEN: u8 = 0;
const HARD: u8 = 2;
/// Triangles of primitives without edge data.
const UNAUTHORED: u8 = u8::MAX;

/// What one glTF mesh is being turned into.
#[derive(Default)]
struct Builder {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    any_normals: bool,
    triangles: Vec<[u32; 3]>,
    /// Per triangle, each edge's visibility level, once any primitive has edge data.
    levels: Option<Vec<[u8; 3]>>,
    line_width: Option<f32>,
}

fn build_mesh(
    doc: &gltf::Document,
    buffers: &Buffers,
    index: usize,
    notes: &mut Vec<String>,
) -> FileResult<Option<GltfMesh>> {
    let Some(mesh) = doc.meshes().nth(index) else {
        return Err(format!("mesh {index} does not exist"));
    };
    let name = mesh
        .name()
        .map(str::to_owned)
        .unwrap_or_else(|| format!("mesh {index}"));
    let what = format!("mesh {index}{}", named(mesh.name()));
    let mut b = Builder::default();
    // Primitives that share vertex accessors share vertices.
    let mut bases: HashMap<(usize, Option<usize>), u32> = HashMap::new();
    let mut widths = Vec::new();
    for p in mesh.primitives() {
        let at = format!("{what}, primitive {}", p.index());
        let mode = p.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            let name = match mode {
                Mode::Points => "POINTS",
                Mode::Lines => "LINES",
                Mode::LineLoop => "LINE_LOOP",
                _ => "LINE_STRIP",
            };
            notes.push(format!("{at}: mode {name} is not triangles; skipped"));
            continue;
        }
        if p.morph_targets().next().is_some() {
            notes.push(format!("{at}: morph targets are not applied"));
        }
        let position = p
            .get(&Semantic::Positions)
            .ok_or_else(|| format!("{at} has no POSITION"))?;
        let normal = p.get(&Semantic::Normals);
        let key = (position.index(), normal.as_ref().map(|n| n.index()));
        let vertices = position.count();
        let base = match bases.get(&key) {
            Some(&base) => base,
            None => {
                let base = b.positions.len();
                let positions = buffers
                    .read_vec3(&position, "POSITION")
                    .map_err(|m| format!("{at}: {m}"))?;
                let normals = match &normal {
                    Some(n) => {
                        let normals = buffers
                            .read_vec3(n, "NORMAL")
                            .map_err(|m| format!("{at}: {m}"))?;
                        if normals.len() != positions.len() {
                            return Err(format!(
                                "{at}: {} normals for {} positions",
                                normals.len(),
                                positions.len()
                            ));
                        }
                        Some(normals)
                    }
                    None => None,
                };
                b.positions.extend_from_slice(&positions);
                // Vertices without normals get NaN ones, filled with smooth normals once the
                // triangles are known; none are kept until some primitive has normals.
                match normals {
                    Some(n) => {
                        b.normals.resize(base, Vec3::NAN);
                        b.normals.extend(n);
                        b.any_normals = true;
                    }
                    None if b.any_normals => b.normals.resize(b.positions.len(), Vec3::NAN),
                    None => {}
                }
                let base = u32::try_from(base)
                    .ok()
                    .filter(|_| b.positions.len() <= u32::MAX as usize)
                    .ok_or_else(|| format!("{what} has more vertices than u32 indices reach"))?;
                bases.insert(key, base);
                base
            }
        };
        // The index list lives only until it is cut into triangles: on large meshes it is
        // as big as they are.
        let indices = match p.indices() {
            Some(acc) => {
                let indices = buffers
                    .read_indices(&acc, "indices")
                    .map_err(|m| format!("{at}: {m}"))?;
                if let Some((k, &v)) = indices
                    .iter()
                    .enumerate()
                    .find(|&(_, &v)| v as usize >= vertices)
                {
                    return Err(format!(
                        "{at}: index {k} refers to vertex {v}, but the primitive has {vertices} vertices"
                    ));
                }
                indices
            }
            None => (0..u32::try_from(vertices).map_err(|_| format!("{at}: too many vertices"))?)
                .collect(),
        };
        let tris = triangles(mode, &indices, &at, notes);
        drop(indices);
        let first = b.triangles.len();
        let count = tris.len();

        // Edge data of this primitive: levels per triangle edge, or none.
        let mut levels: Option<Vec<[u8; 3]>> = None;
        if let Some(ext) = p.extension_value("EXT_mesh_primitive_edge_visibility") {
            let l = edge_visibility(doc, buffers, ext, &tris, count)
                .map_err(|m| format!("{at}: EXT_mesh_primitive_edge_visibility: {m}"))?;
            levels = Some(l);
        }
        if let Some(ext) = p.extension_value("CESIUM_primitive_outline") {
            let listed = outline_pairs(doc, buffers, ext)
                .map_err(|m| format!("{at}: CESIUM_primitive_outline: {m}"))?;
            let l = levels.get_or_insert_with(|| vec![[HIDDEN; 3]; count]);
            mark_pairs(l, &tris, &listed);
        }
        if let Some(l) = levels {
            let all = b.levels.get_or_insert_with(|| vec![[UNAUTHORED; 3]; first]);
            all.extend(l);
        } else if let Some(all) = &mut b.levels {
            all.resize(first + count, [UNAUTHORED; 3]);
        }
        if first == 0 && base == 0 {
            b.triangles = tris;
        } else {
            b.triangles.extend(tris.iter().map(|t| t.map(|v| v + base)));
        }
        if let Some(w) = line_width(doc, &p, notes, &at) {
            widths.push(w);
        }
    }
    if b.triangles.is_empty() {
        notes.push(format!("{what} has no triangles; its nodes are not drawn"));
        return Ok(None);
    }
    if let Some(&w) = widths.first() {
        if widths.iter().any(|&x| x != w) {
            notes.push(format!(
                "{what}: its primitives ask for line widths {widths:?}; one width is drawn per object: {w}"
            ));
        }
        b.line_width = Some(w);
    }
    finish(b, &what, name).map(Some)
}

/// Triangles of a primitive's index list in the order §3.7.2.1 of the glTF specification
/// gives (the order the edge extensions count by): strips alternate their winding, fans
/// turn around the first vertex.
fn triangles(mode: Mode, idx: &[u32], at: &str, notes: &mut Vec<String>) -> Vec<[u32; 3]> {
    match mode {
        Mode::TriangleStrip => (0..idx.len().saturating_sub(2))
            .map(|i| {
                let odd = i % 2;
                [idx[i], idx[i + 1 + odd], idx[i + 2 - odd]]
            })
            .collect(),
        Mode::TriangleFan => (0..idx.len().saturating_sub(2))
            .map(|i| [idx[i + 1], idx[i + 2], idx[0]])
            .collect(),
        _ => {
            if !idx.len().is_multiple_of(3) {
                notes.push(format!(
                    "{at}: {} indices are not whole triangles; the last {} are ignored",
                    idx.len(),
                    idx.len() % 3
                ));
            }
            idx.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
        }
    }
}

/// An accessor named by an extension's property.
fn accessor_at<'d>(
    doc: &'d gltf::Document,
    value: &Value,
    name: &str,
) -> FileResult<gltf::Accessor<'d>> {
    let i = value
        .get(name)
        .ok_or_else(|| format!("no {name}"))?
        .as_u64()
        .ok_or_else(|| format!("{name} is not an accessor index"))?;
    usize::try_from(i)
        .ok()
        .and_then(|i| doc.accessors().nth(i))
        .ok_or_else(|| format!("{name}: accessor {i} does not exist"))
}

/// Per triangle edge, the visibility levels an `EXT_mesh_primitive_edge_visibility` object
/// gives (its `visibility` bits, and its `lineStrings` as hard edges).
fn edge_visibility(
    doc: &gltf::Document,
    buffers: &Buffers,
    ext: &Value,
    tris: &[[u32; 3]],
    count: usize,
) -> FileResult<Vec<[u8; 3]>> {
    let mut levels = vec![[HIDDEN; 3]; count];
    if ext.get("visibility").is_some() {
        let acc = accessor_at(doc, ext, "visibility")?;
        if acc.dimensions() != Dimensions::Scalar || acc.data_type() != DataType::U8 {
            return Err(format!(
                "visibility accessor {} is not unsigned byte scalars",
                acc.index()
            ));
        }
        let need = (6 * count).div_ceil(8);
        if acc.count() < need {
            return Err(format!(
                "visibility accessor {} has {} bytes; {count} triangles need {need}",
                acc.index(),
                acc.count()
            ));
        }
        let bits = buffers.read(&acc, |b| b[0])?;
        for (t, l) in levels.iter_mut().enumerate() {
            for (k, level) in l.iter_mut().enumerate() {
                let bit = 6 * t + 2 * k;
                // 3, a repeated hard edge, is hard too.
                *level = ((bits[bit / 8] >> (bit % 8)) & 3).min(HARD);
            }
        }
    }
    if let Some(strings) = ext.get("lineStrings") {
        let strings = strings.as_array().ok_or("lineStrings is not a list")?;
        let mut pairs = HashSet::new();
        for (s, string) in strings.iter().enumerate() {
            let acc = accessor_at(doc, string, "indices")
                .map_err(|m| format!("lineStrings[{s}]: {m}"))?;
            let restart = match acc.data_type() {
                DataType::U8 => u32::from(u8::MAX),
                DataType::U16 => u32::from(u16::MAX),
                _ => u32::MAX,
            };
            let idx = buffers.read_indices(&acc, "lineStrings")?;
            for w in idx.windows(2) {
                if w[0] != restart && w[1] != restart {
                    pairs.insert(edge_key(w[0], w[1]));
                }
            }
        }
        mark_pairs(&mut levels, tris, &pairs);
    } else if ext.get("visibility").is_none() {
        return Err("neither visibility nor lineStrings".into());
    }
    Ok(levels)
}

/// The vertex pairs a `CESIUM_primitive_outline` object lists.
fn outline_pairs(
    doc: &gltf::Document,
    buffers: &Buffers,
    ext: &Value,
) -> FileResult<HashSet<(u32, u32)>> {
    let acc = accessor_at(doc, ext, "indices")?;
    let idx = buffers.read_indices(&acc, "indices")?;
    if !idx.len().is_multiple_of(2) {
        return Err(format!("{} indices do not make pairs", idx.len()));
    }
    Ok(idx.chunks_exact(2).map(|p| edge_key(p[0], p[1])).collect())
}

fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Raises the edges whose vertex pairs (the primitive's own indices) are listed to hard.
fn mark_pairs(levels: &mut [[u8; 3]], tris: &[[u32; 3]], pairs: &HashSet<(u32, u32)>) {
    if pairs.is_empty() {
        return;
    }
    for (l, t) in levels.iter_mut().zip(tris) {
        for k in 0..3 {
            if pairs.contains(&edge_key(t[k], t[(k + 1) % 3])) {
                l[k] = HARD;
            }
        }
    }
}

/// The width `BENTLEY_materials_line_style` gives the primitive's edges, if any.
fn line_width(
    doc: &gltf::Document,
    p: &gltf::Primitive,
    notes: &mut Vec<String>,
    at: &str,
) -> Option<f32> {
    let edge_material = p
        .extension_value("EXT_mesh_primitive_edge_visibility")
        .and_then(|e| e.get("material"))
        .and_then(Value::as_u64)
        .and_then(|i| doc.materials().nth(usize::try_from(i).ok()?));
    let material = edge_material.unwrap_or_else(|| p.material());
    let style = material.extension_value("BENTLEY_materials_line_style")?;
    if let Some(pattern) = style.get("pattern").and_then(Value::as_u64) {
        if pattern & 0xffff != 0xffff {
            notes.push(format!(
                "{at}: the dash pattern {pattern:#06x} is not drawn; lines are solid"
            ));
        }
    }
    let width = style.get("width")?.as_f64();
    match width {
        Some(w) if w > 0.0 && w <= f64::from(crate::style::MAX_LINE_WIDTH) => Some(w as f32),
        _ => {
            notes.push(format!(
                "{at}: line width {} is not in (0, {}] pixels; ignored",
                style.get("width").map(Value::to_string).unwrap_or_default(),
                crate::style::MAX_LINE_WIDTH
            ));
            None
        }
    }
}

/// Builds the mesh, then its authored edge masks from the levels.
fn finish(b: Builder, what: &str, name: String) -> FileResult<GltfMesh> {
    let Builder {
        positions,
        mut normals,
        any_normals,
        triangles,
        levels,
        line_width,
    } = b;
    let invalid = |e: Error| match e {
        Error::InvalidMesh(m) => format!("{what}: {m}"),
        e => format!("{what}: {e}"),
    };
    let normals = if any_normals {
        if normals.iter().any(|n| n.x.is_nan()) {
            let smooth = crate::mesh::smooth_normals(&positions, &triangles);
            for (n, s) in normals.iter_mut().zip(smooth) {
                if n.x.is_nan() {
                    *n = s;
                }
            }
        }
        Some(normals)
    } else {
        None
    };
    let mut mesh = Mesh::new(positions, normals, triangles, None).map_err(invalid)?;
    let mut edges = None;
    if let Some(levels) = levels {
        let levels = shared_levels(&levels, mesh.edge_neighbours());
        let mask = |keep: fn(u8) -> bool| -> Vec<u8> {
            levels
                .iter()
                .map(|l| (0..3).filter(|&k| keep(l[k])).fold(0, |m, k| m | 1 << k))
                .collect()
        };
        let drawn = mask(|l| l == HARD || l == UNAUTHORED);
        let outline = mask(|l| l != HIDDEN);
        mesh = mesh
            .with_authored_edges(drawn)
            .and_then(|m| m.with_outline_mask(outline))
            .map_err(invalid)?;
        edges = Some(EdgeSelection::Authored);
    }
    Ok(GltfMesh {
        mesh,
        name,
        edges,
        line_width,
    })
}

/// Each edge's level raised to the most visible of its occurrences: the triangle across it
/// (by the mesh's adjacency) may hold the one the file wrote. Triangles without edge data
/// neither give nor take.
fn shared_levels(levels: &[[u8; 3]], neighbours: &[[u32; 3]]) -> Vec<[u8; 3]> {
    levels
        .iter()
        .enumerate()
        .map(|(t, l)| {
            let mut out = *l;
            for k in 0..3 {
                let n = neighbours[t][k];
                if l[k] == UNAUTHORED || n == NO_NEIGHBOUR {
                    continue;
                }
                for j in 0..3 {
                    let across = levels[n as usize][j];
                    if neighbours[n as usize][j] == t as u32 && across != UNAUTHORED {
                        out[k] = out[k].max(across);
                    }
                }
            }
            out
        })
        .collect()
}
