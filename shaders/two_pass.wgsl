// Two-pass wireframe, the "standard" approach the seeds set out to beat: a shaded fill with a
// depth bias that pushes it back, then the drawn edges as 1-pixel hardware lines over it.
// Assembled as common.wgsl + forward.wgsl + this file: it reuses forward.wgsl's bindings and
// `surface_color`, but not its altitude computation.
//
// The lines are a LineList over the mesh's own position buffer with an index buffer of the
// unique drawn edges (see src/gpu/two_pass.rs), so masked edges (polygon diagonals) are never
// drawn and `PolygonMode::Line` is not needed.

struct FillVaryings {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) face_normal: vec3<f32>,
    @location(3) @interpolate(flat) id: u32,
}

// Fill: vertex pulling, for the flat triangle id that adapters without PRIMITIVE_INDEX
// cannot otherwise give; the clip position is the visibility pass's expression.
@vertex
fn vs_fill(@builtin(vertex_index) k: u32) -> FillVaryings {
    let t = k / 3u;
    let corner = k - 3u * t;
    let v = corners(t);
    let w0 = position(v.x);
    let w1 = position(v.y);
    let w2 = position(v.z);
    let own_index = v[corner];
    let own = position(own_index);
    var out: FillVaryings;
    out.clip = reverse_z(frame.view_proj, frame.depth_row, own);
    out.world = own;
    out.normal = normal(own_index);
    out.face_normal = cross(w1 - w0, w2 - w0);
    out.id = draw.first_id + t;
    return out;
}

fn fill_color(in: FillVaryings) -> vec4<f32> {
    return vec4<f32>(surface_color(frame, in.world, in.normal, in.face_normal), 1.0);
}

@fragment
fn fs_fill(in: FillVaryings) -> @location(0) vec4<f32> {
    return encode_output(fill_color(in));
}

struct FillMaps {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
    // f32 bits, as in forward.wgsl. r: no distance is measured (NO_EDGE; the line pass writes
    // 0 where it draws), g: the raster depth as FragCoord.z reports it.
    @location(2) diag: vec4<u32>,
}

@fragment
fn fs_fill_maps(in: FillVaryings) -> FillMaps {
    let diag = vec4<u32>(bitcast<u32>(NO_EDGE), bitcast<u32>(in.clip.z), 0u, 0u);
    return FillMaps(encode_output(fill_color(in)), in.id, diag);
}

struct LineVaryings {
    @builtin(position) clip: vec4<f32>,
    // View depth, for the depth fade; affine along the line, so interpolated exactly.
    @location(0) w: f32,
}

// Lines: the mesh's positions as a vertex buffer, the edge list as the index buffer.
@vertex
fn vs_line(@location(0) p: vec3<f32>) -> LineVaryings {
    let clip = reverse_z(frame.view_proj, frame.depth_row, p);
    return LineVaryings(clip, clip.w);
}

// The wire colour with its alpha and the depth fade; the pipeline blends it over the fill.
fn line_color(in: LineVaryings) -> vec4<f32> {
    let alpha = frame.wire_color.a * depth_fade(in.w, frame.fade);
    return vec4<f32>(encode_output(vec4<f32>(frame.wire_color.rgb, 1.0)).rgb, alpha);
}

@fragment
fn fs_line(in: LineVaryings) -> @location(0) vec4<f32> {
    return line_color(in);
}

struct LineMaps {
    @location(0) color: vec4<f32>,
    // Write mask empty: a line covers no triangle, so the fill's id stays.
    @location(1) id: u32,
    // Write mask red only: distance 0 where a line was drawn, the fill's depth stays in g.
    @location(2) diag: vec4<u32>,
}

@fragment
fn fs_line_maps(in: LineVaryings) -> LineMaps {
    return LineMaps(line_color(in), 0xffffffffu, vec4<u32>(0u)); // 0u = bits of 0.0
}
