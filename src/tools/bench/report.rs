//! The benchmark's reports: Markdown tables, the CSV and JSON files and the plots of a
//! run's results.

use super::baseline::{ratios, ratios_markdown};
use super::run::{same_shot, switch, Run, Stats};
use crate::error::{Error, Result};
use crate::gpu::GpuContext;

/// A markdown table of the deferred method's edge and trace passes under each edge
/// selection timed (`Timing::edges`), relative to the world's own selection (`deferred`) of
/// the same scene and size; empty when only one was timed.
pub fn edges_markdown(runs: &[Run]) -> String {
    let mut out = String::new();
    let median = |r: &Run, name: &str| r.passes.get(name).map_or(0.0, |s| s.median_ms);
    for base in runs.iter().filter(|r| r.method == "deferred") {
        let others: Vec<&Run> = runs
            .iter()
            .filter(|r| {
                same_shot(r, base)
                    && r.outlines == base.outlines
                    && r.method.starts_with("deferred ")
            })
            .collect();
        if others.is_empty() {
            continue;
        }
        if out.is_empty() {
            out += "| scene | size | method | edge ms | ÷ deferred | edge + outline ms | ÷ deferred |\n\
                    |---|---|---|---:|---:|---:|---:|\n";
        }
        let (edge, both) = (
            median(base, "edge"),
            median(base, "edge") + median(base, "outline"),
        );
        for r in std::iter::once(base).chain(others) {
            let (e, b) = (median(r, "edge"), median(r, "edge") + median(r, "outline"));
            out += &format!(
                "| {} | {}x{} | {} | {:.3} | {:.2}× | {:.3} | {:.2}× |\n",
                r.scene,
                r.size[0],
                r.size[1],
                r.method,
                e,
                e / edge,
                b,
                b / both
            );
        }
    }
    out
}

/// A markdown table of runs, with each method's total relative to the deferred one of the
/// same scene and size.
pub fn markdown(runs: &[Run]) -> String {
    let mut out = String::from(
        "| scene | triangles | size | outlines | method | visibility ms | edge/draw ms | total ms | vs deferred | GPU MiB |\n\
         |---|---:|---|---|---|---:|---:|---:|---:|---:|\n",
    );
    for r in runs {
        if let Some(why) = &r.skipped {
            let why = why.replace('|', "/");
            out += &format!("{} – | skipped: {why} | – | – | – |\n", row_head(r));
            continue;
        }
        let deferred = runs
            .iter()
            .find(|d| same_shot(d, r) && d.outlines == r.outlines && d.method == "deferred")
            .map(|d| d.total_median_ms);
        let pass = |name: &str| {
            r.passes
                .get(name)
                .map(|s| format!("{:.3}", s.median_ms))
                .unwrap_or_else(|| "–".into())
        };
        let mut other: Vec<_> = r
            .passes
            .iter()
            .filter(|(k, _)| k.as_str() != "visibility")
            .map(|(k, s)| format!("{k} {:.3}", s.median_ms))
            .collect();
        if let Some(w) = r.edge_work {
            other.push(format!(
                "tiles {:.1} %, traced tiles {:.1} %, refined {:.2} % of pixels, {} outline \
                 clusters, {} traced pieces ({} settled)",
                100.0 * w.tiles,
                100.0 * w.traced_tiles,
                100.0 * w.refined,
                w.traced_clusters,
                w.traced_pieces,
                w.settled_pieces
            ));
        }
        out += &format!(
            "{} {} | {} | {:.3} | {} | {:.1} |\n",
            row_head(r),
            pass("visibility"),
            other.join(", "),
            r.total_median_ms,
            deferred
                .filter(|d| *d > 0.0)
                .map(|d| format!("{:.2}×", r.total_median_ms / d))
                .unwrap_or_else(|| "–".into()),
            r.gpu_bytes as f64 / (1024.0 * 1024.0),
        );
    }
    out
}

/// A row's first cells in [`markdown`]: scene, triangles, size, outlines and method.
fn row_head(r: &Run) -> String {
    format!(
        "| {} | {} | {}x{} | {} | {} |",
        r.scene,
        r.triangles,
        r.size[0],
        r.size[1],
        switch(r.outlines),
        r.method
    )
}

