//! The forward baselines the deferred pass is measured against: the single-pass method of
//! Bærentzen et al. (2006, "Single-pass wireframe rendering"; NVIDIA's "Solid Wireframe"
//! white paper, 2007) and the two-pass method it set out to beat. Both raster the scene
//! into the host's output with one pass skeleton (`raster.rs`) over the deferred pass's scene
//! data and mesh store; nothing in the deferred pass uses them.

mod forward;
mod raster;
mod two_pass;

pub(crate) use forward::forward_source;
pub use forward::ForwardPass;
pub use raster::{RasterFrame, MAPS_DIAGNOSTIC_FORMAT};
pub(crate) use two_pass::two_pass_source;
pub use two_pass::{drawn_edges, EdgeLines, TwoPass};
