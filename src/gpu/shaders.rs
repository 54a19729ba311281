//! WGSL sources. Each pass's module is `common.wgsl` followed by the pass's own files, so the
//! shared definitions (edge math, line profile, shading) exist once.
//!
//! Settings that are constant over a frame specialise the source itself, with
//! `#if NAME` / `#else` / `#endif` lines resolved here: a pipeline contains only the code and
//! the bindings its frame uses (no branch on a uniform that no pixel takes, which a software
//! rasterizer would still pay for, and no binding a device with default limits cannot
//! afford).

/// Definitions shared by every pass; the Rust twins live in `edge_math`, `style` and
/// `gpu::mesh_store`.
pub const COMMON: &str = include_str!("../../shaders/common.wgsl");
/// The scene's bindings and fetches (instances, the mesh store, the id target), and the
/// exact per-pixel triangle test, shared by the trace and edge passes.
pub const SCENE: &str = include_str!("../../shaders/scene.wgsl");
/// Visibility pass: instanced, with `@builtin(primitive_index)`, or vertex-pulled.
pub const VISIBILITY: &str = include_str!("../../shaders/visibility.wgsl");
/// The deferred edge pass (compute).
pub const EDGE_PASS: &str = include_str!("../../shaders/edge_pass.wgsl");
/// The benchmark floor (compute): an id read and a flat colour.
pub const FLOOR: &str = include_str!("../../shaders/floor.wgsl");
/// The trace pass (compute).
pub const TRACE: &str = include_str!("../../shaders/trace.wgsl");
/// The forward single-pass baseline (vertex-pulled altitudes); see `gpu::ForwardPass`.
pub const FORWARD: &str = include_str!("../../shaders/forward.wgsl");
/// The two-pass baseline (fill + edge lines), assembled after [`FORWARD`]; see `gpu::TwoPass`.
pub const TWO_PASS: &str = include_str!("../../shaders/two_pass.wgsl");

/// Drawing a frame's result into the host's render pass (self-contained).
pub const COMPOSITE: &str = include_str!("../../shaders/composite.wgsl");
/// Seeding the targets from the host's depth buffer.
pub const HOST_DEPTH: &str = include_str!("../../shaders/host_depth.wgsl");

/// Storage-texture formats the edge pass can write, with the WGSL name of each.
pub fn storage_format_name(format: wgpu::TextureFormat) -> Option<&'static str> {
    match format {
        wgpu::TextureFormat::Rgba8Unorm => Some("rgba8unorm"),
        wgpu::TextureFormat::Rgba16Float => Some("rgba16float"),
        wgpu::TextureFormat::Rgba32Float => Some("rgba32float"),
        _ => None,
    }
}

