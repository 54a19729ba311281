// Visibility pass: per pixel, the (instance slot, triangle) seen and its reverse depth, for
// every instance at once. Assembled after common.wgsl.
//
// Each mesh is one instanced draw. The instance records are also an instance-rate vertex
// buffer: their clip rows, depth row, bases and slot arrive as attributes.
//
// Flags: PULLED (no PRIMITIVE_INDEX: a non-indexed draw of 3 × triangles vertices per
// instance pulls its vertices from storage and passes the triangle as a flat varying;
// SPLIT as in scene.wgsl), SECTIONS (fragments behind a section plane are discarded: the
// planes' sides, interpolated, are exact at each pixel centre).

#if !PULLED
enable primitive_index;
#endif

@group(0) @binding(0) var<uniform> frame: Frame;

struct InstanceIn {
    @location(1) clip0: vec4<f32>,
    @location(2) clip1: vec4<f32>,
    @location(3) clip2: vec4<f32>,
    @location(4) clip3: vec4<f32>,
    @location(5) depth_row: vec4<f32>,
    @location(6) bases: vec2<u32>,
    @location(7) slot: u32,
}

struct Varyings {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) slot: u32,
#if PULLED
    @location(1) @interpolate(flat) tri: u32,
#endif
#if SECTIONS
    @location(2) sides_a: vec4<f32>,
    @location(3) sides_b: vec2<f32>,
#endif
}

// The varyings of local point p of an instance with clip rows `clip` and depth row
// `depth_row`, in triangle `tri` (PULLED).
fn varyings(clip: mat4x4<f32>, depth_row: vec4<f32>, p: vec3<f32>, slot: u32, tri: u32) -> Varyings {
    var v: Varyings;
    v.clip = raster_position(frame, clip, depth_row, p);
    v.slot = slot;
#if PULLED
    v.tri = tri;
#endif
#if SECTIONS
    let sides = section_sides(frame, clip * vec4<f32>(p, 1.0));
    v.sides_a = sides.a;
    v.sides_b = sides.b;
#endif
    return v;
}

// Discards a fragment behind a section plane (SECTIONS).
fn cut(in: Varyings) {
#if SECTIONS
    if any(in.sides_a < vec4<f32>(0.0)) || any(in.sides_b < vec2<f32>(0.0)) {
        discard;
    }
#endif
}

#if !PULLED
@vertex
fn vs_main(@location(0) position: vec3<f32>, inst: InstanceIn) -> Varyings {
    let clip = mat4x4<f32>(inst.clip0, inst.clip1, inst.clip2, inst.clip3);
    return varyings(clip, inst.depth_row, position, inst.slot, 0u);
}

@fragment
fn fs_main(in: Varyings, @builtin(primitive_index) primitive: u32) -> @location(0) vec2<u32> {
    cut(in);
    return vec2<u32>(in.slot, primitive);
}
#else
@group(0) @binding(2) var<storage, read> vertices: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> indices: array<u32>;
#if SPLIT
@group(0) @binding(3) var<storage, read> vertices_hi: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> indices_hi: array<u32>;
#endif

@vertex
fn vs_main(@builtin(vertex_index) corner: u32, inst: InstanceIn) -> Varyings {
    let k = 3u * inst.bases.y + corner;
    var v: u32;
#if SPLIT
    let split = 3u * frame.triangle_split;
    if k >= split {
        v = indices_hi[k - split];
    } else {
        v = indices[k];
    }
    v += inst.bases.x;
    var p: vec3<f32>;
    if v >= frame.vertex_split {
        p = vertices_hi[v - frame.vertex_split].xyz;
    } else {
        p = vertices[v].xyz;
    }
#else
    v = indices[k] + inst.bases.x;
    let p = vertices[v].xyz;
#endif
    let clip = mat4x4<f32>(inst.clip0, inst.clip1, inst.clip2, inst.clip3);
    return varyings(clip, inst.depth_row, p, inst.slot, corner / 3u);
}

@fragment
fn fs_main(in: Varyings) -> @location(0) vec2<u32> {
    cut(in);
    return vec2<u32>(in.slot, in.tri);
}
#endif
