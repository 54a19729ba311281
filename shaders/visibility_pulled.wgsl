// Visibility pass for adapters without PRIMITIVE_INDEX: a non-indexed draw of 3 × triangles
// vertices pulls its vertices from storage buffers and passes the id as a flat varying.
// Prepended with common.wgsl.

struct Draw {
    first_id: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> draw: Draw;
@group(0) @binding(2) var<storage, read> positions: array<f32>;
@group(0) @binding(3) var<storage, read> indices: array<u32>;
// The second half of `indices`, for meshes split over two bindings (src/gpu/mesh.rs).
@group(0) @binding(4) var<storage, read> indices_hi: array<u32>;

struct Varyings {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) id: u32,
}

@vertex
fn vs_main(@builtin(vertex_index) corner: u32) -> Varyings {
    let split = 3u * frame.index_split;
    var v: u32;
    if corner < split {
        v = indices[corner];
    } else {
        v = indices_hi[corner - split];
    }
    let p = vec3<f32>(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
    return Varyings(reverse_z(frame.view_proj, frame.depth_row, p), draw.first_id + corner / 3u);
}

@fragment
fn fs_main(in: Varyings) -> @location(0) u32 {
    return in.id;
}
