//! # wirepass
//!
//! Mesh wireframes drawn as a **deferred, compute-shader post-process** on wgpu: a visibility
//! pass writes a triangle id and depth per pixel, and a compute pass reconstructs, per pixel,
//! the exact screen-space distance to the visible triangle's edges and composites the shaded
//! colour with the line. Its cost depends on the pixel count, not on the triangle count.

#![warn(missing_docs)]

pub mod camera;
pub mod edge_math;
pub mod error;
pub mod gpu;
pub mod mesh;
mod par;
pub mod scene;
pub mod style;

#[cfg(feature = "tools")]
pub mod bench;
#[cfg(feature = "cli")]
pub mod cli;
#[cfg(feature = "tools")]
pub mod compare;
#[cfg(feature = "tools")]
pub mod outline;
#[cfg(feature = "tools")]
pub mod raycast;
#[cfg(feature = "regression")]
pub mod regression;
#[cfg(feature = "tools")]
pub mod render;
#[cfg(feature = "tools")]
pub mod scene_file;

pub use camera::{Camera, DepthRange, View};
pub use error::{Error, Result};
pub use gpu::{
    Canvas, Composite, DeferredPass, HostDepth, MeshId, MeshStore, OutputTarget, PassOptions,
    PreparedFrame, RenderTarget,
};
pub use mesh::{EdgeSelection, Mesh};
pub use scene::{Instance, InstanceStyle, Scene};
pub use style::{Color, Style};

/// The wgpu this crate is built against: use it (`wirepass::wgpu`) so the host's types match.
pub use wgpu;

/// The glam this crate's API uses for vectors and matrices.
pub use glam;