/// One row per scene and size: each method's total (the deferred method's with outlines and
/// without), the edge pass against the floor's compute pass, and the deferred method
/// against the published one (`gs`); ms, medians. Ratios are given with outlines on / off
/// where both were timed.
pub fn summary_markdown(runs: &[Run]) -> String {
    let mut out = String::from(
        "| scene | triangles | size | floor | deferred | deferred, no outlines | forward | two-pass | gs | edge ÷ floor | deferred ÷ gs |\n\
         |---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let mut shots: Vec<&Run> = Vec::new();
    for r in runs {
        if !shots.iter().any(|s| same_shot(s, r)) {
            shots.push(r);
        }
    }
    for shot in shots {
        let find = |method: &str, outlines: Option<bool>| {
            runs.iter().find(|r| {
                same_shot(r, shot)
                    && r.method == method
                    && r.skipped.is_none()
                    && outlines.is_none_or(|o| r.outlines == o)
            })
        };
        let ms =
            |r: Option<&Run>| r.map_or("–".to_owned(), |r| format!("{:.2}", r.total_median_ms));
        let floor = find("floor", None);
        let on = find("deferred", Some(true));
        let off = find("deferred", Some(false));
        let gs = find("gs", None);
        let edge = |r: &Run| r.passes.get("edge").map(|s| s.median_ms);
        let ratios = |f: &dyn Fn(&Run) -> Option<f64>| {
            let parts: Vec<String> = [on, off]
                .into_iter()
                .flatten()
                .filter_map(|d| f(d).map(|v| format!("{v:.2}×")))
                .collect();
            if parts.is_empty() {
                "–".to_owned()
            } else {
                parts.join(" / ")
            }
        };
        // Against the floor timed beside the same setting, as the ratios table takes it.
        let floor_of = |d: &Run| find("floor", Some(d.outlines)).or(floor);
        let edge_floor = ratios(&|d| Some(edge(d)? / edge(floor_of(d)?)?));
        let deferred_gs = ratios(&|d| Some(d.total_median_ms / gs?.total_median_ms));
        out += &format!(
            "| {} | {} | {}x{} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            shot.scene,
            shot.triangles,
            shot.size[0],
            shot.size[1],
            ms(floor),
            ms(on),
            ms(off),
            ms(find("forward", None)),
            ms(find("two-pass", None)),
            match find("gs", None) {
                Some(r) => ms(Some(r)),
                None if runs.iter().any(|r| same_shot(r, shot) && r.method == "gs") => {
                    "skipped".to_owned()
                }
                None => "–".to_owned(),
            },
            edge_floor,
            deferred_gs,
        );
    }
    out
}

/// The adapter a benchmark ran on, for the report.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DeviceInfo {
    /// Adapter name.
    pub name: String,
    /// wgpu backend.
    pub backend: String,
    /// Device type (discrete, integrated, CPU, …).
    pub device_type: String,
    /// Driver and its version, as reported.
    pub driver: String,
}

impl DeviceInfo {
    /// Reads the adapter's description.
    pub fn of(ctx: &GpuContext) -> DeviceInfo {
        let i = ctx.adapter.get_info();
        DeviceInfo {
            name: i.name,
            backend: format!("{:?}", i.backend),
            device_type: format!("{:?}", i.device_type),
            driver: format!("{} {}", i.driver, i.driver_info).trim().to_owned(),
        }
    }

    /// One line.
    pub fn describe(&self) -> String {
        format!(
            "{} ({}, {}; {})",
            self.name, self.backend, self.device_type, self.driver
        )
    }
}

/// The whole report in markdown: the adapter (and the OpenGL renderer `gs` ran on), the
/// summary by scene ([`summary_markdown`]), every run's passes ([`markdown`]) and the edge
/// selections' table ([`edges_markdown`]).
pub fn report_markdown(device: &DeviceInfo, runs: &[Run]) -> String {
    let mut out = format!("{}\n\n", device.describe());
    if let Some(gl) = runs.iter().find_map(|r| r.gl.as_ref()) {
        out += &format!("gs on {gl}\n\n");
    }
    out += &summary_markdown(runs);
    out += "\n";
    out += &ratios_markdown(&ratios(runs));
    out += "\n";
    out += &markdown(runs);
    let by_edges = edges_markdown(runs);
    if !by_edges.is_empty() {
        out += "\n";
        out += &by_edges;
    }
    out
}

