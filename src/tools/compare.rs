//! Accuracy of every GPU method against the CPU ray-cast ground truth: per-pixel metrics
//! ([`metrics`]), the images that show where methods differ, and the `wirepass compare`
//! report ([`run`]).

mod font;

use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::tools::offline::{draw, Method};
use crate::tools::regression;
use crate::truth::accuracy::{distance_error, hidden_distance_error, id_agreement, percentile};
use crate::truth::draw_raycast;
use crate::world::{Rendering, Shot};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

pub use crate::truth::accuracy::{distance_errors, DistanceError, DISTANCE_RANGE_PX};

/// The distance-error heat map spans 10^MIN .. 10^MAX pixels, on a log scale.
const HEAT_LOG10: (f64, f64) = (-6.0, 0.0);

/// Perceptual image difference (NVIDIA FLIP, LDR, default viewing distance), 0..1.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ImageDifference {
    /// Mean FLIP error over all pixels.
    pub flip_mean: f64,
    /// 99th percentile (nearest rank) of the per-pixel FLIP error.
    pub flip_p99: f64,
}

/// How closely one frame matches the reference.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Metrics {
    /// Among pixels where either side is foreground, the fraction whose id equals the
    /// reference's (1 when neither has any foreground).
    pub id_agreement: f64,
    /// Fraction of all pixels where both agree on foreground versus background.
    pub coverage_agreement: f64,
    /// Edge-distance error, see [`DistanceError`].
    pub distance_error_px: DistanceError,
    /// Hidden-line distance error ([`Rendering::hidden_distance`]); no pixels where the
    /// reference draws no hidden lines.
    pub hidden_distance_error_px: DistanceError,
    /// Agreement of the line-class maps
    /// ([`accuracy::line_class_agreement`](crate::truth::accuracy::line_class_agreement));
    /// `None` for methods that report no classes.
    pub line_class_agreement: Option<f64>,
    /// FLIP difference of the final images.
    pub image_difference: ImageDifference,
}

/// Compares `frame` against `reference` (the ground truth); an error if their sizes differ.
pub fn metrics(reference: &Rendering, frame: &Rendering) -> Result<Metrics> {
    let distance_error_px = distance_error(reference, frame)?;
    let hidden_distance_error_px = hidden_distance_error(reference, frame)?;
    let (id_agreement, coverage_agreement) = id_agreement(reference, frame)?;
    let mut flip: Vec<f64> = flip_map(reference, frame)?
        .into_iter()
        .map(f64::from)
        .collect();
    let flip_mean = flip.iter().sum::<f64>() / flip.len().max(1) as f64;
    flip.sort_by(f64::total_cmp);
    Ok(Metrics {
        id_agreement,
        coverage_agreement,
        distance_error_px,
        hidden_distance_error_px,
        line_class_agreement: crate::truth::accuracy::line_class_agreement(reference, frame)?,
        image_difference: ImageDifference {
            flip_mean,
            flip_p99: percentile(&flip, 0.99).unwrap_or(0.0),
        },
    })
}

fn rgba(frame: &Rendering) -> regression::Rgba<'_> {
    regression::Rgba {
        pixels: &frame.rgba,
        size: frame.size,
    }
}

/// The per-pixel FLIP error (0..1) of `frame` against `reference`
/// ([`regression::flip_map`]).
///
/// An error if the frames differ in size.
pub fn flip_map(reference: &Rendering, frame: &Rendering) -> Result<Vec<f32>> {
    regression::flip_map(rgba(reference), rgba(frame))
}

/// An RGBA image in memory.
#[derive(Clone, Debug)]
pub struct Image {
    /// Width and height.
    pub size: (u32, u32),
    /// 8-bit RGBA, row-major, top row first.
    pub rgba: Vec<u8>,
}

impl Image {
    fn new(size: (u32, u32), fill: [u8; 4]) -> Self {
        Self {
            size,
            rgba: fill.repeat((size.0 * size.1) as usize),
        }
    }

    fn blit(&mut self, src: &Image, (x0, y0): (u32, u32)) {
        for y in 0..src.size.1.min(self.size.1.saturating_sub(y0)) {
            let w = src.size.0.min(self.size.0.saturating_sub(x0)) as usize;
            let s = 4 * (y * src.size.0) as usize;
            let d = 4 * ((y0 + y) * self.size.0 + x0) as usize;
            self.rgba[d..d + 4 * w].copy_from_slice(&src.rgba[s..s + 4 * w]);
        }
    }

