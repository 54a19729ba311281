//! Image regression: compare two RGBA8 images with FLIP (NVIDIA's perceptual difference,
//! crate `nv-flip`, as wgpu and vello use it), write heat maps, and check rendered frames
//! against blessed reference PNGs.
//!
//! The bless workflow: `WIREPASS_BLESS=1 cargo test --test regression` (re)writes the
//! references; without it a missing reference is a failure, never silently created.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// Environment variable that makes [`check_against_reference`] (re)write references.
pub const BLESS_ENV: &str = "WIREPASS_BLESS";

/// An RGBA8 image borrowed from memory: row-major, row 0 at the top, sRGB.
#[derive(Clone, Copy, Debug)]
pub struct Rgba<'a> {
    /// 8-bit RGBA pixels, `4 · width · height` bytes.
    pub pixels: &'a [u8],
    /// Width and height in pixels.
    pub size: (u32, u32),
}

impl<'a> Rgba<'a> {
    /// Wraps `pixels`; fails if the length does not match `size`.
    pub fn new(pixels: &'a [u8], size: (u32, u32)) -> Result<Self> {
        let want = 4 * size.0 as usize * size.1 as usize;
        if pixels.len() != want {
            return Err(Error::InvalidSetting(format!(
                "an RGBA8 image of {}x{} needs {want} bytes, got {}",
                size.0,
                size.1,
                pixels.len()
            )));
        }
        Ok(Self { pixels, size })
    }
}

/// Largest FLIP differences a comparison accepts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Threshold {
    /// Largest mean FLIP error over all pixels (0..1).
    pub mean: f32,
    /// Largest 99th-percentile FLIP error (0..1).
    pub p99: f32,
}

/// FLIP difference between two images: statistics of the per-pixel error (0 = identical,
/// 1 = as different as it gets).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Difference {
    /// Mean over all pixels.
    pub mean: f32,
    /// 99th percentile (nearest rank).
    pub p99: f32,
    /// Largest per-pixel error.
    pub max: f32,
}

impl Difference {
    /// Why `self` exceeds `threshold`, or `None` when it is within it.
    pub fn exceeds(&self, threshold: &Threshold) -> Option<String> {
        let mut why = Vec::new();
        if self.mean.is_nan() || self.mean > threshold.mean {
            why.push(format!("mean {:.5} > {:.5}", self.mean, threshold.mean));
        }
        if self.p99.is_nan() || self.p99 > threshold.p99 {
            why.push(format!("p99 {:.5} > {:.5}", self.p99, threshold.p99));
        }
        (!why.is_empty()).then(|| why.join(", "))
    }
}

impl std::fmt::Display for Difference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "FLIP mean {:.5}, p99 {:.5}, max {:.5}",
            self.mean, self.p99, self.max
        )
    }
}

fn same_size(a: Rgba<'_>, b: Rgba<'_>) -> Result<()> {
    if a.size != b.size {
        return Err(Error::InvalidSetting(format!(
            "images differ in size: {}x{} and {}x{}",
            a.size.0, a.size.1, b.size.0, b.size.1
        )));
    }
    Ok(())
}

