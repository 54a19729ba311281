//! DXF, release 12 (`AC1009`), which every CAD program imports: a layer per class, a
//! linetype per pattern, a `POLYLINE` per path in page units with y up.
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

/// The name of the linetype of a pattern (dash, period in page units).
fn linetype_name(k: usize) -> String {
    format!("WIREPASS{k}")
}

pub(super) fn write(drawing: &Drawing, page: &Page) -> String {
    let s = page.per_pixel;
    let extent = page.extent(drawing.size);
    // Each distinct pattern, in page units.
    let mut patterns: Vec<[u64; 2]> = drawing
        .paths
        .iter()
        .filter(|p| p.pattern[1] > 0.0)
        .map(|p| p.pattern.map(|v| (v * s).to_bits()))
        .collect();
    patterns.sort_unstable();
    patterns.dedup();
    let linetype = |p: &super::Path| -> String {
        if p.pattern[1] > 0.0 {
            let key = p.pattern.map(|v| (v * s).to_bits());
            linetype_name(patterns.binary_search(&key).unwrap_or(0))
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
        let [dash, period] = p.map(f64::from_bits);
        group(0, "LTYPE");
        group(2, &linetype_name(k));
        group(70, "0");
        group(
            3,
            &format!("dash {} gap {}", number(dash), number(period - dash)),
        );
        group(72, "65");
        group(73, "2");
        group(40, &number(period));
        group(49, &number(dash));
        group(49, &number(-(period - dash)));
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
