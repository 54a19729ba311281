//! One entry point for mesh files: the loader is chosen by the file's extension, from a
//! table that a new format joins with one row.

use super::Mesh;
use crate::error::{Error, Result};
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
}

/// The formats [`load`] reads, by extension.
pub const FORMATS: &[Format] = &[
    Format {
        extension: "obj",
        name: "OBJ",
        load: super::obj::load_obj,
    },
    Format {
        extension: "stl",
        name: "STL",
        load: super::stl::load_stl,
    },
    Format {
        extension: "ply",
        name: "PLY",
        load: super::ply::load_ply,
    },
    Format {
        extension: "gltf",
        name: "glTF",
        load: super::gltf::load_gltf_mesh,
    },
    Format {
        extension: "glb",
        name: "glTF",
        load: super::gltf::load_gltf_mesh,
    },
];

/// The format of `path` by its extension, compared case-insensitively.
pub fn format_of(path: &Path) -> Option<&'static Format> {
    let extension = path.extension()?.to_str()?;
    FORMATS
        .iter()
        .find(|f| f.extension.eq_ignore_ascii_case(extension))
}

/// Loads a mesh file with the loader its extension names (`.obj`, `.stl`, `.ply`, `.gltf`,
/// `.glb`, in any case; a glTF scene comes as one mesh: see
/// [`load_gltf_mesh`](super::gltf::load_gltf_mesh)). A missing file is an [`Error::Io`]; an unknown extension is an
/// [`Error::MeshFile`] that names the supported ones.
pub fn load(path: &Path) -> Result<Mesh> {
    if let Some(format) = format_of(path) {
        return (format.load)(path);
    }
    // A missing file says so, whatever its name.
    std::fs::metadata(path).map_err(|e| io_error(path, e))?;
    let supported: Vec<String> = FORMATS
        .iter()
        .map(|f| format!(".{}", f.extension))
        .collect();
    let what = match path.extension() {
        Some(e) => format!("unknown mesh file extension '.{}'", e.to_string_lossy()),
        None => "no file extension to tell the mesh format".to_owned(),
    };
    Err(file_error(
        path,
        None,
        format!("{what}; wirepass reads {}", supported.join(", ")),
    ))
}

pub(crate) fn file_error(path: &Path, line: Option<usize>, message: String) -> Error {
    Error::MeshFile {
        path: path.to_path_buf(),
        line,
        message,
    }
}

pub(crate) fn io_error(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Opens a mesh file for reading, with its length; a directory is an error naming the
/// format that was expected (`format` with its article: "an STL").
pub(crate) fn open(path: &Path, format: &str) -> Result<(std::fs::File, u64)> {
    let file = std::fs::File::open(path).map_err(|e| io_error(path, e))?;
    let metadata = file.metadata().map_err(|e| io_error(path, e))?;
    if metadata.is_dir() {
        return Err(file_error(
            path,
            None,
            format!("is a directory, not {format} file"),
        ));
    }
    Ok((file, metadata.len()))
}

/// Builds the mesh, reporting what [`Mesh::new`] rejects as a problem of the file.
pub(crate) fn build(
    path: &Path,
    positions: Vec<glam::Vec3>,
    normals: Option<Vec<glam::Vec3>>,
    triangles: Vec<[u32; 3]>,
    polygon_edges: Option<Vec<u8>>,
) -> Result<Mesh> {
    Mesh::new(positions, normals, triangles, polygon_edges).map_err(|e| match e {
        Error::InvalidMesh(message) => file_error(path, None, message),
        e => e,
    })
}
