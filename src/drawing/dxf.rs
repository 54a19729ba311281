//! DXF, release 12 (`AC1009`), which every CAD program imports: a layer per class, a
//! linetype per pattern and phase (a linetype has no phase: its elements start where the
//! path's pattern does), a `POLYLINE` per path in page units with y up.
//!
//! Written here rather than with a DXF crate: the format is a flat list of group codes and
//! values, and the crates that write it pull in image, date and UUID libraries a drawing
//! does not use.

use super::svg::number;
use super::{Drawing, Page, PathClass};
use crate::style::Color;
use std::fmt::Write;

/// AutoCAD's first colours (ACI 1–9), sRGB: the nearest stands for a path's colour.
const ACI: [(u8, [u8; 3]); 9] = [
    (1, [255, 0, 0]),
    (2, [255, 255, 0]),
    (3, [0, 255, 0]),
    (4, [0, 255, 255]),
    (5, [0, 0, 255]),
    (6, [255, 0, 255]),
    (7, [0, 0, 0]),
    (8, [128, 128, 128]),
    (9, [192, 192, 192]),
];

/// The AutoCAD colour index nearest `c`.
fn aci(c: Color) -> u8 {
    let [r, g, b, _] = c.to_srgb8();
    let d = |q: [u8; 3]| {
        let e = |x: u8, y: u8| (i32::from(x) - i32::from(y)).pow(2);
        e(q[0], r) + e(q[1], g) + e(q[2], b)
    };
    ACI.iter().min_by_key(|(_, q)| d(*q)).map_or(7, |&(i, _)| i)
}

/// Page units to the ten-thousandths the file keeps, and back.
fn quantize(v: f64) -> i64 {
    (v * 1e4).round() as i64
}

fn unquantize(v: i64) -> f64 {
    v as f64 * 1e-4
}

/// The elements of a linetype (dashes positive, gaps negative, a dot 0) whose pattern of
/// `dash` every `period` starts `phase` into it, as the path's does: a linetype has no phase
/// of its own, so the pattern's elements are rotated to start where the path's does.
fn elements(dash: f64, period: f64, phase: f64) -> Vec<f64> {
    let gap = period - dash;
    if phase <= 0.0 || phase >= period {
        vec![dash, -gap]
    } else if phase < dash {
        // In a dash: its rest, the gap, then the dash up to the phase.
        vec![dash - phase, -gap, phase]
    } else {
        // In a gap: its rest, the dash, then the gap up to the phase.
        let before = phase - dash;
        let mut e = vec![-(period - phase), dash];
        if before > 0.0 {
            e.push(-before);
        }
        e
    }
}

/// The name of the linetype of a pattern and phase.
fn linetype_name(k: usize) -> String {
    format!("WIREPASS{k}")
}

pub(super) fn write(drawing: &Drawing, page: &Page) -> String {
    let s = page.per_pixel;
    let extent = page.extent(drawing.size);
    // Each distinct pattern and phase, in page units, to a ten-thousandth.
    let key = |p: &super::Path| {
        p.pattern
            .map(|v| v * s)
            .map(quantize)
            .into_iter()
            .chain([quantize(p.offset * s)])
            .collect::<Vec<i64>>()
    };
    let mut patterns: Vec<Vec<i64>> = drawing
        .paths
        .iter()
        .filter(|p| p.pattern[1] > 0.0)
        .map(key)
        .collect();
    patterns.sort_unstable();
    patterns.dedup();
    let linetype = |p: &super::Path| -> String {
        if p.pattern[1] > 0.0 {
            linetype_name(patterns.binary_search(&key(p)).unwrap_or(0))
        } else {
            "CONTINUOUS".into()
        }
    };
    let mut out = String::new();
    let mut group = |code: u32, value: &str| {
        let _ = writeln!(out, "{code:>3}\n{value}");
    };
    group(0, "SECTION");
    group(2, "HEADER");
    group(9, "$ACADVER");
    group(1, "AC1009");
    group(9, "$EXTMIN");
    group(10, "0");
    group(20, "0");
    group(9, "$EXTMAX");
    group(10, &number(extent.x));
    group(20, &number(extent.y));
    group(0, "ENDSEC");

    group(0, "SECTION");
    group(2, "TABLES");
    group(0, "TABLE");
    group(2, "LTYPE");
    group(70, &(patterns.len() + 1).to_string());
    group(0, "LTYPE");
    group(2, "CONTINUOUS");
    group(70, "0");
    group(3, "Solid line");
    group(72, "65");
    group(73, "0");
    group(40, "0");
    for (k, p) in patterns.iter().enumerate() {
        let [dash, period, phase] = [p[0], p[1], p[2]].map(unquantize);
        let elements = elements(dash, period, phase);
        group(0, "LTYPE");
        group(2, &linetype_name(k));
        group(70, "0");
        group(
            3,
            &format!(
                "dash {} gap {} from {}",
                number(dash),
                number(period - dash),
                number(phase)
            ),
        );
        group(72, "65");
        group(73, &elements.len().to_string());
        group(40, &number(period));
        for e in elements {
            group(49, &number(e));
        }
    }
    group(0, "ENDTAB");
    group(0, "TABLE");
    group(2, "LAYER");
    group(70, &PathClass::ALL.len().to_string());
    for class in PathClass::ALL {
        let first = drawing.of_class(class).next();
        group(0, "LAYER");
        group(2, &class.name().to_ascii_uppercase());
        group(70, "0");
        group(62, &first.map_or(7, |p| aci(p.color)).to_string());
        group(6, &first.map_or("CONTINUOUS".into(), linetype));
    }
    group(0, "ENDTAB");
    group(0, "ENDSEC");

    group(0, "SECTION");
    group(2, "ENTITIES");
    for p in &drawing.paths {
        let layer = p.class.name().to_ascii_uppercase();
        group(0, "POLYLINE");
        group(8, &layer);
        group(6, &linetype(p));
        group(62, &aci(p.color).to_string());
        group(66, "1");
        group(10, "0");
        group(20, "0");
        group(30, "0");
        // The pattern runs on along the whole polyline, not restarting at each vertex.
        group(70, "128");
        for q in &p.points {
            group(0, "VERTEX");
            group(8, &layer);
            group(10, &number(q.x * s));
            group(20, &number(extent.y - q.y * s));
            group(30, "0");
        }
        group(0, "SEQEND");
        group(8, &layer);
    }
    group(0, "ENDSEC");
    group(0, "EOF");
    out
}