    fn text(&mut self, at: (u32, u32), text: &str, scale: u32, color: [u8; 4]) {
        font::draw_text(&mut self.rgba, self.size.0, at, text, scale, color);
    }

    /// Writes the image as a PNG.
    pub fn save_png(&self, path: &Path) -> Result<()> {
        crate::tools::regression::save_rgba_png(path, &self.rgba, self.size)
    }
}

fn magma() -> Vec<[u8; 3]> {
    nv_flip::magma_lut()
        .to_vec()
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect()
}

const GREY: [u8; 4] = [128, 128, 128, 255];
const WHITE: [u8; 4] = [255, 255, 255, 255];
const BLACK: [u8; 4] = [0, 0, 0, 255];

/// The edge-distance error as a heat map: magma on a log scale from 1e-6 px (dark) to 1 px
/// and beyond (bright), grey where not measured, with a labelled scale below the image.
pub fn distance_error_image(reference: &Rendering, frame: &Rendering) -> Result<Image> {
    let lut = magma();
    let (w, h) = reference.size;
    let (lo, hi) = HEAT_LOG10;
    let colour = |e: f64| {
        let t = ((e.max(1e-300).log10() - lo) / (hi - lo)).clamp(0.0, 1.0);
        let c = lut[(t * (lut.len() - 1) as f64).round() as usize];
        [c[0], c[1], c[2], 255]
    };
    let legend = 2 * font::LINE + 14;
    let mut img = Image::new((w, h + legend), WHITE);
    for (i, e) in distance_errors(reference, frame)?.into_iter().enumerate() {
        let c = e.map_or(GREY, colour);
        img.rgba[4 * i..4 * i + 4].copy_from_slice(&c);
    }
    // Colour bar over the full width, decade ticks labelled under it.
    let bar = (h + 2, 8);
    for x in 0..w {
        let t = (f64::from(x) + 0.5) / f64::from(w);
        let c = colour(10f64.powf(lo + t * (hi - lo)));
        for y in bar.0..bar.0 + bar.1 {
            let i = 4 * (y * w + x) as usize;
            img.rgba[i..i + 4].copy_from_slice(&c);
        }
    }
    let decades = (hi - lo) as i32;
    for k in 0..=decades {
        let x = (f64::from(k) / f64::from(decades) * f64::from(w - 1)) as u32;
        let label = match lo as i32 + k {
            0 => "1".to_string(),
            e => format!("1e{e}"),
        };
        let lx = x
            .saturating_sub(font::text_width(&label, 1) / 2)
            .min(w.saturating_sub(font::text_width(&label, 1)));
        img.text((lx, bar.0 + bar.1 + 2), &label, 1, BLACK);
    }
    img.text(
        (2, bar.0 + bar.1 + 3 + font::LINE),
        "edge distance error px - grey: not measured",
        1,
        BLACK,
    );
    Ok(img)
}

/// The FLIP error map through nv-flip's magma LUT ([`regression::flip_error_rgba`]).
///
/// An error if the frames differ in size.
pub fn flip_error_image(reference: &Rendering, frame: &Rendering) -> Result<Image> {
    Ok(Image {
        size: reference.size,
        rgba: regression::flip_error_rgba(rgba(reference), rgba(frame))?,
    })
}

fn frame_image(frame: &Rendering) -> Image {
    Image {
        size: frame.size,
        rgba: frame.rgba.clone(),
    }
}

/// What happened to one method in a comparison.
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
pub enum MethodReport {
    /// It rendered; its metrics and timing.
    Measured {
        /// Accuracy against the ground truth (boxed: it is most of the report's size).
        #[serde(flatten)]
        metrics: Box<Metrics>,
        /// GPU time of the method's passes; `None` where not measured (see `note`).
        gpu_ms: Option<f64>,
        /// Wall-clock time of the whole render call: pipeline creation, upload, draw and
        /// readback included.
        wall_ms: f64,
        /// How the timing was taken.
        note: String,
    },
    /// It could not run on this adapter.
    Skipped {
        /// Why.
        skipped: String,
    },
}

