//! SVG: a group per class, one `<path>` per path, in the view's pixels (the `viewBox`), on
//! a page of the page's size and unit.

use super::{Drawing, Page, PageUnit, PathClass};
use crate::style::Color;
use std::fmt::Write;

/// `v` with at most four decimals (a twentieth of a thousandth of a pixel), no trailing
/// zeros.
pub(super) fn number(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// `#rrggbb` (sRGB) and the alpha.
pub(super) fn hex(c: Color) -> (String, f32) {
    let [r, g, b, _] = c.to_srgb8();
    (format!("#{r:02x}{g:02x}{b:02x}"), c.0[3].clamp(0.0, 1.0))
}

pub(super) fn write(drawing: &Drawing, page: &Page) -> String {
    let (w, h) = (drawing.size.0, drawing.size.1);
    let extent = page.extent(drawing.size);
    let unit = match page.unit {
        PageUnit::Pixel => "",
        PageUnit::Millimetre => "mm",
    };
    let mut out = String::new();
    let _ = writeln!(out, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}{unit}" height="{}{unit}" viewBox="0 0 {w} {h}">"#,
        number(extent.x),
        number(extent.y)
    );
    let (background, opacity) = hex(drawing.background);
    if opacity > 0.0 {
        let _ = writeln!(
            out,
            r#"<rect width="{w}" height="{h}" fill="{background}"{}/>"#,
            alpha("fill-opacity", opacity)
        );
    }
    for class in PathClass::ALL {
        let mut paths = drawing.of_class(class).peekable();
        if paths.peek().is_none() {
            continue;
        }
        let _ = writeln!(
            out,
            r#"<g id="{}" fill="none" stroke-linecap="round" stroke-linejoin="round">"#,
            class.name()
        );
        for p in paths {
            let mut d = String::with_capacity(16 * p.points.len());
            for (k, q) in p.points.iter().enumerate() {
                let _ = write!(
                    d,
                    "{}{} {}",
                    if k == 0 { "M" } else { " L" },
                    number(q.x),
                    number(q.y)
                );
            }
            let (color, opacity) = hex(p.color);
            let [dash, period] = p.pattern;
            let pattern = if period > 0.0 {
                format!(
                    r#" stroke-dasharray="{} {}" stroke-dashoffset="{}""#,
                    number(dash),
                    number(period - dash),
                    number(p.offset)
                )
            } else {
                String::new()
            };
            let _ = writeln!(
                out,
                r#"<path d="{d}" stroke="{color}"{} stroke-width="{}"{pattern}/>"#,
                alpha("stroke-opacity", opacity),
                number(p.width)
            );
        }
        let _ = writeln!(out, "</g>");
    }
    out.push_str("</svg>\n");
    out
}

fn alpha(name: &str, a: f32) -> String {
    if a < 1.0 {
        format!(r#" {name}="{}""#, number(f64::from(a)))
    } else {
        String::new()
    }
}
