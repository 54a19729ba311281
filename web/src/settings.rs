//! What the `<wirepass-viewer>` element's attributes say, parsed into wirepass's settings.
//! Free of the browser, so the element's native tests draw the same view for the references
//! the browser is held against.

use wirepass::camera::Orbit;
use wirepass::glam::DVec3;
use wirepass::{Color, EdgeSelection, HiddenLines, LinePattern, SectionPlane, Style, MAX_SECTIONS};

/// `edges`: `file` (each file's own: a glTF's authored edges, polygon edges otherwise),
/// `polygon`, `feature[:DEGREES]` or `all`.
pub fn edges(s: &str) -> Result<Option<EdgeSelection>, String> {
    match s.trim() {
        "" | "file" => Ok(None),
        other => other.parse().map(Some).map_err(|e: wirepass::Error| {
            format!("edges {other:?} is not file, polygon, feature[:DEGREES] or all ({e})")
        }),
    }
}

/// The name `edges` parses back from.
pub fn edges_name(edges: Option<EdgeSelection>) -> String {
    match edges {
        None => "file".into(),
        Some(EdgeSelection::All) => "all".into(),
        Some(EdgeSelection::Polygon) => "polygon".into(),
        Some(EdgeSelection::Authored) => "authored".into(),
        Some(EdgeSelection::Feature(deg)) => format!("feature:{deg}"),
    }
}

/// `hidden`: `off`, `solid`, `dashed[:DASH,GAP]` or `dotted[:SPACING]`, in pixels.
pub fn hidden(s: &str) -> Result<Option<HiddenLines>, String> {
    let s = s.trim();
    if s.is_empty() {
        return Ok(None);
    }
    let pattern = LinePattern::parse(s).map_err(|e| e.to_string())?;
    Ok(pattern.map(|pattern| HiddenLines {
        pattern,
        ..HiddenLines::default()
    }))
}

/// `outlines`: present and not `false` or `off` draws them.
pub fn switch(s: Option<&str>) -> bool {
    !matches!(s.map(str::trim), None | Some("false" | "off"))
}

/// A colour attribute: `#rgb`, `#rrggbb` or `#rrggbbaa`, sRGB.
pub fn color(s: &str) -> Result<Color, String> {
    Color::from_hex(s.trim()).map_err(|e| e.to_string())
}

/// `line-width`: pixels, a positive number.
pub fn line_width(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(w) if w.is_finite() && w > 0.0 => Ok(w),
        _ => Err(format!(
            "line-width {s:?} is not a positive number of pixels"
        )),
    }
}

/// Sets `style`'s attribute `name` (`outlines`, `hidden`, `line-width`, `line-color`,
/// `background`) to `value` (`None`: removed, the default); `None` where `name` is not one
/// of the style's. A value it cannot read changes nothing.
pub fn apply_style(
    style: &mut Style,
    name: &str,
    value: Option<&str>,
) -> Option<Result<(), String>> {
    let default = Style::default();
    Some(match name {
        "outlines" => {
            style.outlines = value.map_or(default.outlines, |v| switch(Some(v)));
            Ok(())
        }
        "hidden" => hidden(value.unwrap_or("")).map(|h| style.hidden = h),
        "line-width" => value
            .map_or(Ok(default.line_width), line_width)
            .map(|w| style.line_width = w),
        "line-color" => value
            .map_or(Ok(default.wire_color), color)
            .map(|c| style.wire_color = c),
        "background" => value
            .map_or(Ok(default.background), color)
            .map(|c| style.background = c),
        _ => return None,
    })
}

/// `sections`: up to [`MAX_SECTIONS`] planes separated by `;`, each `PX,PY,PZ,NX,NY,NZ` (a
/// point on it and its normal, world units; the side the normal points to is kept).
pub fn sections(s: &str) -> Result<Vec<SectionPlane>, String> {
    let planes: Vec<SectionPlane> = s
        .split(';')
        .map(str::trim)
        .filter(|p| !p.is_empty())
        .map(|p| SectionPlane::parse(p).map_err(|e| format!("sections: {e}")))
        .collect::<Result<_, _>>()?;
    if planes.len() > MAX_SECTIONS {
        return Err(format!(
            "sections: {} planes, at most {MAX_SECTIONS}",
            planes.len()
        ));
    }
    for (k, plane) in planes.iter().enumerate() {
        plane.validate(k).map_err(|e| format!("sections: {e}"))?;
    }
    Ok(planes)
}

