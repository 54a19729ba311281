// Two-pass wireframe, the "standard" approach that Bærentzen et al. 2006 ("Single-pass wireframe rendering") set out to beat: a shaded fill with a
// depth bias that pushes it back, then the drawn edges as 1-pixel hardware lines over it.
// Assembled as common.wgsl + scene.wgsl + forward.wgsl + this file: it reuses forward.wgsl's
// vertex pulling and shading, but not its altitude computation.
//
// The lines are, per mesh, an instanced LineList over the mesh store's vertices with an
// index buffer of the mesh's unique drawn edges (see src/gpu/two_pass.rs), so masked edges
// (polygon diagonals) are never drawn and `PolygonMode::Line` is not needed.

struct FillMaps {
    @location(0) color: vec4<f32>,
    @location(1) id: vec2<u32>,
    // f32 bits, as in forward.wgsl. r: no distance is measured (NO_EDGE; the line pass writes
    // 0 where it draws), g: the raster depth as FragCoord.z reports it.
    @location(2) diag: vec4<u32>,
}

fn fill_color(in: Varyings) -> vec4<f32> {
    return vec4<f32>(surface_color(frame, instances[in.slot], in.local, in.normal, in.face_normal), 1.0);
}

// The fill uses forward.wgsl's `vs_main` (vertex pulling gives the flat triangle id that
// adapters without PRIMITIVE_INDEX cannot otherwise give).
@fragment
fn fs_fill(in: Varyings) -> @location(0) vec4<f32> {
    return encode_output(fill_color(in));
}

@fragment
fn fs_fill_maps(in: Varyings) -> FillMaps {
    let diag = vec4<u32>(bitcast<u32>(NO_EDGE), bitcast<u32>(in.clip.z), bitcast<u32>(NO_EDGE), 0u);
    return FillMaps(encode_output(fill_color(in)), vec2<u32>(in.slot, in.tri), diag);
}

struct LineVaryings {
    @builtin(position) clip: vec4<f32>,
    // View depth, for the depth fade; affine along the line.
    @location(0) depth: f32,
    @location(1) @interpolate(flat) slot: u32,
}

// Lines: the store's vertices as a vertex buffer, the mesh's edge list as the index buffer,
// the instance records as an instance-rate buffer for the slot. An instance whose edges are
// off, or whose line width is 0, puts its lines at w = 0, where nothing is rasterized.
@vertex
fn vs_line(@location(0) p: vec3<f32>, @location(7) slot: u32) -> LineVaryings {
    let inst = instances[slot];
    var clip = raster_position(frame, inst.clip, inst.depth_row, p);
    if (inst.flags & INSTANCE_EDGES) == 0u || !(inst.line_width > 0.0) {
        clip = vec4<f32>(0.0);
    }
    return LineVaryings(clip, dot(inst.fade_row, vec4<f32>(p, 1.0)), slot);
}

// The wire colour with its alpha and the depth fade; the pipeline blends it over the fill.
fn line_color(in: LineVaryings) -> vec4<f32> {
    let wire = instances[in.slot].wire_color;
    let alpha = wire.a * depth_fade(in.depth, frame.fade);
    return vec4<f32>(encode_output(vec4<f32>(wire.rgb, 1.0)).rgb, alpha);
}

@fragment
fn fs_line(in: LineVaryings) -> @location(0) vec4<f32> {
    return line_color(in);
}

struct LineMaps {
    @location(0) color: vec4<f32>,
    // Write mask empty: a line covers no triangle, so the fill's id stays.
    @location(1) id: vec2<u32>,
    // Write mask red only: distance 0 where a line was drawn, the fill's depth stays in g.
    @location(2) diag: vec4<u32>,
}

@fragment
fn fs_line_maps(in: LineVaryings) -> LineMaps {
    return LineMaps(line_color(in), vec2<u32>(0xffffffffu), vec4<u32>(0u)); // 0u = bits of 0.0
}
