// The deferred edge pass, after common.wgsl and scene.wgsl. Two dispatches:
//
// `edge_main`, one invocation per output pixel: the triangle the rasterizer gave the pixel
// is tested exactly at the centre; where it covers the centre with room to spare (nearly
// every pixel), the pixel is finished here: distance to the drawn edges, perspective-correct
// barycentrics, shading, the line. Pixels it cannot decide (the centre within
// COVERAGE_MARGIN of the triangle's boundary or outside it, background next to foreground)
// are appended to a list instead.
//
// `refine_main`, dispatched indirectly over that list only: the exact coverage search among
// the neighbourhood's triangles and the walks across edges from them.
//
// Flags: OUTLINES (read what the outline pass left), COLORS (instances differ in line
// colour: the outline pass also left which instance's line a pixel holds), HOST (the host's
// depth seeded the targets: a triangle must also be nearer than it), and the output
// mode: MODE_SHADE, MODE_OVERLAY, MODE_RESULT (with SHADED: surface and lines, else lines
// only), MODE_DIAGNOSTIC.

#if OUTLINES
// What the outline pass left per target pixel: the greatest `line_key` (and, with COLORS,
// the greatest (level, instance) pair after it).
@group(0) @binding(12) var<storage, read> acc: array<u32>;
#endif

// The pixels `edge_main` leaves to `refine_main`, and the indirect dispatch size for them.
struct WorkList {
    x: atomic<u32>,
    y: u32,
    z: u32,
    count: atomic<u32>,
    items: array<u32>,
}
@group(0) @binding(15) var<storage, read_write> work_rw: WorkList;

struct WorkListRead {
    x: u32,
    y: u32,
    z: u32,
    count: u32,
    items: array<u32>,
}
@group(0) @binding(16) var<storage, read> work: WorkListRead;

// Workgroups of `refine_main` at most; each then takes every MAX_REFINE_GROUPS × 64-th item.
const MAX_REFINE_GROUPS: u32 = 16384u;

#if MODE_SHADE
@group(0) @binding(20) var out_color: texture_storage_2d<OUTPUT_FORMAT, write>;
#endif
#if MODE_OVERLAY
@group(0) @binding(20) var out_color: texture_storage_2d<OUTPUT_FORMAT, write>;
@group(0) @binding(21) var host_color: texture_2d<f32>;
#endif
#if MODE_RESULT
// Premultiplied linear RGBA, drawn into the host's render pass by composite.wgsl.
@group(0) @binding(20) var out_color: texture_storage_2d<rgba16float, write>;
#endif
#if MODE_DIAGNOSTIC
// Distance in pixels to the line (r) and reverse depth (g); the resolved (instance, triangle).
@group(0) @binding(22) var out_diagnostic: texture_storage_2d<rgba32float, write>;
@group(0) @binding(23) var out_ids: texture_storage_2d<rgba32uint, write>;
#endif

struct Pixel {
    // The visible instance and triangle; inst is BACKGROUND_ID or HOST_ID where none is.
    inst: u32,
    tri: u32,
    // Distance in pixels to the line that colours the pixel most (NO_EDGE for none).
    distance: f32,
    // That line's intensity (profile × depth fade), before the wire alpha, and its colour.
    line: f32,
    wire: vec4<f32>,
    // Linear shaded surface colour.
    surface: vec3<f32>,
    // Reverse depth of the visible point (0 where none).
    depth: f32,
}

// The pixel's line and surface, given the triangle that covers its centre (`s.inst` is
// BACKGROUND_ID or HOST_ID for none).
fn finish(xy: vec2<u32>, s: Sample) -> Pixel {
    var p: Pixel;
    p.inst = s.inst;
    p.tri = s.tri;
    p.depth = 0.0;
    var key = 0u;
    var owner = 0u;
#if OUTLINES
    let k = xy.y * u32(frame.target_size.x) + xy.x;
#if COLORS
    key = acc[2u * k];
    owner = acc[2u * k + 1u] & 0xfffffu;
#else
    key = acc[k];
#endif
#endif
    if s.inst == HOST_ID {
        p.depth = host_at(vec2<i32>(xy));
    }
    var own = NO_EDGE;
    var own_line = 0.0;
    var own_key = 0u;
    if s.inst < HOST_ID {
        let inst = s.inst;
        let flags = instances[inst].flags;
        var mask = info[instances[inst].triangle_base + s.tri] & 7u;
        if (flags & INSTANCE_EDGES) == 0u {
            mask = 0u;
        }
        let d = drawn_distances(s.lines, vec3<f32>(s.clip0.z, s.clip1.z, s.clip2.z), mask);
        own = min(d.x, min(d.y, d.z));
        let b = s.bary;
        let local = b.x * s.v0.xyz + b.y * s.v1.xyz + b.z * s.v2.xyz;
        let view_depth = dot(instances[inst].fade_row, vec4<f32>(local, 1.0));
        own_line = line_intensity(own, instances[inst].line_width) * depth_fade(view_depth, frame.fade);
        if own < NO_EDGE {
            own_key = line_key(own_line, own);
        }
        let n = b.x * unpack_normal(bitcast<u32>(s.v0.w)) + b.y * unpack_normal(bitcast<u32>(s.v1.w)) + b.z * unpack_normal(bitcast<u32>(s.v2.w));
        let face = cross(s.v1.xyz - s.v0.xyz, s.v2.xyz - s.v0.xyz);
        p.surface = surface_color(frame, instances[inst], local, n, face);
        p.depth = s.depth;
    }
    // The stronger line colours the pixel; equal ones go to the nearer.
    if own_key >= key {
        p.distance = own;
        p.line = own_line;
        p.wire = instances[min(s.inst, frame.instances - 1u)].wire_color;
    } else {
        p.distance = key_distance(key);
        p.line = key_intensity(key);
        p.wire = instances[owner].wire_color;
    }
    return p;
}

