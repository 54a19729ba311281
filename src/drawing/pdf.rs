//! PDF: one page of vector paths (with `pdf-writer`, which keeps the file's cross-reference
//! table right), drawn in the view's pixels through one transform to points.

use super::{Drawing, Page, PageUnit};
use pdf_writer::types::{LineCapStyle, LineJoinStyle};
use pdf_writer::{Content, Name, Pdf, Rect, Ref};

/// Points (1/72 inch) per page unit.
fn points_per(unit: PageUnit) -> f64 {
    match unit {
        PageUnit::Pixel => 72.0 / 96.0,
        PageUnit::Millimetre => 72.0 / 25.4,
    }
}

pub(super) fn write(drawing: &Drawing, page: &Page) -> Vec<u8> {
    let scale = page.per_pixel * points_per(page.unit);
    let (w, h) = (
        f64::from(drawing.size.0) * scale,
        f64::from(drawing.size.1) * scale,
    );
    let (catalog, tree, page_id, content_id) = (Ref::new(1), Ref::new(2), Ref::new(3), Ref::new(4));
    // One graphics state per stroke opacity below 1.
    let mut alphas: Vec<u32> = drawing
        .paths
        .iter()
        .map(|p| p.color.0[3].clamp(0.0, 1.0).to_bits())
        .chain(std::iter::once(
            drawing.background.0[3].clamp(0.0, 1.0).to_bits(),
        ))
        .filter(|&a| f32::from_bits(a) < 1.0)
        .collect();
    alphas.sort_unstable();
    alphas.dedup();
    let state = |a: f32| alphas.binary_search(&a.clamp(0.0, 1.0).to_bits()).ok();
    let name = |k: usize| format!("A{k}");

    let mut pdf = Pdf::new();
    pdf.catalog(catalog).pages(tree);
    pdf.pages(tree).kids([page_id]).count(1);
    {
        let mut p = pdf.page(page_id);
        p.parent(tree)
            .media_box(Rect::new(0.0, 0.0, w as f32, h as f32))
            .contents(content_id);
        let mut resources = p.resources();
        let mut states = resources.ext_g_states();
        for k in 0..alphas.len() {
            states.pair(Name(name(k).as_bytes()), Ref::new(5 + k as i32));
        }
    }
    for (k, &a) in alphas.iter().enumerate() {
        let a = f32::from_bits(a);
        pdf.ext_graphics(Ref::new(5 + k as i32))
            .stroking_alpha(a)
            .non_stroking_alpha(a);
    }

    let mut c = Content::new();
    // Pixels (y down) to points (y up).
    c.transform([scale as f32, 0.0, 0.0, -scale as f32, 0.0, h as f32]);
    let [r, g, b] = srgb(drawing.background);
    if drawing.background.0[3] > 0.0 {
        c.save_state();
        if let Some(k) = state(drawing.background.0[3]) {
            c.set_parameters(Name(name(k).as_bytes()));
        }
        c.set_fill_rgb(r, g, b)
            .rect(0.0, 0.0, drawing.size.0 as f32, drawing.size.1 as f32)
            .fill_nonzero();
        c.restore_state();
    }
    c.set_line_cap(LineCapStyle::RoundCap);
    c.set_line_join(LineJoinStyle::RoundJoin);
    for path in &drawing.paths {
        c.save_state();
        if let Some(k) = state(path.color.0[3]) {
            c.set_parameters(Name(name(k).as_bytes()));
        }
        let [r, g, b] = srgb(path.color);
        c.set_stroke_rgb(r, g, b).set_line_width(path.width as f32);
        let [dash, period] = path.pattern;
        if period > 0.0 {
            c.set_dash_pattern([dash as f32, (period - dash) as f32], path.offset as f32);
        }
        for (k, q) in path.points.iter().enumerate() {
            if k == 0 {
                c.move_to(q.x as f32, q.y as f32);
            } else {
                c.line_to(q.x as f32, q.y as f32);
            }
        }
        c.stroke();
        c.restore_state();
    }
    pdf.stream(content_id, &c.finish());
    pdf.finish()
}

/// The colour's sRGB components, 0..1.
fn srgb(c: crate::style::Color) -> [f32; 3] {
    let [r, g, b, _] = c.to_srgb8();
    [r, g, b].map(|v| f32::from(v) / 255.0)
}
