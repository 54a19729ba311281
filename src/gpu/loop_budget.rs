//! How long the trace pass's loops may run: llvmpipe's cap on loop iterations, and the
//! piece lengths that keep under it.
//!
//! Mesa's software rasterizer llvmpipe (under lavapipe's Vulkan and under Mesa's GL driver)
//! runs a compute shader's invocations in SIMD batches (8 lanes with AVX2) and caps the loop
//! iterations one batch may run at [`LOOP_CAP`] (its `LP_MAX_TGSI_LOOP_ITERATIONS`), counted
//! over all loops of the shader together: past it every loop ends after the iteration it is
//! in and the shader goes on with what it has, without an error. A batch runs each loop
//! until its slowest lane is done, so what counts is the sum, over the loops the batch
//! enters, of the most iterations any of its lanes needs; and which pieces share a batch
//! changes from frame to frame. A batch of traced pieces past the cap draws some of its
//! lines in part, and differently each frame.
//!
//! So on a software rasterizer the trace pass cuts an edge into pieces short enough that
//! the most a batch of them can loop ([`piece_loops`]) stays under the cap, for lines up to
//! [`COVERED_WIDTH`] wide: the samples along a piece ([`RUN_SAMPLES_PER_PX`] a pixel, and
//! [`RUN_BISECTIONS`] more at each change of visibility, at most one a step), each looking
//! at the pixel ids of a window round its point and walking from each ([`WALK_STEPS`] from
//! the 3×3 pixels round it, [`FOLD_STEPS`] from those further out and from the line's
//! triangles' other neighbours); then the pixels in reach of the piece, each against up to
//! [`MAX_RUNS`] runs, for its visible and its hidden line; and first, for a short piece
//! drawn for its hidden line alone, the pixels of its box ([`SETTLE_PX`]). The wider the
//! window, the shorter the pieces. A GPU has no such cap, and its pieces are 1 px whatever
//! the window.
//!
//! Three loops are not bounded here: the pieces of a cluster whose lines the piece list had
//! no room for, which a lane of the piece dispatch draws for each of its triangles, one
//! after another; an edge of more than 65 535 pieces, drawn the same way; and the walk along
//! a chain of drawn edges for the patterns' phases (`chain_phases`), an iteration an edge.
//!
//! The shaders take these constants from here ([`wgsl`]).

/// Loop iterations one SIMD batch of a shader may run on llvmpipe, all loops together.
pub(crate) const LOOP_CAP: u32 = 65_535;

/// Steps of a walk across edges from a rasterized triangle towards a point (`locate` in
/// scene.wgsl): enough to go round a vertex's fan of small triangles from a rasterized
/// neighbour to the one that owns the point, and, in the trace pass, to cross the few
/// pixels' worth of sub-pixel triangles between a rasterized triangle and one that hides a
/// point of an outline.
pub(crate) const WALK_STEPS: u32 = 24;
/// Steps of the trace pass's walks from the outer ring of a wide window and from the
/// line's triangles' other neighbours: they only cross the sheet's last few triangles.
pub(crate) const FOLD_STEPS: u32 = 4;
/// Times a walk of the trace pass turns about a fold's end instead of ending there
/// (`locate`), in frames with hidden lines: a surface that folds back and forth within a
/// pixel hides a line's point with the sheet past the fold. Turning takes steps of the
/// walk's own, so it adds no loop.
pub(crate) const FOLD_TURNS: u32 = 1;
/// Samples of visibility a pixel along an outline piece.
pub(crate) const RUN_SAMPLES_PER_PX: u32 = 4;
/// Bisections of a step where visibility changes: 2^-12 of a quarter pixel, well below the
/// accuracy bounds.
pub(crate) const RUN_BISECTIONS: u32 = 12;
/// Visible (and hidden) runs a piece keeps; past them the last run absorbs the rest.
pub(crate) const MAX_RUNS: u32 = 8;
/// The longest piece (px) and the widest hidden line's reach (px) for which the trace pass
/// first checks whether the piece's hidden line is settled, every pixel in its reach holding
/// a nearer line already (`hidden_settled`), before finding its runs: a loop over the pixels
/// of the piece's box grown by the reach, at most [`SETTLE_LOOPS`] iterations.
pub(crate) const SETTLE_PX: u32 = 2;
pub(crate) const SETTLE_REACH: u32 = 3;
/// The pixels of that box: the piece and the reach either side, each end rounded out.
const SETTLE_LOOPS: u32 = (SETTLE_PX + 2 * SETTLE_REACH + 3) * (SETTLE_PX + 2 * SETTLE_REACH + 3);
/// The widest line (px) whose pieces [`piece_loops`] keeps under [`LOOP_CAP`].
pub(crate) const COVERED_WIDTH: u32 = 16;
/// What the pieces' other loops may take: the section planes' clip of an edge, the
/// pattern's phase-table probes, the output tiles a piece marks.
const OTHER_LOOPS: u32 = 1024;