// Writes pixel `p` of target pixel `xy` into the output.
fn store_pixel(xy: vec2<u32>, p: Pixel) {
    let out = xy - vec2<u32>(frame.output_offset);
    let i = p.line * p.wire.a;
#if MODE_SHADE
    var base = frame.background;
    if p.inst < HOST_ID {
        base = vec4<f32>(p.surface, 1.0);
    }
    textureStore(out_color, out, encode_output(vec4<f32>(mix(base.rgb, p.wire.rgb, i), max(base.a, i))));
#endif
#if MODE_OVERLAY
    var host = textureLoad(host_color, out, 0);
#if HOST_ENCODED
    host = vec4<f32>(srgb_to_linear(host.rgb), host.a);
#endif
    textureStore(out_color, out, encode_output(vec4<f32>(mix(host.rgb, p.wire.rgb, i), max(host.a, i))));
#endif
#if MODE_RESULT
    var color = vec4<f32>(p.wire.rgb * i, i);
#if SHADED
    if p.inst < HOST_ID {
        color = vec4<f32>(mix(p.surface, p.wire.rgb, i), 1.0);
    }
#endif
    textureStore(out_color, out, color);
#endif
#if MODE_DIAGNOSTIC
    textureStore(out_diagnostic, out, vec4<f32>(p.distance, p.depth, 0.0, 0.0));
    textureStore(out_ids, out, vec4<u32>(p.inst, p.tri, 0u, 0u));
#endif
}

// True when one of the four edge-adjacent pixels is foreground.
fn foreground_next_to(xy: vec2<u32>) -> bool {
    let q = vec2<i32>(xy);
    let l = id_at(q - vec2<i32>(1, 0)).x;
    let r = id_at(q + vec2<i32>(1, 0)).x;
    let u = id_at(q - vec2<i32>(0, 1)).x;
    let d = id_at(q + vec2<i32>(0, 1)).x;
    return min(min(l, r), min(u, d)) < HOST_ID;
}

fn no_sample(inst: u32) -> Sample {
    var s: Sample;
    s.inst = inst;
    s.tri = 0u;
    s.covers = false;
    return s;
}

@compute @workgroup_size(8, 8)
fn edge_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !all(vec2<f32>(gid.xy) < frame.output_size) {
        return;
    }
    let xy = gid.xy + vec2<u32>(frame.output_offset);
    let raster = textureLoad(ids, xy, 0).xy;
    var s = no_sample(raster.x);
    var certain: bool;
    if raster.x < HOST_ID {
        s = sample(raster.x, raster.y, pixel_centre(xy));
        certain = s.covers && s.margin >= COVERAGE_MARGIN;
    } else {
        certain = !foreground_next_to(xy);
    }
    if !certain {
        let k = atomicAdd(&work_rw.count, 1u);
        work_rw.items[k] = xy.x | (xy.y << 16u);
        atomicMax(&work_rw.x, min(k / 64u + 1u, MAX_REFINE_GROUPS));
        return;
    }
    store_pixel(xy, finish(xy, s));
}

// The triangle whose surface the centre of target pixel `xy` sees, for a pixel `edge_main`
// could not decide: the nearest of the triangles covering the centre among the rasterizer's
// triangle, the 3×3 neighbourhood's, and those a walk from them reaches (the walk from the
// neighbours only when the pixel itself is background). If none covers it, the pixel is
// background where background is next to it, and keeps the rasterizer's triangle otherwise
// (the true one is out of reach). Where the host gave its depth, a triangle must also be
// nearer than the host's surface at the centre.
fn resolve(xy: vec2<u32>) -> Sample {
    let point = pixel_centre(xy);
    let host = host_at(vec2<i32>(xy));
    let raster = textureLoad(ids, xy, 0).xy;
    let raster_empty = raster.x >= HOST_ID;
    var best = no_sample(raster.x);
    var found = false;
    var background_near = raster_empty;
    var checked = raster;
    for (var k = 0; k < 10; k++) {
        var id = raster;
        var steps = WALK_STEPS;
        if k > 0 {
            let q = vec2<i32>(xy) + vec2<i32>((k - 1) % 3 - 1, (k - 1) / 3 - 1);
            id = id_at(q);
            background_near = background_near || id.x >= HOST_ID;
            if all(id == raster) || all(id == checked) {
                continue;
            }
            checked = id;
            steps = select(0u, WALK_STEPS, raster_empty);
        }
        if id.x >= HOST_ID {
            continue;
        }
        let s = locate(id.x, id.y, point, steps);
        if s.covers && s.depth > host && (!found || s.near < best.near) {
            best = s;
            found = true;
        }
    }
    if !found && !background_near {
        return sample(raster.x, raster.y, point);
    }
    return best;
}

@compute @workgroup_size(64)
fn refine_main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let count = work.count;
    for (var k = gid.x; k < count; k += 64u * groups.x) {
        let item = work.items[k];
        let xy = vec2<u32>(item & 0xffffu, item >> 16u);
        store_pixel(xy, finish(xy, resolve(xy)));
    }
}