fn rgb8(image: Rgba<'_>) -> Vec<u8> {
    image
        .pixels
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// The FLIP error image of `test` against `reference` (alpha is ignored).
///
/// # Panics
/// If the sizes differ; [`flip_map`] and [`difference`] check them first.
fn flip_image(reference: Rgba<'_>, test: Rgba<'_>) -> nv_flip::FlipImageFloat {
    assert_eq!(reference.size, test.size, "images of different sizes");
    let (w, h) = reference.size;
    let a = nv_flip::FlipImageRgb8::with_data(w, h, &rgb8(reference));
    let b = nv_flip::FlipImageRgb8::with_data(w, h, &rgb8(test));
    nv_flip::flip(a, b, nv_flip::DEFAULT_PIXELS_PER_DEGREE)
}

/// The per-pixel FLIP error (0..1) of `test` against `reference`, row-major.
pub fn flip_map(reference: Rgba<'_>, test: Rgba<'_>) -> Result<Vec<f32>> {
    same_size(reference, test)?;
    Ok(flip_image(reference, test).to_vec())
}

/// The FLIP error map through nv-flip's magma colour map, as RGBA8 of the images' size.
pub fn flip_error_rgba(reference: Rgba<'_>, test: Rgba<'_>) -> Result<Vec<u8>> {
    same_size(reference, test)?;
    let map = flip_image(reference, test);
    let rgb = map.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    Ok(rgb
        .chunks_exact(3)
        .flat_map(|c| [c[0], c[1], c[2], 255])
        .collect())
}

/// Statistics of a FLIP error map.
pub fn statistics(map: &[f32]) -> Difference {
    if map.is_empty() {
        return Difference {
            mean: 0.0,
            p99: 0.0,
            max: 0.0,
        };
    }
    let mean = (map.iter().map(|&e| f64::from(e)).sum::<f64>() / map.len() as f64) as f32;
    let mut sorted = map.to_vec();
    sorted.sort_by(f32::total_cmp);
    let rank = (0.99 * sorted.len() as f64).ceil() as usize;
    Difference {
        mean,
        p99: sorted[rank.clamp(1, sorted.len()) - 1],
        max: sorted[sorted.len() - 1],
    }
}

/// FLIP difference of `b` against `a` (`a` is the reference). Different sizes are an
/// [`Error::InvalidSetting`] naming both.
///
/// ```
/// use wirepass::tools::regression::{difference, Rgba, Threshold};
///
/// let grey = vec![128u8; 4 * 32 * 32];
/// let same = difference(Rgba::new(&grey, (32, 32))?, Rgba::new(&grey, (32, 32))?)?;
/// assert_eq!(same.max, 0.0);
///
/// // A red 4×4 square in one corner.
/// let mut marked = grey.clone();
/// for y in 0..4 {
///     for x in 0..4 {
///         marked[4 * (32 * y + x)..][..4].copy_from_slice(&[255, 0, 0, 255]);
///     }
/// }
/// let d = difference(Rgba::new(&grey, (32, 32))?, Rgba::new(&marked, (32, 32))?)?;
/// println!("{d}");
/// assert!(d.max > d.p99 && d.mean < d.max);
/// let threshold = Threshold { mean: 0.002, p99: 0.02 };
/// assert!(d.exceeds(&threshold).is_some());
/// # Ok::<(), wirepass::Error>(())
/// ```
pub fn difference(a: Rgba<'_>, b: Rgba<'_>) -> Result<Difference> {
    Ok(statistics(&flip_map(a, b)?))
}

/// Writes the FLIP heat map of `b` against `a` (magma: black = same, bright = different)
/// as a PNG.
pub fn heat_map(a: Rgba<'_>, b: Rgba<'_>, path: &Path) -> Result<()> {
    let rgba = flip_error_rgba(a, b)?;
    save_rgba_png(path, &rgba, a.size)
}

/// Reads a PNG (or any format the `image` crate was built with) as RGBA8; errors name the file.
pub fn load_rgba(path: &Path) -> Result<(Vec<u8>, (u32, u32))> {
    let image = image::open(path).map_err(|e| match e {
        image::ImageError::IoError(source) => Error::Io {
            path: path.to_owned(),
            source,
        },
        e => Error::Image {
            path: path.to_owned(),
            message: e.to_string(),
        },
    })?;
    let rgba = image.to_rgba8();
    let size = rgba.dimensions();
    Ok((rgba.into_raw(), size))
}

/// The result of a successful [`check_against_reference`].
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// Within the threshold.
    Pass(Difference),
    /// `WIREPASS_BLESS=1`: the reference was (re)written.
    Blessed(PathBuf),
}

/// Whether `WIREPASS_BLESS` asks for references to be rewritten (`1`, `true`, `yes`).
pub fn blessing() -> bool {
    std::env::var(BLESS_ENV)
        .map(|v| matches!(v.trim(), "1" | "true" | "yes"))
        .unwrap_or(false)
}

/// Compares `actual` (RGBA8 of `size`) against the PNG at `reference`.
///
/// - With `WIREPASS_BLESS=1` it writes `actual` as the new reference and returns
///   [`Outcome::Blessed`].
/// - A missing reference is an error that says how to bless; it is never created silently.
/// - Over `threshold` (or a size mismatch), it writes `<name>.actual.png` and
///   `<name>.diff.png` (FLIP magma heat map, when the sizes match) into `out_dir` and
///   returns an error naming both.
pub fn check_against_reference(
    actual: &[u8],
    size: (u32, u32),
    reference: &Path,
    threshold: &Threshold,
    out_dir: &Path,
) -> Result<Outcome> {
    check(actual, size, reference, threshold, out_dir, blessing())
}

fn check(
    actual: &[u8],
    size: (u32, u32),
    reference: &Path,
    threshold: &Threshold,
    out_dir: &Path,
    bless: bool,
) -> Result<Outcome> {
    let actual = Rgba::new(actual, size)?;
    if bless {
        if let Some(dir) = reference.parent() {
            create_dir(dir)?;
        }
        save_rgba_png(reference, actual.pixels, size)?;
        return Ok(Outcome::Blessed(reference.to_owned()));
    }
    if !reference.exists() {
        return Err(Error::InvalidSetting(format!(
            "reference image {} does not exist; render it and check it by eye, then bless \
             it with {BLESS_ENV}=1 cargo test --release --test regression",
            reference.display()
        )));
    }
    let (pixels, ref_size) = load_rgba(reference)?;
    let expected = Rgba::new(&pixels, ref_size)?;
    let name = reference
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "image".into());
    create_dir(out_dir)?;
    let actual_path = out_dir.join(format!("{name}.actual.png"));
    let diff_path = out_dir.join(format!("{name}.diff.png"));
    if ref_size != size {
        save_rgba_png(&actual_path, actual.pixels, size)?;
        return Err(Error::InvalidSetting(format!(
            "{}: reference is {}x{}, the render {}x{}; actual image: {}",
            reference.display(),
            ref_size.0,
            ref_size.1,
            size.0,
            size.1,
            actual_path.display()
        )));
    }
    let diff = difference(expected, actual)?;
    let Some(why) = diff.exceeds(threshold) else {
        return Ok(Outcome::Pass(diff));
    };
    let why = format!("{diff}: {why}");
    save_rgba_png(&actual_path, actual.pixels, size)?;
    heat_map(expected, actual, &diff_path)?;
    Err(Error::InvalidSetting(format!(
        "{} differs from the render ({why}); actual image: {}, FLIP heat map: {}; if the \
         change is intended, bless with {BLESS_ENV}=1",
        reference.display(),
        actual_path.display(),
        diff_path.display()
    )))
}

fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        path: dir.to_owned(),
        source,
    })
}

/// Writes 8-bit RGBA pixels, row 0 at the top, as a PNG.
pub fn save_rgba_png(path: &Path, rgba: &[u8], (width, height): (u32, u32)) -> Result<()> {
    image::save_buffer(path, rgba, width, height, image::ColorType::Rgba8).map_err(|e| {
        Error::Image {
            path: path.to_owned(),
            message: e.to_string(),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn solid(size: (u32, u32), c: [u8; 4]) -> Vec<u8> {
        c.repeat((size.0 * size.1) as usize)
    }

    #[test]
    fn identical_images_have_no_difference() {
        let a = solid((16, 8), [10, 200, 30, 255]);
        let d = difference(
            Rgba::new(&a, (16, 8)).unwrap(),
            Rgba::new(&a, (16, 8)).unwrap(),
        );
        assert_eq!(d.unwrap().max, 0.0);
    }

    #[test]
    fn black_and_white_differ_fully() {
        let a = solid((16, 16), [0, 0, 0, 255]);
        let b = solid((16, 16), [255, 255, 255, 255]);
        let d = difference(
            Rgba::new(&a, (16, 16)).unwrap(),
            Rgba::new(&b, (16, 16)).unwrap(),
        )
        .unwrap();
        assert!(d.mean > 0.5, "{d}");
        let t = Threshold {
            mean: 0.01,
            p99: 0.1,
        };
        assert!(d.exceeds(&t).unwrap().contains("mean"));
    }

    #[test]
    fn different_sizes_name_both() {
        let a = solid((4, 4), [0; 4]);
        let b = solid((4, 2), [0; 4]);
        let e = difference(
            Rgba::new(&a, (4, 4)).unwrap(),
            Rgba::new(&b, (4, 2)).unwrap(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("4x4") && e.contains("4x2"), "{e}");
    }

    #[test]
    fn missing_reference_fails_and_says_how_to_bless() {
        let dir = std::env::temp_dir().join(format!("wirepass-regr-{}", std::process::id()));
        let reference = dir.join("missing.png");
        let img = solid((8, 8), [9, 9, 9, 255]);
        let t = Threshold {
            mean: 0.0,
            p99: 0.0,
        };
        let e = check(&img, (8, 8), &reference, &t, &dir, false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.png") && e.contains(BLESS_ENV), "{e}");
        assert!(
            !reference.exists(),
            "a missing reference must not be created"
        );
        // Blessing writes it; then the same image passes and a different one fails with
        // the actual image and the heat map written and named.
        let blessed = check(&img, (8, 8), &reference, &t, &dir, true).unwrap();
        assert_eq!(blessed, Outcome::Blessed(reference.clone()));
        assert!(matches!(
            check(&img, (8, 8), &reference, &t, &dir, false),
            Ok(Outcome::Pass(_))
        ));
        let other = solid((8, 8), [250, 9, 9, 255]);
        let e = check(&other, (8, 8), &reference, &t, &dir, false)
            .unwrap_err()
            .to_string();
        let (actual, diff) = (dir.join("missing.actual.png"), dir.join("missing.diff.png"));
        assert!(actual.exists() && diff.exists());
        assert!(
            e.contains(&*actual.to_string_lossy()) && e.contains(&*diff.to_string_lossy()),
            "{e}"
        );
        let e = check(&solid((4, 8), [0; 4]), (4, 8), &reference, &t, &dir, false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("8x8") && e.contains("4x8"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn wrong_length_is_an_error() {
        assert!(Rgba::new(&[0; 12], (2, 2)).is_err());
    }

    #[test]
    fn statistics_nearest_rank() {
        let map: Vec<f32> = (1..=100).map(|i| i as f32 / 100.0).collect();
        let s = statistics(&map);
        assert_eq!(s.p99, 0.99);
        assert_eq!(s.max, 1.0);
        assert!((s.mean - 0.505).abs() < 1e-6);
    }
}
