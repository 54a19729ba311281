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
/// exact per-pixel triangle test, shared by the outline and edge passes.
pub const SCENE: &str = include_str!("../../shaders/scene.wgsl");
/// Visibility pass: instanced, with `@builtin(primitive_index)`, or vertex-pulled.
pub const VISIBILITY: &str = include_str!("../../shaders/visibility.wgsl");
/// The deferred edge pass (compute).
pub const EDGE_PASS: &str = include_str!("../../shaders/edge_pass.wgsl");
/// The benchmark floor (compute): an id read and a flat colour.
pub const FLOOR: &str = include_str!("../../shaders/floor.wgsl");
/// The outline pass (compute).
pub const OUTLINE: &str = include_str!("../../shaders/outline.wgsl");
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

/// The constants the shaders share with the Rust side, declared from their Rust values.
fn constants() -> String {
    format!(
        "const BACKGROUND_ID: u32 = {}u;\nconst HOST_ID: u32 = {}u;\n{}",
        super::BACKGROUND_ID,
        super::HOST_ID,
        super::loop_budget::wgsl()
    )
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

/// The outline pass's module for the frame's `flags`.
pub fn outline_source(flags: &[&str]) -> String {
    assemble(&[SCENE, OUTLINE], flags)
}

/// The host-depth seeding module, for a single- or multisampled host depth texture.
pub fn host_depth_source(multisampled: bool) -> String {
    let flags: &[&str] = if multisampled { &["MULTISAMPLED"] } else { &[] };
    assemble(&[HOST_DEPTH], flags)
}

/// The composite's module: testing the host's depth per sample (`tested`) or not.
pub fn composite_source(tested: bool) -> String {
    let flags: &[&str] = if tested { &["TESTED"] } else { &[] };
    assemble(&[COMPOSITE], flags)
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
}
