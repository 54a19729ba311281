//! What tools and tests add to an encode (feature `diagnostics`): GPU timestamps around each
//! pass, a second output of an already rasterized frame, and the baselines' id and distance
//! maps. A renderer needs none of it; every pass's plain `encode` is `encode_with` and the
//! default options. What the deferred pass adds is in `deferred_diagnostics.rs`.

use super::GpuTimer;

/// Options of `encode_with` on [`DeferredPass`](super::DeferredPass),
/// [`ForwardPass`](super::baselines::ForwardPass) and [`TwoPass`](super::baselines::TwoPass).
#[derive(Default)]
pub struct EncodeOptions<'t> {
    /// Timestamps around each pass, into this timer: the deferred pass names its spans
    /// `"visibility"`, `"trace.cull"`, `"trace.list"` and `"trace.pieces"` (when
    /// outlines are drawn), and `"edge.classify"`, `"edge.border"`, `"edge.clear"` or
    /// `"edge.background"` (whichever lays down the background), `"edge.traced"` (with
    /// outlines), `"edge.tiles"` and `"edge.refine"`; the baselines name theirs `"draw"`
    /// (two-pass: `"fill"` and `"lines"`).
    pub timer: Option<&'t mut GpuTimer>,
    /// The deferred pass only: record the trace and edge passes over the ids the frame's
    /// last encode rasterized, without the visibility pass (a second output of one frame).
    pub reuse_ids: bool,
    /// The baselines only: also write the id and diagnostic maps of their frame.
    pub maps: bool,
}
