//! # wirepass
//!
//! Mesh wireframes drawn as a **deferred, compute-shader post-process** on wgpu: a visibility
//! pass writes a triangle id and depth per pixel, and a compute pass reconstructs, per pixel,
//! the exact screen-space distance to the visible triangle's edges and composites the shaded
//! colour with the line. Its cost depends on the pixel count, not on the triangle count.

#![warn(missing_docs)]

pub mod bench;
pub mod camera;
pub mod cli;
pub mod compare;
pub mod edge_math;
pub mod error;
pub mod gpu;
pub mod mesh;
pub mod outline;
pub mod raycast;
pub mod regression;
pub mod render;
pub mod style;

pub use camera::Camera;
pub use error::{Error, Result};
pub use mesh::{EdgeSelection, Mesh};
pub use style::{Color, Style};
