//! What tools and tests add to the deferred pass (feature `diagnostics`): the diagnostic
//! maps, a second output of an already rasterized frame, timestamps, a piece list of a
//! chosen size, and the counts of what its later dispatches took on ([`EdgeWork`]). A
//! renderer needs none of it.

use super::deferred::{DeferredPass, PreparedFrame};
use super::diagnostics::EncodeOptions;
use super::mesh_store::MeshStore;
use super::options::OutputTarget;
use super::targets::LIST_HEADER;
use crate::error::Result;

/// How much of a frame the edge pass's later dispatches took on (see
/// [`PreparedFrame::edge_work`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeWork {
    /// 8×8 output tiles holding foreground, which the tile dispatch visited.
    pub tiles: u32,
    /// Output tiles the trace pass's lines reach, whose background the edge pass's
    /// traced dispatch visited (0 where the trace pass did not run).
    pub traced_tiles: u32,
    /// Output tiles in all.
    pub all_tiles: u32,
    /// Pixels the refine dispatch decided: centres the exact test could not settle from the
    /// rasterizer's triangle, and background next to foreground.
    pub refined: u32,
    /// Output pixels in all.
    pub pixels: u32,
    /// Clusters of 64 triangles the trace pass's cull listed (those that may hold an
    /// outline edge from the eye, or a drawn edge of a large patch), 0 where it did not run.
    pub traced_clusters: u32,
    /// Lines the trace pass listed pieces of (outline and drawn edges, cut and
    /// intersection lines with a piece within reach of the targets), 0 where it did not run.
    pub outline_lines: u32,
    /// Pieces (up to 2 px, or 1 px for [`Tuning::Gpu`](super::Tuning::Gpu)) of those lines
    /// the trace pass listed or found beyond its list's room, 0 where it did not run.
    pub traced_pieces: u32,
    /// How many of them its piece list has room for.
    pub piece_room: u32,
    /// Clusters (and groups of 64 intersection segments) whose pieces the list had no room
    /// for, which the piece dispatch drew 64 lanes each.
    pub overflowed: u32,
    /// Outline edges the frame's outline chains were found for (those beyond their
    /// capacity included), 0 where no outline's hidden parts are patterned.
    pub chained_outlines: u32,
    /// Pieces drawn for their hidden line alone that the trace pass found settled, every
    /// pixel in their reach holding a nearer hidden line already, and found no runs for.
    /// Which pieces these are depends on the order the GPU draws them in.
    pub settled_pieces: u32,
}

impl PreparedFrame {
    /// What the trace pass and the edge pass's tile and refine dispatches took on in the
    /// last encode of this frame, read back from the GPU (it waits for the work submitted so
    /// far): for tools, tests and benchmarks. [`edge_work_async`](Self::edge_work_async)
    /// reads it without blocking.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn edge_work(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<EdgeWork> {
        let mut counts = [0u32; 9];
        for (count, (buffer, at)) in counts.iter_mut().zip(self.counters()) {
            if let Some(buffer) = buffer {
                let bytes = super::readback::read_buffer(device, queue, buffer, at, 4)?;
                *count = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
            }
        }
        Ok(self.edge_work_of(counts))
    }

    /// [`edge_work`](Self::edge_work) without blocking, as a browser needs.
    pub async fn edge_work_async(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<EdgeWork> {
        let mut counts = [0u32; 9];
        for (count, (buffer, at)) in counts.iter_mut().zip(self.counters()) {
            if let Some(buffer) = buffer {
                let read = super::readback::read_buffer_async(device, queue, buffer, at, 4);
                let bytes = read.await?;
                *count = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
            }
        }
        Ok(self.edge_work_of(counts))
    }

    /// Where the counts lie (a list's is the last word of its header): the tile list, the
    /// traced tiles, the refine list, the cluster list, the lines and the pieces listed,
    /// the overflow list (the last five only where the trace pass ran), the outline chains
    /// (where a frame has them), and the settled pieces (the overflow list's second word,
    /// less the 1 it starts at).
    fn counters(&self) -> [(Option<&wgpu::Buffer>, u64); 9] {
        let t = &self.targets;
        let traced = |b| self.data.traced.then_some(b);
        let count = LIST_HEADER - 4;
        let (chains, chains_at, _) = self.data.outline_chains();
        let chained = (chains > 0).then_some(&t.acc).and_then(traced);
        [
            (Some(&t.tiles), count),
            (traced(&t.acc), t.acc_tiles + count),
            (Some(&t.work), count),
            (traced(&self.cull), count),
            (traced(&t.acc), t.acc_overflow),
            (traced(&t.acc), t.acc_pieces + count),
            (traced(&t.acc), t.acc_overflow + count),
            (chained, t.acc_phases + 4 * u64::from(chains_at) + count),
            (traced(&t.acc), t.acc_overflow + 4),
        ]
    }

    /// The work from the counts at [`counters`](Self::counters).
    fn edge_work_of(
        &self,
        [tiles, traced_tiles, refined, clusters, lines, pieces, overflowed, chained, settled]: [u32; 9],
    ) -> EdgeWork {
        let (w, h) = self.targets.output;
        let tile = super::edge_pass::TILE;
        EdgeWork {
            tiles,
            traced_tiles,
            all_tiles: w.div_ceil(tile) * h.div_ceil(tile),
            refined,
            pixels: w * h,
            traced_clusters: clusters,
            outline_lines: lines,
            traced_pieces: pieces,
            piece_room: self.targets.piece_room(),
            overflowed,
            chained_outlines: chained,
            // A list header's second word starts at 1 (an indirect dispatch's y).
            settled_pieces: settled.saturating_sub(1),
        }
    }

    /// The (instance slot, triangle) each output pixel centre sees after the exact coverage
    /// test, written by [`OutputTarget::Diagnostic`].
    pub fn resolved_id_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.diagnostic.as_ref().map(|d| &d.1)
    }

    /// The diagnostic map written by [`OutputTarget::Diagnostic`].
    pub fn diagnostic_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.diagnostic.as_ref().map(|d| &d.0)
    }
}

impl DeferredPass {
    /// Enables [`OutputTarget::Diagnostic`], which needs 24 more bytes of targets per pixel
    /// (and, where the trace pass runs, a second word per pixel in its buffer, which tells
    /// outlines from edges for the line-class map); tools and tests use it, a renderer does
    /// not need it.
    pub fn with_diagnostics(mut self) -> Self {
        self.diagnostics = true;
        self.targets = None;
        self
    }

    /// Gives the trace pass's piece list room for `pieces` entries instead of one per 8
    /// target pixels, so that a test can draw a frame whose pieces overflow it.
    pub fn with_piece_room(mut self, pieces: u64) -> Self {
        self.piece_room = Some(pieces);
        self.targets = None;
        self
    }

    /// [`encode`](Self::encode) with what tools add (see [`EncodeOptions`]): timestamps
    /// around each pass, or a second output over the ids the last encode of this frame
    /// rasterized.
    pub fn encode_with(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        store: &MeshStore,
        frame: &PreparedFrame,
        target: OutputTarget<'_>,
        options: EncodeOptions<'_>,
    ) -> Result<()> {
        let visibility = !options.reuse_ids;
        self.encode_inner(
            device,
            encoder,
            store,
            frame,
            target,
            options.timer,
            visibility,
        )
    }
}