/// The radii of the windows of pixel ids the trace pass looks at round a sample
/// (`line_window` in trace.wgsl): the 3×3 pixels round it; 5×5 with section planes and for
/// intersection lines; 9×9 where the line's triangles cross other surfaces.
pub(crate) const WINDOW_RADII: [u32; 3] = [1, 2, 4];

/// Longest piece (px) for each of [`WINDOW_RADII`] on a software rasterizer: the longest of
/// 16, 8, 4, 2 and 1 px whose [`piece_loops`] keeps under the cap.
pub(crate) const SOFTWARE_PIECE_PX: [u32; 3] = [
    longest_piece(WINDOW_RADII[0]),
    longest_piece(WINDOW_RADII[1]),
    longest_piece(WINDOW_RADII[2]),
];

/// Loop iterations of one visibility sample (`class_at`) with a window of radius `r`: the
/// window's pixels, a walk from each, and in a wide window (r > 1) a walk from each of six
/// neighbours. A walk of n steps runs n + 1 iterations.
pub(crate) const fn sample_loops(r: u32) -> u32 {
    let across = 2 * r + 1;
    let cells = across * across;
    let walks = 9 * (WALK_STEPS + 1) + (cells - 9) * (FOLD_STEPS + 1);
    let neighbours = if r > 1 { 6 * (FOLD_STEPS + 2) } else { 0 };
    cells + walks + neighbours
}

/// The most loop iterations a piece of `piece_px` pixels can take with a window of radius
/// `r`, for lines up to [`COVERED_WIDTH`] wide.
pub(crate) const fn piece_loops(piece_px: u32, r: u32) -> u32 {
    // A piece is at most piece_px long, which its step count rounds up by one at most.
    let steps = RUN_SAMPLES_PER_PX * piece_px + 1;
    let samples = steps + 1 + RUN_BISECTIONS * steps;
    // Pixels in reach, along the piece and across it (`splat_runs`): reach is
    // width / 2 + 1, the band across it reach × √2 + 1 on either side, each rounded out.
    let reach = COVERED_WIDTH / 2 + 1;
    let along = piece_px + 2 * reach + 3;
    let across = 2 * (reach * 3 / 2 + 1) + 3;
    let splat = along * (1 + across * (1 + MAX_RUNS));
    samples * (sample_loops(r) + 1) + 2 * splat + SETTLE_LOOPS + OTHER_LOOPS
}

const fn longest_piece(r: u32) -> u32 {
    let mut px = 16;
    while px > 1 && piece_loops(px, r) > LOOP_CAP {
        px /= 2;
    }
    px
}

const _: () = {
    let mut i = 0;
    while i < WINDOW_RADII.len() {
        assert!(piece_loops(SOFTWARE_PIECE_PX[i], WINDOW_RADII[i]) <= LOOP_CAP);
        i += 1;
    }
};

/// The constants above, as WGSL declarations.
pub(crate) fn wgsl() -> String {
    let [narrow, section, crossed] = SOFTWARE_PIECE_PX;
    let [r0, r1, r2] = WINDOW_RADII;
    format!(
        "const WALK_STEPS: u32 = {WALK_STEPS}u;\n\
         const FOLD_STEPS: u32 = {FOLD_STEPS}u;\n\
         const FOLD_TURNS: u32 = {FOLD_TURNS}u;\n\
         const RUN_SAMPLES_PER_PX: f32 = {RUN_SAMPLES_PER_PX}.0;\n\
         const RUN_BISECTIONS: u32 = {RUN_BISECTIONS}u;\n\
         const MAX_RUNS: u32 = {MAX_RUNS}u;\n\
         const SETTLE_PX: f32 = {SETTLE_PX}.0;\n\
         const SETTLE_REACH: f32 = {SETTLE_REACH}.0;\n\
         const SOFTWARE_PIECE_PX: vec3<f32> = vec3<f32>({narrow}.0, {section}.0, {crossed}.0);\n\
         const WINDOW_RADII: vec3<i32> = vec3<i32>({r0}, {r1}, {r2});"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wider_windows_take_shorter_pieces() {
        assert!(SOFTWARE_PIECE_PX.windows(2).all(|w| w[0] >= w[1]));
        for (&px, &r) in SOFTWARE_PIECE_PX.iter().zip(&WINDOW_RADII) {
            assert!(piece_loops(px, r) <= LOOP_CAP);
            assert!(px == 16 || piece_loops(2 * px, r) > LOOP_CAP);
        }
        assert!(wgsl().contains("const WALK_STEPS: u32 = 24u;"));
    }
}