/// Resolves `#if NAME`, `#else` and `#endif` lines (nesting allowed): a line is kept when
/// every enclosing condition holds, a condition holding when its name is in `flags`
/// (`#if !NAME` negates).
pub fn specialise(source: &str, flags: &[&str]) -> String {
    let mut stack: Vec<(bool, bool)> = Vec::new(); // (condition, in else)
    let mut out = String::with_capacity(source.len());
    for line in source.lines() {
        let t = line.trim_start();
        if let Some(name) = t.strip_prefix("#if ") {
            let name = name.trim();
            let (neg, name) = match name.strip_prefix('!') {
                Some(n) => (true, n),
                None => (false, name),
            };
            stack.push((flags.contains(&name) != neg, false));
            out.push('\n');
            continue;
        }
        if t.starts_with("#else") {
            if let Some(top) = stack.last_mut() {
                top.1 = true;
            }
            out.push('\n');
            continue;
        }
        if t.starts_with("#endif") {
            stack.pop();
            out.push('\n');
            continue;
        }
        // Blank lines keep line numbers, so compiler messages point at the file's lines.
        if stack.iter().all(|&(cond, in_else)| cond != in_else) {
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}

/// A complete module: `common.wgsl`, then `parts` in order, specialised with `flags`.
/// `enable` directives must come first in WGSL, so they are lifted out of the parts.
pub fn assemble(parts: &[&str], flags: &[&str]) -> String {
    let body = parts.join("\n").replace(
        "UNIFORM_INSTANCE_CAPACITY",
        &super::frame::UNIFORM_INSTANCE_CAPACITY.to_string(),
    );
    let body = specialise(&body, flags);
    let (enables, rest): (Vec<&str>, Vec<&str>) = body
        .lines()
        .partition(|l| l.trim_start().starts_with("enable "));
    format!(
        "{}\n{}\n{}\n{}\n",
        enables.join("\n"),
        constants(),
        specialise(COMMON, flags),
        rest.join("\n")
    )
}

/// The distance the shaders write where no edge is drawn: a finite sentinel, since WGSL has
/// no infinity literal (`edge_math::NO_EDGE`, the f64 twins' "none", is infinite).
pub(crate) const NO_EDGE: f32 = 3.0e38;

/// Bits of an owner word above its instance slot (`OWNER_INSTANCE`): the class of the
/// trace pass's line at a pixel.
const OWNER_CLASS_SHIFT: u32 = crate::scene::MAX_INSTANCES.trailing_zeros();
const _: () = assert!(crate::scene::MAX_INSTANCES.is_power_of_two());
// An owner word keeps a line key's top 12 bits over the owner: slot and class take 20.
const _: () = assert!(OWNER_CLASS_SHIFT + 2 <= 20);

/// Every constant the shaders share with the Rust side, declared in WGSL from its Rust
/// value, so each is written once: the ids, the loop budget, the edge math's margins, the
/// line key, the mesh records' bit layouts, the instance flags and the line classes.
pub fn constants() -> String {
    use super::frame as fr;
    use super::mesh_records as mr;
    use crate::edge_math as em;
    use crate::style::LineClass;
    let u32s: &[(&str, u32)] = &[
        ("BACKGROUND_ID", super::BACKGROUND_ID),
        ("HOST_ID", super::HOST_ID),
        ("MAX_SECTIONS", crate::scene::MAX_SECTIONS as u32),
        ("OWNER_INSTANCE", crate::scene::MAX_INSTANCES - 1),
        ("OWNER_CUT", 1 << OWNER_CLASS_SHIFT),
        ("OWNER_OUTLINE", 2 << OWNER_CLASS_SHIFT),
        ("OWNER_INTERSECTION", 3 << OWNER_CLASS_SHIFT),
        ("OWNER_CLASS", 3 << OWNER_CLASS_SHIFT),
        ("LINE_CLASS_EDGE", LineClass::Edge as u32),
        ("LINE_CLASS_OUTLINE", LineClass::Outline as u32),
        ("LINE_CLASS_HIDDEN", LineClass::Hidden as u32),
        ("LINE_CLASS_CUT", LineClass::Cut as u32),
        ("LINE_CLASS_INTERSECTION", LineClass::Intersection as u32),
        ("KEY_DISTANCE_MAX", crate::style::KEY_DISTANCE_MAX),
        (
            "CLUSTER_TRIANGLES",
            crate::mesh::clusters::CLUSTER_TRIANGLES as u32,
        ),
        (
            "PATCH_TRIANGLES",
            crate::mesh::patches::PATCH_TRIANGLES as u32,
        ),
        ("INSTANCE_EDGES", fr::INSTANCE_EDGES),
        ("INSTANCE_OUTLINES", fr::INSTANCE_OUTLINES),
        ("INSTANCE_HIDDEN", fr::INSTANCE_HIDDEN),
        ("INSTANCE_BEHIND_HOST", fr::INSTANCE_BEHIND_HOST),
        ("INSTANCE_HIDDEN_EDGES", fr::INSTANCE_HIDDEN_EDGES),
        ("INSTANCE_LISTED_EDGES", fr::INSTANCE_LISTED_EDGES),
        ("INSTANCE_PHASES", fr::INSTANCE_PHASES),
        ("INSTANCE_CROSSED", fr::INSTANCE_CROSSED),
        ("INSTANCE_OUTLINE_PHASES", fr::INSTANCE_OUTLINE_PHASES),
        ("OUTLINE_CHAIN_WORDS", fr::OUTLINE_CHAIN_WORDS),
        ("PHASE_ENTRY_WORDS", fr::PHASE_ENTRY_WORDS),
        ("PIECE_WORDS", super::targets::PIECE_WORDS),
        ("NEIGHBOUR_INDEX", mr::MAX_MESH_TRIANGLES),
        ("NEIGHBOUR_CORNER_SHIFT", mr::NEIGHBOUR_CORNER_SHIFT),
        ("NEIGHBOUR_SAME_WAY", mr::NEIGHBOUR_SAME_WAY),
        ("INFO_LARGE_PATCH", mr::INFO_LARGE_PATCH),
        ("INFO_SPLAT_SHIFT", mr::INFO_SPLAT_SHIFT),
        ("INFO_QUAD", mr::INFO_QUAD),
        ("INFO_CHAINED_SHIFT", mr::INFO_CHAINED_SHIFT),
        ("INFO_CROSSED", mr::INFO_CROSSED),
        ("QUAD_EDGE_SHIFT", mr::QUAD_SHIFT),
        ("QUAD_CORNER_SHIFT", mr::QUAD_CORNER_SHIFT),
        ("QUAD_SAME", mr::QUAD_SAME),
        ("QUAD_MASK_SHIFT", mr::QUAD_MASK_SHIFT),
        ("QUAD_NEXT", mr::QUAD_NEXT),
        ("QUAD_PREVIOUS", mr::QUAD_PREVIOUS),
        ("CLASSIFY_COLUMNS", super::targets::CLASSIFY_GROUP.0),
        ("CLASSIFY_ROWS", super::targets::CLASSIFY_GROUP.1),
        ("COMPOSITE_RUN_SHIFT", super::targets::COMPOSITE_RUN_SHIFT),
    ];
    let f32s: &[(&str, f64)] = &[
        ("NO_EDGE", f64::from(NO_EDGE)),
        ("KEY_DISTANCE_STEPS", crate::style::KEY_DISTANCE_STEPS),
        ("EDGE_ON", em::EDGE_ON),
        ("EDGE_ON_MARGIN", crate::mesh::adjacency::EDGE_ON_MARGIN),
        ("HIDDEN_MARGIN", em::HIDDEN_MARGIN),
        ("CAP_MARGIN", em::CAP_MARGIN),
        ("REACH_SLACK", em::REACH_SLACK),
        ("DASH_SLACK", em::DASH_SLACK),
        ("END_INSET", em::END_INSET),
    ];
    let mut out = String::new();
    for (name, value) in u32s {
        out += &format!("const {name}: u32 = {value}u;\n");
    }
    for (name, value) in f32s {
        // Rounded to f32 here, so the literal is the value the shader holds.
        out += &format!("const {name}: f32 = {:e};\n", *value as f32);
    }
    out + &super::loop_budget::wgsl()
}

/// The colour encoding of an output format: 8-bit unorm storage textures cannot be sRGB, so
/// the shader writes sRGB-encoded values into them; float formats hold linear values.
pub fn encode_output(format: wgpu::TextureFormat) -> &'static str {
    if format == wgpu::TextureFormat::Rgba8Unorm {
        "fn encode_output(c: vec4<f32>) -> vec4<f32> { return vec4<f32>(linear_to_srgb(c.rgb), c.a); }"
    } else {
        "fn encode_output(c: vec4<f32>) -> vec4<f32> { return c; }"
    }
}

/// The visibility pass's module: vertex-pulled or not, for a split store or not, cutting by
/// section planes or not.
pub fn visibility_source(pulled: bool, split: bool, sections: bool) -> String {
    let mut flags = vec![];
    if sections {
        flags.push("SECTIONS");
    }
    if pulled {
        flags.push("PULLED");
    }
    if split {
        flags.push("SPLIT");
    }
    assemble(&[VISIBILITY], &flags)
}

/// The edge pass's module (with the floor) for an output of `format` (one of
/// [`storage_format_name`]'s) and the frame's `flags`.
pub fn edge_source(format: wgpu::TextureFormat, flags: &[&str]) -> String {
    let name = storage_format_name(format).unwrap_or("rgba8unorm");
    let edge = EDGE_PASS.replace("OUTPUT_FORMAT", name);
    let floor = FLOOR.replace("OUTPUT_FORMAT", name);
    assemble(&[SCENE, &edge, &floor, encode_output(format)], flags)
}

/// The trace pass's module for the frame's `flags`.
pub fn trace_source(flags: &[&str]) -> String {
    assemble(&[SCENE, TRACE], flags)
}

/// The host-depth seeding module, for a single- or multisampled host depth texture.
pub fn host_depth_source(multisampled: bool) -> String {
    let flags: &[&str] = if multisampled { &["MULTISAMPLED"] } else { &[] };
    assemble(&[HOST_DEPTH], flags)
}

/// The composite's module: testing the host's depth per sample (`tested`) or not.
pub fn composite_source(tested: bool, encode_srgb: bool) -> String {
    let flags = [("TESTED", tested), ("ENCODE_SRGB", encode_srgb)];
    let flags: Vec<&str> = flags.iter().filter(|f| f.1).map(|f| f.0).collect();
    assemble(&[COMPOSITE], &flags)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specialise_keeps_what_the_flags_select() {
        let src = "a\n#if X\nb\n#if !Y\nc\n#else\nd\n#endif\n#else\ne\n#endif\nf";
        let lines = |flags: &[&str]| -> Vec<String> {
            specialise(src, flags)
                .lines()
                .filter(|l| !l.is_empty())
                .map(str::to_owned)
                .collect()
        };
        assert_eq!(lines(&[]), ["a", "e", "f"]);
        assert_eq!(lines(&["X"]), ["a", "b", "c", "f"]);
        assert_eq!(lines(&["X", "Y"]), ["a", "b", "d", "f"]);
        assert_eq!(specialise(src, &[]).lines().count(), src.lines().count());
    }

    /// The constants declared from Rust (`constants`) are the only declarations of their
    /// names, each is used by some shader, and each f32 literal is a finite f32.
    #[test]
    fn shared_constants_are_declared_once_from_rust() {
        let declared = constants();
        let sources = [
            COMMON, SCENE, VISIBILITY, EDGE_PASS, FLOOR, TRACE, FORWARD, TWO_PASS, COMPOSITE,
            HOST_DEPTH,
        ];
        let mut names = std::collections::HashSet::new();
        for line in declared.lines() {
            let rest = line.strip_prefix("const ").expect("one declaration a line");
            let (name, rest) = rest.split_once(':').unwrap();
            assert!(names.insert(name.to_owned()), "{name} declared twice");
            let pattern = format!("const {name}:");
            for source in sources {
                assert!(
                    !source.contains(&pattern),
                    "{name} is also declared in a .wgsl file"
                );
            }
            let used = |s: &str| {
                s.match_indices(name).any(|(i, _)| {
                    let after = s[i + name.len()..].chars().next();
                    let before = s[..i].chars().last();
                    let word = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
                    !word(after) && !word(before)
                })
            };
            assert!(
                sources.iter().any(|s| used(s)),
                "{name} is declared but used by no shader"
            );
            if let Some(literal) = rest.strip_prefix(" f32 = ") {
                let value: f32 = literal.trim_end_matches(';').parse().unwrap();
                assert!(value.is_finite(), "{name} = {literal}");
            }
        }
        assert!(names.contains("MAX_SECTIONS") && names.contains("LINE_CLASS_INTERSECTION"));
    }
}
