// Draws a frame's result (premultiplied linear RGBA, written by the edge pass in its result
// mode) into the host's own render pass: one triangle over the viewport, blended with
// (One, OneMinusSrcAlpha). The host's colour attachment decides the encoding: sRGB formats
// store sRGB and blend in linear light, float formats hold linear values. Self-contained.

@group(0) @binding(34) var result: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<i32>(textureDimensions(result));
    let xy = clamp(vec2<i32>(floor(position.xy)), vec2<i32>(0), size - 1);
    return textureLoad(result, xy, 0);
}
