//! The crate's one error type. Every fallible public function returns [`Result`].

use std::path::PathBuf;

/// Everything that can go wrong in wirepass, from a malformed file to a lost device. New
/// variants may come with new features, so a `match` needs a catch-all arm.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// No adapter matched the request (backend, name) on this machine.
    #[error("no GPU adapter found: {0}")]
    NoAdapter(String),
    /// The adapter exists but lacks a feature or limit the pass needs.
    #[error("adapter '{adapter}' lacks {what}")]
    MissingFeature {
        /// Adapter name as the driver reports it.
        adapter: String,
        /// The missing feature, named as wgpu names it.
        what: String,
    },
    /// A mesh file could not be parsed; `line` is 1-based where the format has lines.
    #[error("{}{}: {message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    MeshFile {
        /// The file that was read.
        path: PathBuf,
        /// 1-based line number, when known.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// A mesh built in memory is not valid (NaN coordinates, indices out of range, …).
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// A camera that cannot produce an image (eye on target, fov out of range, …).
    #[error("invalid camera: {0}")]
    InvalidCamera(String),
    /// A scene that cannot be drawn (a singular or non-affine instance transform, a mesh
    /// that is not in the store, too many instances, …).
    #[error("invalid scene: {0}")]
    InvalidScene(String),
    /// A scene file could not be read; the message names the field.
    #[cfg(feature = "tools")]
    #[error("{}: {message}", path.display())]
    SceneFile {
        /// The file that was read.
        path: PathBuf,
        /// What is wrong, and where.
        message: String,
    },
    /// The library was used in a way it does not support: a texture of the wrong format,
    /// size, usage or sample count, a frame from another pass, a mesh from another store,
    /// encoding before preparing, …
    #[error("misuse of the wirepass API: {0}")]
    Misuse(String),
    /// Any other setting out of range (size, line width, colour string, …).
    #[error("invalid setting: {0}")]
    InvalidSetting(String),
    /// A request exceeds one of the device's limits.
    #[error("{what} is {value}, over the device limit {limit_name} = {limit} (by {excess})", excess = value - limit)]
    OverLimit {
        /// What was too large, in words.
        what: String,
        /// The requested amount.
        value: u64,
        /// Name of the wgpu limit.
        limit_name: &'static str,
        /// The device's value of that limit.
        limit: u64,
    },
    /// The device reported a validation or out-of-memory error, or was lost.
    #[error("GPU device error: {0}")]
    Device(String),
    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// Encoding or decoding an image failed.
    #[cfg(feature = "regression")]
    #[error("{}: {message}", path.display())]
    Image {
        /// The file concerned.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// Shorthand for `std::result::Result<T, wirepass::Error>`.
pub type Result<T> = std::result::Result<T, Error>;