/// `camera`, for a model within `bounds`: empty for the default view (a little from above
/// and to the side); a named view `front` (+Z), `back`, `left`, `right` (+X), `top` (+Y),
/// `bottom` or `iso`; or an orbit position `YAW PITCH [DISTANCE]`, degrees about the
/// vertical axis from +Z towards +X, degrees of elevation (within ±85.9, the orbit's limit)
/// and the distance from the model's centre in world units (default: the framing distance).
/// The orbit always circles the centre of the model's box.
pub fn orbit(camera: &str, bounds: (DVec3, DVec3)) -> Result<Orbit, String> {
    let mut orbit = Orbit::framing(bounds.0, bounds.1);
    let (yaw, pitch) = match camera.trim() {
        "" => return Ok(orbit),
        "front" => (0.0, 0.0),
        "back" => (180.0, 0.0),
        "right" => (90.0, 0.0),
        "left" => (-90.0, 0.0),
        "top" => (0.0, 90.0),
        "bottom" => (0.0, -90.0),
        // The cube's corner (1, 1, 1): 45° around, atan(1/√2) up.
        "iso" => (45.0, 35.264_389_682_754_654),
        position => {
            let bad = || {
                format!(
                    "camera {position:?} is not front, back, left, right, top, bottom, iso or \
                     YAW PITCH [DISTANCE] (degrees, degrees, world units)"
                )
            };
            let n: Vec<f64> = position
                .split(|c: char| c.is_whitespace() || c == ',')
                .filter(|t| !t.is_empty())
                .map(|t| t.parse::<f64>().map_err(|_| bad()))
                .collect::<Result<_, _>>()?;
            let (yaw, pitch, distance) = match n[..] {
                [yaw, pitch] => (yaw, pitch, orbit.distance),
                [yaw, pitch, distance] => (yaw, pitch, distance),
                _ => return Err(bad()),
            };
            if !(yaw.is_finite() && pitch.is_finite() && distance.is_finite() && distance > 0.0) {
                return Err(bad());
            }
            orbit.distance = distance;
            (yaw, pitch)
        }
    };
    orbit.yaw = f64::to_radians(yaw);
    orbit.pitch = f64::to_radians(pitch).clamp(-1.5, 1.5);
    Ok(orbit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attributes_parse_and_name_their_errors() {
        assert_eq!(edges("file").unwrap(), None);
        assert_eq!(
            edges("feature:30").unwrap(),
            Some(EdgeSelection::Feature(30.0))
        );
        assert!(edges("some").unwrap_err().contains("\"some\""));
        assert!(hidden("off").unwrap().is_none());
        assert!(hidden("dashed:6,3").unwrap().is_some());
        assert!(hidden("wavy").is_err());
        assert!(switch(Some("")) && !switch(Some("false")) && !switch(None));
        assert!(line_width("0").is_err() && line_width("NaN").is_err());
        assert_eq!(sections("0,0,0,0,1,0; 0,0,0,1,0,0").unwrap().len(), 2);
        assert!(sections("0,0,0,0,0,0").is_err());
        assert!(sections(&"0,0,0,0,1,0;".repeat(7)).is_err());
        let bounds = (DVec3::splat(-1.0), DVec3::ONE);
        let front = orbit("front", bounds).unwrap();
        let eye = front.camera().eye.as_dvec3();
        assert!(eye.x.abs() < 1e-6 && eye.y.abs() < 1e-6 && eye.z > 0.0);
        let right = orbit("90 0 5", bounds).unwrap();
        assert!((right.camera().eye.as_dvec3() - DVec3::new(5.0, 0.0, 0.0)).length() < 1e-5);
        assert!(orbit("30", bounds).is_err() && orbit("0 0 -1", bounds).is_err());
    }
}
