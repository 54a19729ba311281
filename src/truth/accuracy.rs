//! How closely a frame matches the ground truth, pixel by pixel: triangle-id agreement and
//! edge-distance error. The `compare` tool, the tests and the browser tests all measure
//! with these.

use crate::error::{Error, Result};
use crate::world::{Rendering, BACKGROUND};

/// Edge distances are compared where the true distance is below this many pixels: that is
/// where a line can be drawn, and where the distance matters.
pub const DISTANCE_RANGE_PX: f64 = 4.0;

/// And where the frame's distance is below this many pixels, whatever the truth's: a line
/// this near its pixel's centre colours it at any width, so a frame's line where the ground
/// truth has none is a stray line pixel. (Beyond a line's reach the distances a frame
/// reports need not match: it colours nothing there.)
pub const STRAY_RANGE_PX: f64 = 1.0;

/// Edge-distance error in pixels: over pixels whose ids agree with the ground truth and whose
/// true distance is under [`DISTANCE_RANGE_PX`] or measured one under [`STRAY_RANGE_PX`], so
/// that a line missing from the frame and a stray line the ground truth does not draw both
/// count (as an infinite error where the other side has no line). `None` when no pixel
/// qualifies.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "tools", derive(serde::Serialize))]
pub struct DistanceError {
    /// Mean absolute error.
    pub mean: Option<f64>,
    /// 99th percentile (nearest rank) of the absolute error.
    pub p99: Option<f64>,
    /// Largest absolute error (`inf` where one side has a line and the other none).
    pub max: Option<f64>,
    /// Number of pixels measured.
    pub pixels: usize,
    /// Measured pixels where the frame has a line and the ground truth none.
    pub stray: usize,
    /// Measured pixels where the ground truth has a line and the frame none.
    pub missing: usize,
}

/// Checks that two frames can be compared pixel for pixel.
fn check_same_shape(reference: &Rendering, frame: &Rendering) -> Result<()> {
    let n = reference.size.0 as usize * reference.size.1 as usize;
    let whole = |f: &Rendering| {
        f.ids.len() == n
            && f.edge_distance.len() == n
            && f.hidden_distance.len() == n
            && f.depth.len() == n
            && f.rgba.len() == 4 * n
    };
    if reference.size != frame.size || !whole(reference) || !whole(frame) {
        return Err(Error::InvalidSetting(format!(
            "cannot compare a {}x{} frame with a {}x{} one (or a frame's maps are incomplete)",
            reference.size.0, reference.size.1, frame.size.0, frame.size.1
        )));
    }
    Ok(())
}

/// `(id agreement, coverage agreement)` of `frame` against `reference`: among pixels where
/// either side is foreground, the fraction whose id equals the reference's (1 when neither
/// has any foreground); and the fraction of all pixels where both agree on foreground versus
/// background. An error if their sizes differ.
pub fn id_agreement(reference: &Rendering, frame: &Rendering) -> Result<(f64, f64)> {
    check_same_shape(reference, frame)?;
    let n = reference.ids.len();
    let (mut either, mut same_id, mut same_cover) = (0usize, 0usize, 0usize);
    for (&a, &b) in reference.ids.iter().zip(&frame.ids) {
        let (fa, fb) = (a != BACKGROUND, b != BACKGROUND);
        same_cover += usize::from(fa == fb);
        if fa || fb {
            either += 1;
            same_id += usize::from(a == b);
        }
    }
    let ids = if either == 0 {
        1.0
    } else {
        same_id as f64 / either as f64
    };
    Ok((ids, same_cover as f64 / n.max(1) as f64))
}

/// The [`DistanceError`] of `frame` against `reference`; an error if their sizes differ.
pub fn distance_error(reference: &Rendering, frame: &Rendering) -> Result<DistanceError> {
    summarise(reference, frame, |f| &f.edge_distance)
}

/// [`distance_error`] of the hidden lines ([`Rendering::hidden_distance`]).
pub fn hidden_distance_error(reference: &Rendering, frame: &Rendering) -> Result<DistanceError> {
    summarise(reference, frame, |f| &f.hidden_distance)
}

