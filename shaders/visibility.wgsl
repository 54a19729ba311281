// Visibility pass: triangle id (draw's first id + primitive index) and depth per pixel.
// Prepended with common.wgsl.

enable primitive_index;

struct Draw {
    first_id: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> draw: Draw;

@vertex
fn vs_main(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return reverse_z(frame.view_proj, frame.depth_row, position);
}

@fragment
fn fs_main(@builtin(primitive_index) primitive: u32) -> @location(0) u32 {
    return draw.first_id + primitive;
}
