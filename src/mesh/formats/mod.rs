//! The mesh file loaders (OBJ, STL, PLY, glTF), and one entry point for them: the loader is
//! chosen by the file's extension, from a table that a new format joins with one row. Each
//! loader builds on the helpers in `read.rs` and on [`crate::mesh`], never on this table.

pub mod gltf;
mod obj;
mod ply;
mod read;
mod stl;

pub use gltf::{load_gltf, load_gltf_bytes, load_gltf_mesh, load_gltf_mesh_bytes, Resolver};
pub use obj::{load_obj, load_obj_bytes};
pub use ply::{load_ply, load_ply_bytes};
pub use stl::{load_stl, load_stl_bytes};

use crate::error::Result;
use crate::mesh::Mesh;
use read::{file_error, io_error};
use std::path::Path;

/// A mesh file format that [`load`] reads.
#[derive(Clone, Copy, Debug)]
pub struct Format {
    /// The file extension, lower case, without the dot.
    pub extension: &'static str,
    /// The format's name, as error messages say it.
    pub name: &'static str,
    /// The loader.
    pub load: fn(&Path) -> Result<Mesh>,
    /// The loader of a file's bytes, the path only naming the file in errors.
    pub load_bytes: fn(&Path, &[u8]) -> Result<Mesh>,
}

/// The formats [`load`] reads, by extension.
pub const FORMATS: &[Format] = &[
    Format {
        extension: "obj",
        name: "OBJ",
        load: obj::load_obj,
        load_bytes: obj::load_obj_bytes,
    },
    Format {
        extension: "stl",
        name: "STL",
        load: stl::load_stl,
        load_bytes: stl::load_stl_bytes,
    },
    Format {
        extension: "ply",
        name: "PLY",
        load: ply::load_ply,
        load_bytes: ply::load_ply_bytes,
    },
    Format {
        extension: "gltf",
        name: "glTF",
        load: gltf::load_gltf_mesh,
        load_bytes: gltf_mesh_alone,
    },
    Format {
        extension: "glb",
        name: "glTF",
        load: gltf::load_gltf_mesh,
        load_bytes: gltf_mesh_alone,
    },
];

/// A glTF scene as one mesh from its bytes alone: a `.glb`, or a `.gltf` whose buffers are
/// `data:` URIs; one that names external buffers needs [`load_gltf_mesh_bytes`] and a
/// resolver for them.
fn gltf_mesh_alone(name: &Path, bytes: &[u8]) -> Result<Mesh> {
    let mut none = |buffer: &str| {
        Err(format!(
            "its buffer '{buffer}' is a separate file, which loading from bytes cannot read \
             (load_gltf_mesh_bytes takes a resolver for it)"
        ))
    };
    load_gltf_mesh_bytes(name, bytes, &mut none)
}

/// The format of `path` by its extension, compared case-insensitively.
pub fn format_of(path: &Path) -> Option<&'static Format> {
    let extension = path.extension()?.to_str()?;
    FORMATS
        .iter()
        .find(|f| f.extension.eq_ignore_ascii_case(extension))
}

/// Loads a mesh file with the loader its extension names (`.obj`, `.stl`, `.ply`, `.gltf`,
/// `.glb`, in any case; a glTF scene comes as one mesh: see
/// [`load_gltf_mesh`]). A missing file is an [`Error::Io`](crate::Error::Io); an unknown
/// extension is an [`Error::MeshFile`](crate::Error::MeshFile) that names the supported ones.
pub fn load(path: &Path) -> Result<Mesh> {
    if let Some(format) = format_of(path) {
        return (format.load)(path);
    }
    // A missing file says so, whatever its name.
    std::fs::metadata(path).map_err(|e| io_error(path, e))?;
    Err(unknown_format(path))
}

/// The error for a name whose extension names no format: the supported ones.
fn unknown_format(path: &Path) -> crate::Error {
    let supported: Vec<String> = FORMATS
        .iter()
        .map(|f| format!(".{}", f.extension))
        .collect();
    let what = match path.extension() {
        Some(e) => format!("unknown mesh file extension '.{}'", e.to_string_lossy()),
        None => "no file extension to tell the mesh format".to_owned(),
    };
    file_error(
        path,
        None,
        format!("{what}; wirepass reads {}", supported.join(", ")),
    )
}

/// [`load`] from the bytes of a file, as a browser gets them (by drag and drop or `fetch`):
/// the loader is the one `name`'s extension names, and the errors are the ones the file
/// would give, naming `name`. A `.gltf` that names external buffers needs
/// [`load_gltf_mesh_bytes`] with a resolver for them.
pub fn load_bytes(name: &Path, bytes: &[u8]) -> Result<Mesh> {
    match format_of(name) {
        Some(format) => (format.load_bytes)(name, bytes),
        None => Err(unknown_format(name)),
    }
}