fn summarise(
    reference: &Rendering,
    frame: &Rendering,
    map: impl Fn(&Rendering) -> &[f32],
) -> Result<DistanceError> {
    let errors = errors_of(reference, frame, &map)?;
    // An infinite error is a line on one side only: the frame's (stray) or the truth's.
    let lined = map(frame);
    let (mut stray, mut missing) = (0, 0);
    for (i, e) in errors.iter().enumerate() {
        if *e == Some(f64::INFINITY) {
            if lined[i].is_finite() {
                stray += 1;
            } else {
                missing += 1;
            }
        }
    }
    let mut measured: Vec<f64> = errors.into_iter().flatten().collect();
    measured.sort_by(f64::total_cmp);
    Ok(DistanceError {
        mean: (!measured.is_empty()).then(|| measured.iter().sum::<f64>() / measured.len() as f64),
        p99: percentile(&measured, 0.99),
        max: measured.last().copied(),
        pixels: measured.len(),
        stray,
        missing,
    })
}

/// Among pixels whose ids agree and where either side has a line, the fraction whose
/// [`Rendering::line_class`] (the class of the line that colours the pixel most) equals the
/// reference's; `None` where a side reports no classes or no pixel qualifies.
pub fn line_class_agreement(reference: &Rendering, frame: &Rendering) -> Result<Option<f64>> {
    check_same_shape(reference, frame)?;
    let (t, f) = (&reference.line_class, &frame.line_class);
    if t.len() != reference.ids.len() || f.len() != frame.ids.len() {
        return Ok(None);
    }
    let (mut lined, mut agree) = (0usize, 0usize);
    for i in 0..t.len() {
        if reference.ids[i] == frame.ids[i] && (t[i] != 0 || f[i] != 0) {
            lined += 1;
            agree += usize::from(t[i] == f[i]);
        }
    }
    Ok((lined > 0).then(|| agree as f64 / lined as f64))
}

/// Nearest-rank percentile of sorted values.
pub fn percentile(sorted: &[f64], q: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let rank = (q * sorted.len() as f64).ceil() as usize;
    Some(sorted[rank.clamp(1, sorted.len()) - 1])
}

/// Per pixel, `|d − d_true|` where it is measured (ids agree, background included, which
/// outlines reach; see [`DistanceError`]), `None` elsewhere.
pub fn distance_errors(reference: &Rendering, frame: &Rendering) -> Result<Vec<Option<f64>>> {
    errors_of(reference, frame, |f| &f.edge_distance)
}

/// [`distance_errors`] of the hidden lines ([`Rendering::hidden_distance`]).
pub fn hidden_distance_errors(
    reference: &Rendering,
    frame: &Rendering,
) -> Result<Vec<Option<f64>>> {
    errors_of(reference, frame, |f| &f.hidden_distance)
}

fn errors_of(
    reference: &Rendering,
    frame: &Rendering,
    map: impl Fn(&Rendering) -> &[f32],
) -> Result<Vec<Option<f64>>> {
    check_same_shape(reference, frame)?;
    let (truths, distances) = (map(reference), map(frame));
    Ok((0..reference.ids.len())
        .map(|i| {
            let (truth, d) = (f64::from(truths[i]), f64::from(distances[i]));
            let measured = frame.ids[i] == reference.ids[i]
                && (truth < DISTANCE_RANGE_PX || d < STRAY_RANGE_PX);
            measured.then(|| {
                if d.is_finite() && truth.is_finite() {
                    (d - truth).abs()
                } else {
                    f64::INFINITY
                }
            })
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four pixels of one triangle, with the given edge distances.
    fn frame(edge_distance: [f32; 4]) -> Rendering {
        Rendering {
            size: (4, 1),
            rgba: vec![0; 16],
            ids: vec![7; 4],
            depth: vec![0.5; 4],
            edge_distance: edge_distance.to_vec(),
            hidden_distance: vec![f32::INFINITY; 4],
            line_class: Vec::new(),
        }
    }

    #[test]
    fn a_missing_and_a_stray_line_pixel_both_count() {
        let inf = f32::INFINITY;
        let truth = frame([0.5, 2.0, inf, inf]);
        // Alike, and a line of the frame beyond the stray range: no error.
        let same = distance_error(&truth, &frame([0.5, 2.0, inf, 3.0])).unwrap();
        assert_eq!((same.max, same.pixels), (Some(0.0), 2));
        // The line through pixel 1 missing.
        let missing = distance_error(&truth, &frame([0.5, inf, inf, inf])).unwrap();
        assert_eq!((missing.max, missing.pixels), (Some(f64::INFINITY), 2));
        assert_eq!((missing.stray, missing.missing), (0, 1));
        // A line through pixel 2 that the truth does not draw.
        let stray = distance_error(&truth, &frame([0.5, 2.0, 0.25, inf])).unwrap();
        assert_eq!((stray.max, stray.pixels), (Some(f64::INFINITY), 3));
        assert_eq!((stray.stray, stray.missing), (1, 0));
    }
}