/// Writes `bench.md` ([`report_markdown`]), `bench.json`, `bench.csv`, `ratios.json`
/// ([`ratios`]), `time_vs_triangles.png` and `time_vs_pixels.png` into `dir`.
pub fn write_outputs(dir: &std::path::Path, device: &DeviceInfo, runs: &[Run]) -> Result<()> {
    let io = |path: std::path::PathBuf| move |source| Error::Io { path, source };
    std::fs::create_dir_all(dir).map_err(io(dir.to_owned()))?;
    let path = dir.join("bench.md");
    std::fs::write(&path, report_markdown(device, runs)).map_err(io(path.clone()))?;
    let json = serde_json::json!({ "device": device, "runs": runs });
    let path = dir.join("bench.json");
    let text = serde_json::to_string_pretty(&json)
        .map_err(|e| Error::InvalidSetting(format!("bench.json: {e}")))?;
    std::fs::write(&path, text).map_err(io(path.clone()))?;
    let path = dir.join("bench.csv");
    std::fs::write(&path, csv(runs)).map_err(io(path.clone()))?;
    let path = dir.join("ratios.json");
    let text = serde_json::to_string_pretty(&ratios(runs))
        .map_err(|e| Error::InvalidSetting(format!("ratios.json: {e}")))?;
    std::fs::write(&path, text).map_err(io(path.clone()))?;
    // Lines join procedural scenes of one kind (`sphere:N`); a mesh file is a point.
    let family = |r: &Run| match r.scene.split_once(':') {
        Some((kind, _)) if !r.scene.contains('/') => kind.to_owned(),
        _ => r.scene.clone(),
    };
    plot::time_against(
        &dir.join("time_vs_triangles.png"),
        runs,
        "triangles",
        |r| r.triangles as f64,
        (|r: &Run| format!("{}x{}", r.size[0], r.size[1]), family),
    )?;
    plot::time_against(
        &dir.join("time_vs_pixels.png"),
        runs,
        "pixels",
        |r| f64::from(r.size[0]) * f64::from(r.size[1]),
        (|r: &Run| r.scene.clone(), |_: &Run| String::new()),
    )
}

/// One row per run and pass (plus a `total` row per run).
pub fn csv(runs: &[Run]) -> String {
    let mut out = String::from(
        "scene,triangles,width,height,outlines,method,pass,median_ms,p10_ms,p90_ms,cpu_median_ms,gpu_bytes\n",
    );
    for r in runs {
        let total = Stats {
            median_ms: r.total_median_ms,
            p10_ms: f64::NAN,
            p90_ms: f64::NAN,
        };
        let rows = r.passes.iter().map(|(k, v)| (k.as_str(), v));
        for (pass, s) in rows.chain([("total", &total)]) {
            let num = |v: f64| {
                if v.is_nan() {
                    String::new()
                } else {
                    format!("{v:.6}")
                }
            };
            out += &format!(
                "{},{},{},{},{},{},{},{},{},{},{:.6},{}\n",
                r.scene.replace(',', ";"),
                r.triangles,
                r.size[0],
                r.size[1],
                switch(r.outlines),
                r.method,
                pass,
                num(s.median_ms),
                num(s.p10_ms),
                num(s.p90_ms),
                r.cpu.median_ms,
                r.gpu_bytes
            );
        }
    }
    out
}

mod plot {
    //! Log-log plots of GPU time per method (and per pass of the deferred one), with
    //! plotters and an embedded font so they draw the same on a machine without fonts.

    use super::super::run::Run;
    use crate::error::{Error, Result};
    use plotters::prelude::*;
    use std::path::Path;
    use std::sync::Once;

    fn register_font() {
        static ONCE: Once = Once::new();
        ONCE.call_once(|| {
            // The bytes are a known-good embedded TTF; a failure would only lose the text.
            let _ = plotters::style::register_font(
                "sans-serif",
                FontStyle::Normal,
                dejavu::sans::regular(),
            );
        });
    }

    const COLORS: [RGBColor; 5] = [
        RGBColor(120, 120, 120),
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
    ];
    /// The deferred method's own passes, drawn thin beside the totals.
    const PASSES: [(&str, RGBColor); 2] = [
        ("edge", RGBColor(23, 190, 207)),
        ("outline", RGBColor(148, 103, 189)),
    ];

    /// One plotted line.
    struct Line {
        /// In the legend; the first line of each method and group only.
        label: Option<String>,
        color: RGBAColor,
        /// Stroke width in pixels.
        width: u32,
        points: Vec<(f64, f64)>,
    }

    /// `20k`, `2M`, `1.5M`: tick labels that read at a glance.
    fn short(v: f64) -> String {
        let (scaled, unit) = match v.abs() {
            a if a >= 1e9 => (v / 1e9, "G"),
            a if a >= 1e6 => (v / 1e6, "M"),
            a if a >= 1e3 => (v / 1e3, "k"),
            _ => (v, ""),
        };
        let text = format!("{scaled:.1}");
        format!("{}{unit}", text.trim_end_matches(".0"))
    }

    /// Whether `r` is a deferred method (or the floor) timed without outlines: drawn as a
    /// line of its own, fainter.
    fn without_outlines(r: &Run) -> bool {
        !r.outlines && (r.method == "floor" || r.method.starts_with("deferred"))
    }