/// The content of `report.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Image size.
    pub size: [u32; 2],
    /// Triangles over all objects.
    pub triangles: u64,
    /// Per method (JSON key: the method's name with `-` as `_`), in [`Method::ALL`] order.
    pub methods: serde_json::Map<String, serde_json::Value>,
    /// The same, typed, for the table.
    #[serde(skip)]
    pub rows: Vec<(Method, MethodReport)>,
    /// Seconds the ground truth took.
    #[serde(skip)]
    pub reference_seconds: f64,
}

/// What `wall_ms` measures.
const WALL_NOTE: &str = "wall_ms times the whole render call (pipeline creation, upload, draw, \
readback) on this adapter";

/// Frames timed for `gpu_ms`, after [`WARM_UP_FRAMES`] untimed ones.
const TIMED_FRAMES: u32 = 20;
/// Frames drawn before timing starts.
const WARM_UP_FRAMES: u32 = 3;

/// GPU time of each method's passes for `shot` in milliseconds (median over frames, methods
/// interleaved frame by frame, see [`crate::tools::bench`]), with a note on how it was taken.
fn gpu_times(ctx: &GpuContext, shot: &Shot<'_>) -> (BTreeMap<String, f64>, String) {
    let timing = crate::tools::bench::Timing {
        frames: TIMED_FRAMES,
        warmup: WARM_UP_FRAMES,
        edges: Vec::new(),
        methods: Vec::new(),
    };
    match crate::tools::bench::bench_scene(ctx, "compare", shot, timing) {
        Ok(runs) => (
            runs.into_iter()
                .map(|r| (r.method, r.total_median_ms))
                .collect(),
            format!(
                "gpu_ms: median over {TIMED_FRAMES} frames (after {WARM_UP_FRAMES} warm-up) of \
                 the sum of the method's timestamped passes; {WALL_NOTE}"
            ),
        ),
        Err(e) => (
            BTreeMap::new(),
            format!("gpu_ms not measured: {e}; {WALL_NOTE}"),
        ),
    }
}

/// Renders `shot` with the ground truth and every GPU method, writes the images, heat maps,
/// `sheet.png` and `report.json` into `out`, and returns the report.
pub fn run(ctx: &GpuContext, shot: &Shot<'_>, out: &Path) -> Result<Report> {
    std::fs::create_dir_all(out).map_err(|source| Error::Io {
        path: out.to_owned(),
        source,
    })?;
    let start = Instant::now();
    let reference = draw_raycast(shot)?;
    let reference_seconds = start.elapsed().as_secs_f64();
    reference.save_png(&out.join(format!("{}.png", Method::Raycast.name())))?;

    let (gpu_ms, note) = gpu_times(ctx, shot);
    let mut rows = Vec::new();
    let mut panels: Vec<(String, Option<[Image; 3]>)> = Vec::new();
    for &method in Method::ALL {
        if method == Method::Raycast {
            continue;
        }
        let name = method.name();
        let start = Instant::now();
        let report = match draw(ctx, shot, method) {
            Err(e) => {
                panels.push((name.to_string(), None));
                MethodReport::Skipped {
                    skipped: e.to_string(),
                }
            }
            Ok(frame) => {
                let wall_ms = start.elapsed().as_secs_f64() * 1e3;
                let key = name.replace('-', "_");
                frame.save_png(&out.join(format!("{name}.png")))?;
                let heat = distance_error_image(&reference, &frame)?;
                heat.save_png(&out.join(format!("{key}_distance_error.png")))?;
                let flip = flip_error_image(&reference, &frame)?;
                flip.save_png(&out.join(format!("{key}_flip.png")))?;
                panels.push((name.to_string(), Some([frame_image(&frame), heat, flip])));
                MethodReport::Measured {
                    metrics: Box::new(metrics(&reference, &frame)?),
                    gpu_ms: gpu_ms.get(name).copied(),
                    wall_ms,
                    note: note.clone(),
                }
            }
        };
        rows.push((method, report));
    }
    let sheet = sheet(&frame_image(&reference), &panels);
    sheet.save_png(&out.join("sheet.png"))?;

    let mut methods = serde_json::Map::new();
    for (m, r) in &rows {
        let value = serde_json::to_value(r).map_err(|e| Error::Device(e.to_string()))?;
        methods.insert(m.name().replace('-', "_"), value);
    }
    let report = Report {
        size: [shot.size.0, shot.size.1],
        triangles: shot.world.triangle_count(),
        methods,
        rows,
        reference_seconds,
    };
    let path = out.join("report.json");
    let text = serde_json::to_string_pretty(&report).unwrap_or_default();
    std::fs::write(&path, text + "\n").map_err(|source| Error::Io { path, source })?;
    Ok(report)
}

