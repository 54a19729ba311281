// The deferred edge pass: one invocation per pixel. Prepended with common.wgsl.
//
// id -> three indices -> three clip-space vertices -> homogeneous screen edge lines ->
// distance to each drawn edge + perspective-correct barycentrics -> shade -> line -> store.

@group(0) @binding(0) var<uniform> frame: Frame;
// xyz per vertex, packed, mesh-local.
@group(0) @binding(1) var<storage, read> positions: array<f32>;
@group(0) @binding(2) var<storage, read> normals: array<f32>;
@group(0) @binding(3) var<storage, read> indices: array<u32>;
// Edge masks, 8 bits per triangle, 4 triangles per word.
@group(0) @binding(4) var<storage, read> edge_masks: array<u32>;
@group(0) @binding(5) var ids: texture_2d<u32>;

const BACKGROUND_ID: u32 = 0xffffffffu;

fn position(v: u32) -> vec3<f32> {
    return vec3<f32>(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

fn normal(v: u32) -> vec3<f32> {
    return vec3<f32>(normals[3u * v], normals[3u * v + 1u], normals[3u * v + 2u]);
}

struct Pixel {
    // False on background.
    covered: bool,
    // Distance in pixels to the nearest drawn edge of the visible triangle.
    distance: f32,
    // Linear shaded surface colour.
    surface: vec3<f32>,
}

fn evaluate(xy: vec2<u32>) -> Pixel {
    var out: Pixel;
    out.covered = false;
    out.distance = NO_EDGE;
    let id = textureLoad(ids, xy, 0).x;
    if id == BACKGROUND_ID {
        return out;
    }
    let v = vec3<u32>(indices[3u * id], indices[3u * id + 1u], indices[3u * id + 2u]);
    let w0 = position(v.x);
    let w1 = position(v.y);
    let w2 = position(v.z);
    let mask = (edge_masks[id >> 2u] >> ((id & 3u) * 8u)) & 7u;
    let pixel = vec2<f32>(xy) + 0.5;
    let e = edge_eval(
        frame.view_proj * vec4<f32>(w0, 1.0),
        frame.view_proj * vec4<f32>(w1, 1.0),
        frame.view_proj * vec4<f32>(w2, 1.0),
        mask, pixel, frame.size,
    );
    out.covered = true;
    out.distance = min(e.distance.x, min(e.distance.y, e.distance.z));

    let world = e.bary.x * w0 + e.bary.y * w1 + e.bary.z * w2;
    let to_eye = frame.eye.xyz - world;
    var n = e.bary.x * normal(v.x) + e.bary.y * normal(v.y) + e.bary.z * normal(v.z);
    if !(dot(n, n) > 1e-12) {
        n = cross(w1 - w0, w2 - w0);
    }
    if !(dot(n, n) > 0.0) {
        n = to_eye;
    }
    out.surface = shade(frame.fill_color.rgb, normalize(n), to_eye, frame.light_dir.xyz, frame.ambient);
    return out;
}

fn inside(xy: vec2<u32>) -> bool {
    return all(vec2<f32>(xy) < frame.size);
}

// Shaded mode: the pass draws the surface itself.
@group(1) @binding(0) var shaded_out: texture_storage_2d<OUTPUT_FORMAT, write>;

@compute @workgroup_size(8, 8)
fn shade_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !inside(gid.xy) {
        return;
    }
    let p = evaluate(gid.xy);
    var color = frame.background;
    if p.covered {
        let i = line_intensity(p.distance, frame.line_width);
        color = vec4<f32>(mix(p.surface, frame.wire_color.rgb, i * frame.wire_color.a), 1.0);
    }
    textureStore(shaded_out, gid.xy, encode_output(color));
}

// Overlay mode: blend the line over the host's own colour image.
@group(1) @binding(1) var overlay_out: texture_storage_2d<OUTPUT_FORMAT, write>;
@group(1) @binding(2) var host_color: texture_2d<f32>;

@compute @workgroup_size(8, 8)
fn overlay_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !inside(gid.xy) {
        return;
    }
    let p = evaluate(gid.xy);
    var color = textureLoad(host_color, gid.xy, 0);
    if p.covered {
        let i = line_intensity(p.distance, frame.line_width) * frame.wire_color.a;
        color = vec4<f32>(mix(color.rgb, frame.wire_color.rgb, i), max(color.a, i));
    }
    textureStore(overlay_out, gid.xy, encode_output(color));
}

// Diagnostic mode: the raw distance (pixels; NO_EDGE on background) and the raster depth,
// which some backends (GL) cannot copy out of a depth texture directly.
@group(1) @binding(3) var diagnostic_out: texture_storage_2d<rgba32float, write>;
@group(1) @binding(4) var depth_in: texture_2d<f32>;

@compute @workgroup_size(8, 8)
fn diagnostic_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !inside(gid.xy) {
        return;
    }
    let depth = textureLoad(depth_in, gid.xy, 0).x;
    textureStore(diagnostic_out, gid.xy, vec4<f32>(evaluate(gid.xy).distance, depth, 0.0, 0.0));
}
