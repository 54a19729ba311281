//! The ground truth every method is judged against: each pixel's ray cast in f64 against
//! the world's triangles (a BVH from `obvhs`), and the outlines found from their
//! definition, edge by edge, with their visibility decided by more ray casts. It shares the
//! edge math (`edge_math`) and the line profile (`style`) with the shaders, so a test can
//! hold the two equal, and nothing else with the GPU passes.
//!
//! It uses the core (meshes, camera, style, edge math) and [`crate::world`]; nothing below
//! it uses it.

pub mod accuracy;
pub mod raycast;
pub mod rays;
pub mod traced;

pub use raycast::{draw_raycast, draw_raycast_over};
pub use rays::{HostOccluders, RayCaster};
