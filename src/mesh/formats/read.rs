//! What the loaders share: opening a file, and its errors in the terms of the file.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use std::path::Path;

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
