//! WGSL sources. Each pass's module is `common.wgsl` followed by the pass's own file, so the
//! shared definitions (edge math, line profile, shading) exist once.

/// Definitions shared by every pass; the Rust twins live in `edge_math` and `style`.
pub const COMMON: &str = include_str!("../../shaders/common.wgsl");
/// Visibility pass using `@builtin(primitive_index)`.
pub const VISIBILITY: &str = include_str!("../../shaders/visibility.wgsl");
/// Visibility pass for adapters without `PRIMITIVE_INDEX`: vertex pulling, flat id.
pub const VISIBILITY_PULLED: &str = include_str!("../../shaders/visibility_pulled.wgsl");
/// The deferred edge pass (compute).
pub const EDGE_PASS: &str = include_str!("../../shaders/edge_pass.wgsl");
/// The outline pass (compute), assembled after [`EDGE_PASS`] into the same module.
pub const OUTLINE: &str = include_str!("../../shaders/outline.wgsl");
/// The forward single-pass baseline (vertex-pulled altitudes); see `gpu::ForwardPass`.
pub const FORWARD: &str = include_str!("../../shaders/forward.wgsl");
/// The two-pass baseline (fill + edge lines), assembled after [`FORWARD`]; see `gpu::TwoPass`.
pub const TWO_PASS: &str = include_str!("../../shaders/two_pass.wgsl");

/// Storage-texture formats the edge pass can write, with the WGSL name of each.
pub fn storage_format_name(format: wgpu::TextureFormat) -> Option<&'static str> {
    match format {
        wgpu::TextureFormat::Rgba8Unorm => Some("rgba8unorm"),
        wgpu::TextureFormat::Rgba16Float => Some("rgba16float"),
        wgpu::TextureFormat::Rgba32Float => Some("rgba32float"),
        _ => None,
    }
}

/// A complete module: the common definitions, then `body`. `enable` directives must come
/// first in WGSL, so they are lifted out of `body`.
pub fn assemble(body: &str) -> String {
    let (enables, rest): (Vec<&str>, Vec<&str>) = body
        .lines()
        .partition(|l| l.trim_start().starts_with("enable "));
    format!("{}\n{COMMON}\n{}\n", enables.join("\n"), rest.join("\n"))
}

/// The edge pass and the outline pass for an output texture of `format`: 8-bit outputs are written sRGB-encoded
/// (storage textures cannot be sRGB), float outputs linear.
pub fn edge_pass(format: wgpu::TextureFormat) -> Option<String> {
    let name = storage_format_name(format)?;
    let encode = if format == wgpu::TextureFormat::Rgba8Unorm {
        "fn encode_output(c: vec4<f32>) -> vec4<f32> { return vec4<f32>(linear_to_srgb(c.rgb), c.a); }"
    } else {
        "fn encode_output(c: vec4<f32>) -> vec4<f32> { return c; }"
    };
    Some(assemble(&format!(
        "{}\n{OUTLINE}\n{encode}\n",
        EDGE_PASS.replace("OUTPUT_FORMAT", name)
    )))
}