    /// Median GPU time against `x` (log-log): the total per method, one colour per method
    /// and one line per method, `group` (the variable held fixed along the line, named in
    /// the legend) and `family` (scenes whose points a line may join: the spheres of
    /// `sphere:N`, say; a mesh file is a point of its own), and thinner lines for the
    /// deferred method's edge and trace passes. The deferred methods timed without
    /// outlines are fainter lines of their own.
    pub fn time_against(
        path: &Path,
        runs: &[Run],
        x_name: &str,
        x: impl Fn(&Run) -> f64,
        (group, family): (impl Fn(&Run) -> String, impl Fn(&Run) -> String),
    ) -> Result<()> {
        register_font();
        let fail = |e: String| Error::Image {
            path: path.to_owned(),
            message: e,
        };
        let group = |r: &Run| {
            let suffix = if without_outlines(r) {
                ", no outlines"
            } else {
                ""
            };
            format!("{}{suffix}", group(r))
        };
        let mut methods: Vec<&str> = Vec::new();
        let mut keys: Vec<(&str, String, String)> = Vec::new();
        for r in runs.iter().filter(|r| r.skipped.is_none()) {
            if !methods.contains(&r.method.as_str()) {
                methods.push(&r.method);
            }
            let key = (r.method.as_str(), group(r), family(r));
            if !keys.contains(&key) {
                keys.push(key);
            }
        }
        let groups = keys
            .iter()
            .map(|l| &l.1)
            .collect::<std::collections::BTreeSet<_>>();
        let mut lines: Vec<Line> = Vec::new();
        let mut labelled = std::collections::BTreeSet::new();
        for (method, fixed, kind) in &keys {
            let chosen = || {
                runs.iter().filter(|r| {
                    r.skipped.is_none()
                        && r.method == *method
                        && group(r) == *fixed
                        && family(r) == *kind
                })
            };
            let suffix = if groups.len() > 1 {
                format!(" ({fixed})")
            } else {
                String::new()
            };
            let first = labelled.insert((*method, fixed.clone()));
            let label = |name: String| first.then_some(name);
            let faint = fixed.ends_with(", no outlines");
            let shade = |c: RGBColor| c.mix(if faint { 0.45 } else { 1.0 });
            let m = methods.iter().position(|n| n == method).unwrap_or(0);
            let total = chosen().map(|r| (x(r), r.total_median_ms)).collect();
            lines.push(Line {
                label: label(format!("{method}{suffix}")),
                color: shade(COLORS[m % COLORS.len()]),
                width: 2,
                points: total,
            });
            if *method == "deferred" {
                for (pass, color) in PASSES {
                    let points: Vec<_> = chosen()
                        .filter_map(|r| r.passes.get(pass).map(|s| (x(r), s.median_ms)))
                        .collect();
                    if !points.is_empty() {
                        lines.push(Line {
                            label: label(format!("deferred: {pass} pass{suffix}")),
                            color: shade(color),
                            width: 1,
                            points,
                        });
                    }
                }
            }
        }
        for line in &mut lines {
            line.points.retain(|p| p.0 > 0.0 && p.1 > 0.0);
            line.points.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        let points = lines.iter().flat_map(|l| l.points.iter());
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(px, py) in points {
            (x0, x1, y0, y1) = (x0.min(px), x1.max(px), y0.min(py), y1.max(py));
        }
        if x0 > x1 {
            return Ok(());
        }
        let root = BitMapBackend::new(path, (900, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(e.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("GPU time per frame against {x_name}"),
                ("sans-serif", 22),
            )
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d(
                (x0 * 0.8..x1 * 1.25).log_scale(),
                (y0 * 0.8..y1 * 1.25).log_scale(),
            )
            .map_err(|e| fail(e.to_string()))?;
        chart
            .configure_mesh()
            .x_desc(x_name)
            .y_desc("median GPU ms")
            .x_label_formatter(&|v| short(*v))
            .y_label_formatter(&|v| short(*v))
            .draw()
            .map_err(|e| fail(e.to_string()))?;
        for Line {
            label,
            color,
            width,
            points: series,
        } in lines
        {
            let drawn = chart
                .draw_series(LineSeries::new(series.clone(), color.stroke_width(width)))
                .map_err(|e| fail(e.to_string()))?;
            if let Some(label) = label {
                drawn.label(label).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(width))
                });
            }
            chart
                .draw_series(
                    series
                        .into_iter()
                        .map(|p| Circle::new(p, 2 + width, color.filled())),
                )
                .map_err(|e| fail(e.to_string()))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperLeft)
            .draw()
            .map_err(|e| fail(e.to_string()))?;
        root.present().map_err(|e| fail(e.to_string()))
    }
}