/// One labelled sheet: a column for the ground truth and one per method; rows: the image,
/// the distance-error heat map, the FLIP map.
fn sheet(reference: &Image, panels: &[(String, Option<[Image; 3]>)]) -> Image {
    let (w, h) = reference.size;
    let scale = if w >= 240 { 2 } else { 1 };
    let label = font::LINE * scale + 4;
    let gap = 8;
    let heights: [u32; 3] = std::array::from_fn(|r| {
        panels
            .iter()
            .filter_map(|(_, p)| p.as_ref().map(|p| p[r].size.1))
            .max()
            .unwrap_or(h)
            .max(h)
    });
    let columns = 1 + panels.len() as u32;
    let width = columns * w + (columns + 1) * gap;
    let height = heights.iter().map(|r| r + label + gap).sum::<u32>() + gap;
    let mut sheet = Image::new((width, height), WHITE);
    let row_top = |r: usize| gap + heights[..r].iter().map(|x| x + label + gap).sum::<u32>();
    let x_of = |c: u32| gap + c * (w + gap);
    sheet.text((x_of(0), row_top(0)), "raycast reference", scale, BLACK);
    sheet.blit(reference, (x_of(0), row_top(0) + label));
    let notes = [
        (1, "edge distance"),
        (1, "error vs raycast ->"),
        (2, "flip error map"),
        (2, "vs raycast ->"),
    ];
    for (k, (row, text)) in notes.into_iter().enumerate() {
        let y = row_top(row) + (k as u32 % 2) * label;
        sheet.text((x_of(0), y), text, scale, BLACK);
    }
    for (c, (name, p)) in panels.iter().enumerate() {
        let x = x_of(c as u32 + 1);
        match p {
            Some(images) => {
                let titles = [
                    name.clone(),
                    format!("{name} distance"),
                    format!("{name} flip"),
                ];
                for (r, (img, title)) in images.iter().zip(titles).enumerate() {
                    sheet.text((x, row_top(r)), &title, scale, BLACK);
                    sheet.blit(img, (x, row_top(r) + label));
                }
            }
            None => {
                sheet.text((x, row_top(0)), &format!("{name} skipped"), scale, BLACK);
                sheet.blit(&Image::new((w, h), GREY), (x, row_top(0) + label));
            }
        }
    }
    sheet
}

