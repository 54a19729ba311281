//! The native side of the browser tests: each frame of `cases` drawn on the machine's own
//! adapter (lavapipe in CI) is within the project's bounds of the ground truth and matches
//! the reference image the browser's frame is held against (`web/tests/reference/`, drawn
//! on lavapipe; `WIREPASS_BLESS=1` redraws them). FLIP mean ≤ 0.002, p99 ≤ 0.05: the same
//! frame on another native adapter (llvmpipe through GL) differs by rounding only.

#![cfg(not(target_arch = "wasm32"))]

mod cases;

use std::path::Path;
use wirepass::gpu::GpuContext;
use wirepass::tools::regression::{check_against_reference, Outcome, Threshold};

#[test]
fn native_frames_match_the_references_and_the_ground_truth() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("a native adapter: {e}"));
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("web-references");
    for case in cases::all() {
        let frame = pollster::block_on(cases::draw(&ctx.device, &ctx.queue, &case));
        ctx.finish()
            .unwrap_or_else(|e| panic!("{}: {e}", case.name));
        let frame = frame.unwrap_or_else(|e| panic!("{}: {e}", case.name));
        let truth = cases::truth(&case).unwrap_or_else(|e| panic!("{}: {e}", case.name));
        println!("{}", cases::check_accuracy(case.name, &truth, &frame));
        let reference = dir.join("reference").join(case.reference());
        let threshold = Threshold {
            mean: 0.002,
            p99: 0.05,
        };
        match check_against_reference(&frame.rgba, frame.size, &reference, &threshold, &out) {
            Ok(Outcome::Pass(d)) => println!("{}: FLIP against the reference {d}", case.name),
            Ok(Outcome::Blessed(path)) => println!("wrote {}", path.display()),
            Err(e) => panic!("{}: {e}", case.name),
        }
    }
}

/// A frame's time on the native adapter, measured as the browser test measures it (the
/// browser docs, docs/browser.md, quote both); printed, never asserted.
#[test]
fn frame_time_of_the_builtin_scene() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("a native adapter: {e}"));
    let start = std::time::Instant::now();
    let clock = || start.elapsed().as_secs_f64() * 1000.0;
    let ms = pollster::block_on(cases::frame_time(
        &ctx.device,
        &ctx.queue,
        (1280, 720),
        15,
        clock,
    ));
    ctx.finish().unwrap();
    println!(
        "frame time, built-in scene, 1280x720, {}: {:.1} ms (median of 15)",
        ctx.describe(),
        ms.unwrap()
    );
}
