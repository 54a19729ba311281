//! What the page shows: the built-in scene, or a mesh file read from its bytes (a browser has
//! no file system: files come by the file picker or drag and drop).

use std::collections::HashMap;
use std::path::Path;
use wirepass::glam::{DMat4, DVec3};
use wirepass::mesh::formats::gltf::load_gltf_bytes;
use wirepass::{EdgeSelection, Mesh};

/// The files a `.gltf` names beside it (its external buffers), by URI as it writes them.
pub type Resources = HashMap<String, Vec<u8>>;

/// Meshes placed as instances, as a file describes them.
pub struct Model {
    /// The file's name, or "the built-in scene".
    pub name: String,
    /// Each mesh with the edges its file asks for (`None`: its polygon edges).
    pub meshes: Vec<(Mesh, Option<EdgeSelection>)>,
    /// Placements: an index into `meshes` and the model → world transform.
    pub instances: Vec<(usize, DMat4)>,
}

impl Model {
    /// The torus and sphere that `wirepass render` draws when given no mesh.
    pub fn builtin() -> Result<Model, wirepass::Error> {
        let parts = wirepass::mesh::default_parts()?;
        Ok(Model {
            name: "the built-in scene".into(),
            instances: (0..parts.len()).map(|i| (i, parts[i].1)).collect(),
            meshes: parts.into_iter().map(|(m, _)| (m, None)).collect(),
        })
    }

    /// Reads a `.glb`, `.gltf`, `.obj`, `.stl` or `.ply` file, the loader chosen by `name`'s
    /// extension; a `.gltf`'s external buffers come from `resources`, by their URI as the
    /// file writes it. A glTF scene keeps its instances and authored edges; every other
    /// format is one mesh at the origin.
    pub fn from_file(
        name: &str,
        bytes: &[u8],
        resources: &Resources,
    ) -> Result<Model, wirepass::Error> {
        let path = Path::new(name);
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if matches!(ext.as_deref(), Some("gltf" | "glb")) {
            let doc = load_gltf_bytes(path, bytes, &mut |uri: &str| match resources.get(uri) {
                Some(bytes) => Ok(bytes.clone()),
                None if resources.is_empty() => Err(format!(
                    "names the external buffer {uri:?}, which a page cannot fetch beside a \
                     dropped file: use a .glb, or a .gltf with its buffers embedded"
                )),
                None => Err(format!(
                    "names the external buffer {uri:?}, which was not fetched"
                )),
            })?;
            return Ok(Model {
                name: name.into(),
                meshes: doc.meshes.into_iter().map(|m| (m.mesh, m.edges)).collect(),
                instances: doc.instances,
            });
        }
        Ok(Model {
            name: name.into(),
            meshes: vec![(wirepass::mesh::load_bytes(path, bytes)?, None)],
            instances: vec![(0, DMat4::IDENTITY)],
        })
    }

    /// Triangles over all instances.
    pub fn triangles(&self) -> u64 {
        let per_mesh = |i: usize| self.meshes[i].0.triangle_count() as u64;
        self.instances.iter().map(|&(m, _)| per_mesh(m)).sum()
    }

    /// World bounds: every instance's mesh box, transformed.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let placed = self
            .instances
            .iter()
            .map(|&(m, transform)| self.meshes[m].0.placed_bounds(transform));
        placed.fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
        )
    }
}