/// The report as an aligned text table.
pub fn table(report: &Report) -> String {
    let fmt = |v: Option<f64>| match v {
        Some(v) if v.is_finite() => format!("{v:.2e}"),
        Some(_) => "inf".into(),
        None => "-".into(),
    };
    let mut lines = vec![format!(
        "{:<10} {:>9} {:>9} {:>9} {:>9} {:>9} {:>7} {:>7} {:>8} {:>8} {:>9} {:>9}",
        "method",
        "id agree",
        "coverage",
        "d mean",
        "d p99",
        "d max",
        "stray",
        "missing",
        "flip",
        "flip p99",
        "gpu ms",
        "wall ms"
    )];
    for (m, r) in &report.rows {
        lines.push(match r {
            MethodReport::Measured {
                metrics,
                gpu_ms,
                wall_ms,
                ..
            } => format!(
                "{:<10} {:>9.5} {:>9.5} {:>9} {:>9} {:>9} {:>7} {:>7} {:>8.4} {:>8.4} {:>9} {:>9.1}",
                m.name(),
                metrics.id_agreement,
                metrics.coverage_agreement,
                fmt(metrics.distance_error_px.mean),
                fmt(metrics.distance_error_px.p99),
                fmt(metrics.distance_error_px.max),
                metrics.distance_error_px.stray,
                metrics.distance_error_px.missing,
                metrics.image_difference.flip_mean,
                metrics.image_difference.flip_p99,
                gpu_ms.map_or("-".into(), |v| format!("{v:.3}")),
                wall_ms
            ),
            MethodReport::Skipped { skipped } => format!(
                "{:<10} skipped: {}",
                m.name(),
                skipped.lines().next().unwrap_or_default()
            ),
        });
    }
    // The hidden lines' own distance errors, where the reference draws any.
    let hidden: Vec<_> = report
        .rows
        .iter()
        .filter_map(|(m, r)| match r {
            MethodReport::Measured { metrics, .. } => Some((m, metrics.hidden_distance_error_px)),
            MethodReport::Skipped { .. } => None,
        })
        .collect();
    if hidden.iter().any(|(_, h)| h.pixels > 0) {
        lines.push(String::new());
        lines.push(format!(
            "{:<10} {:>9} {:>9} {:>9} {:>7} {:>7} {:>9}",
            "hidden", "h mean", "h p99", "h max", "stray", "missing", "pixels"
        ));
        for (m, h) in hidden {
            lines.push(format!(
                "{:<10} {:>9} {:>9} {:>9} {:>7} {:>7} {:>9}",
                m.name(),
                fmt(h.mean),
                fmt(h.p99),
                fmt(h.max),
                h.stray,
                h.missing,
                h.pixels
            ));
        }
    }
    // How often each method's line class (edge, outline, hidden) is the reference's.
    let classes: Vec<_> = report
        .rows
        .iter()
        .filter_map(|(m, r)| match r {
            MethodReport::Measured { metrics, .. } => Some((m, metrics.line_class_agreement?)),
            MethodReport::Skipped { .. } => None,
        })
        .collect();
    if !classes.is_empty() {
        lines.push(String::new());
        lines.push(format!("{:<10} {:>12}", "classes", "class agree"));
        for (m, a) in classes {
            lines.push(format!("{:<10} {:>12.5}", m.name(), a));
        }
    }
    lines.join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(ids: Vec<u32>, d: Vec<f32>) -> Rendering {
        let n = ids.len();
        Rendering {
            size: (n as u32, 1),
            rgba: vec![200; 4 * n],
            ids,
            depth: vec![0.5; n],
            edge_distance: d,
            hidden_distance: vec![f32::INFINITY; n],
            line_class: Vec::new(),
        }
    }

    #[test]
    fn frames_of_different_sizes_are_an_error_not_a_panic() {
        let a = frame(vec![0; 4], vec![1.0; 4]);
        let b = frame(vec![0; 3], vec![1.0; 3]);
        assert!(metrics(&a, &b).is_err());
        assert!(flip_error_image(&a, &b).is_err());
        assert!(distance_error_image(&a, &b).is_err());
    }

    #[test]
    fn metrics_count_the_right_pixels() {
        let inf = f32::INFINITY;
        let bg = crate::world::BACKGROUND;
        let reference = frame(
            vec![1, 1, 2, 2, bg, bg, 3, 3],
            vec![0.5, 3.0, 5.0, 1.0, inf, inf, inf, 2.0],
        );
        let test = frame(
            vec![1, 1, 2, 9, bg, 4, bg, 3],
            vec![0.5, 3.25, 5.5, 1.0, inf, 0.0, inf, 2.0],
        );
        let m = metrics(&reference, &test).unwrap();
        // Either side foreground: 7 pixels; ids equal at 0, 1, 2, 7.
        assert!((m.id_agreement - 4.0 / 7.0).abs() < 1e-12);
        // Coverage differs at 5 and 6.
        assert!((m.coverage_agreement - 6.0 / 8.0).abs() < 1e-12);
        // Measured: 0 (0), 1 (0.25), 7 (0); pixel 2 is beyond the range.
        let d = m.distance_error_px;
        assert_eq!(d.pixels, 3);
        assert_eq!(d.max, Some(0.25));
        assert_eq!(d.p99, Some(0.25));
        assert!((d.mean.unwrap() - 0.25 / 3.0).abs() < 1e-12);
        assert_eq!((d.stray, d.missing), (0, 0));
        assert_eq!(m.image_difference.flip_mean, 0.0);
    }

    #[test]
    fn percentiles_are_nearest_rank() {
        let v: Vec<f64> = (1..=200).map(f64::from).collect();
        assert_eq!(percentile(&v, 0.99), Some(198.0));
        assert_eq!(percentile(&v[..1], 0.99), Some(1.0));
        assert_eq!(percentile(&[], 0.99), None);
    }
}
