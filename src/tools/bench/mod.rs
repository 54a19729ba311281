//! The benchmark comparison: every method on one scene and size, GPU time per pass from
//! timestamp queries, frames interleaved across methods so that drift on a busy machine
//! affects them alike.
//!
//! The runner (`run.rs`), the reports it writes (`report.rs`), and the ratios compared with
//! a baseline of record (`baseline.rs`).

mod baseline;
mod report;
mod run;

pub use baseline::{against, ratios, ratios_markdown, Baseline, Ratio, WORSE};
pub use report::{
    csv, edges_markdown, markdown, report_markdown, summary_markdown, write_outputs, DeviceInfo,
};
pub use run::{bench, bench_scene, EdgeShares, Run, Stats, Timed, Timing};
