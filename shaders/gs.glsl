// The single-pass wireframe as published (Bærentzen et al. 2006, "Single-pass wireframe
// rendering"; NVIDIA's "Solid Wireframe" white paper, 2007): an indexed draw whose geometry
// shader gives each corner its screen-space altitude, interpolated without perspective.
// OpenGL 3.3 core (4.3 with STORAGE_INFO); src/tools/gs/mod.rs prepends the version and one
// of VERTEX, GEOMETRY, FRAGMENT (and MAPS for the id and distance maps).
//
// It draws what forward.wgsl draws (the same frame and instance records, drawn-edge masks,
// line profile, shading and reverse depth), so that the two compare pixel for pixel:
// forward.wgsl is the same method with vertex pulling in place of this geometry shader. Its
// functions below are twins of common.wgsl's; tests/gs.rs keeps the images equal. Like
// the published method, it DIVIDES BY w, and fails for triangles across the near plane.

// common.wgsl's `struct Frame`, in the same std140 bytes (src/gpu/frame.rs).
layout(std140) uniform Frame {
    vec2 image_size;
    vec2 target_origin;
    vec2 target_size;
    vec2 output_offset;
    vec2 output_size;
    vec2 fade;
    vec4 crop;
    vec4 light_dir;
    vec4 fill_color;
    vec4 background;
    float ambient;
    uint instance_count;
    uint vertex_split;
    uint triangle_split;
    uint clusters;
    uint host_depth;
    uint pad0;
    uint pad1;
} frame;

// common.wgsl's `struct Instance`.
struct Instance {
    mat4 clip;
    vec4 depth_row;
    vec4 eye;
    vec4 fade_row;
    vec3 normal_x;
    float hidden_width;
    vec3 normal_y;
    float hidden_dash;
    vec3 normal_z;
    float hidden_period;
    vec4 wire_color;
    vec4 fill_color;
    float line_width;
    uint flags;
    uint vertex_base;
    uint triangle_base;
    uint triangles;
    uint cluster_base;
    uint cluster_first;
    uint index;
    uvec2 outline_color;
    uvec2 hidden_color;
    float outline_width;
    uint pad0;
    uint pad1;
    uint pad2;
    vec2 edge_pattern;
    vec2 outline_pattern;
    vec4 cross_box;
};

// The records of one instanced draw's instances, gl_InstanceID first.
layout(std140) uniform Instances {
    Instance instances[INSTANCE_CAPACITY];
};

// What the geometry stage hands the fragment stage: `dist` component j is the distance in
// pixels to the edge opposite corner j, interpolated without perspective; the local point and
// normal; the face normal; the instance (within the draw) and the triangle (of its mesh).
#ifdef MAPS
#define VARYINGS Fragment { noperspective vec3 dist; vec3 local; vec3 normal; flat vec3 face_normal; flat uint instance; flat uint tri; }
#else
#define VARYINGS Fragment { noperspective vec3 dist; vec3 local; vec3 normal; flat vec3 face_normal; flat uint instance; }
#endif

const uint INSTANCE_EDGES = 1u;
// The distance a masked edge's component carries (forward.wgsl's MASKED).
const float MASKED = 1.0e6;
const float NO_EDGE = 3.0e38;

#ifdef VERTEX

layout(location = 0) in vec3 position;
layout(location = 1) in uint packed_normal;

out Corner {
    vec3 local;
    flat uint packed_normal;
    flat uint instance;
} corner;

void main() {
    Instance inst = instances[gl_InstanceID];
    vec4 h = vec4(position, 1.0);
    vec4 c = inst.clip * h;
    // Whole images only: the frame's crop is the identity.
    float z = dot(inst.depth_row, h);
#ifdef NO_CLIP_CONTROL
    // Without glClipControl: depth -w..w, and the first row at the bottom; turned so that
    // depth is z / w again and the image's top row comes first, as with it.
    gl_Position = vec4(c.x, -c.y, 2.0 * z - c.w, c.w);
#else
    gl_Position = vec4(c.x, c.y, z, c.w);
#endif
    corner.local = position;
    corner.packed_normal = packed_normal;
    corner.instance = uint(gl_InstanceID);
}

#endif

#ifdef GEOMETRY

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

in Corner {
    vec3 local;
    flat uint packed_normal;
    flat uint instance;
} corners[];

out VARYINGS fragment;

// Per stored triangle: bits 0-2 the drawn edges (src/gpu/mesh_store.rs, triangle_info): a
// storage buffer where OpenGL 4.3 has them (STORAGE_INFO: a plain load, where llvmpipe's
// buffer texture fetch in the geometry stage cost a fifth of the frame), else a buffer
// texture.
#ifdef STORAGE_INFO
layout(std430, binding = 0) readonly buffer Info {
    uint info[];
};
#else
uniform usamplerBuffer info;
#endif
// The published WIN_SCALE, corrected to half the image size.
uniform vec2 WIN_SCALE;

vec3 unpack_normal(uint bits);

void main() {
    uint i = corners[0].instance;
    Instance inst = instances[i];
    vec2 p0 = WIN_SCALE * gl_in[0].gl_Position.xy / gl_in[0].gl_Position.w;
    vec2 p1 = WIN_SCALE * gl_in[1].gl_Position.xy / gl_in[1].gl_Position.w;
    vec2 p2 = WIN_SCALE * gl_in[2].gl_Position.xy / gl_in[2].gl_Position.w;
    vec2 v0 = p2 - p1;
    vec2 v1 = p2 - p0;
    vec2 v2 = p1 - p0;
    float area = abs(v1.x * v2.y - v1.y * v2.x);
    float altitude[3] = float[3](area / length(v0), area / length(v1), area / length(v2));

    // Component j belongs to edge (j + 1) % 3, as in forward.wgsl.
    uint mask = 0u;
    if ((inst.flags & INSTANCE_EDGES) != 0u) {
#ifdef STORAGE_INFO
        mask = info[inst.triangle_base + uint(gl_PrimitiveIDIn)] & 7u;
#else
        mask = texelFetch(info, int(inst.triangle_base) + gl_PrimitiveIDIn).x & 7u;
#endif
    }
    bvec3 drawn = bvec3((mask & 2u) != 0u, (mask & 4u) != 0u, (mask & 1u) != 0u);
    vec3 base = mix(vec3(MASKED), vec3(0.0), drawn);
    vec3 a0 = corners[0].local;
    vec3 face_normal = cross(corners[1].local - a0, corners[2].local - a0);
    for (int k = 0; k < 3; k++) {
        vec3 dist = base;
        if (drawn[k]) {
            dist[k] = altitude[k];
        }
        fragment.dist = dist;
        fragment.local = corners[k].local;
        fragment.normal = unpack_normal(corners[k].packed_normal);
        fragment.face_normal = face_normal;
        fragment.instance = i;
#ifdef MAPS
        fragment.tri = uint(gl_PrimitiveIDIn);
#endif
        gl_Position = gl_in[k].gl_Position;
        EmitVertex();
    }
    EndPrimitive();
}

// Twin of common.wgsl's unpack_normal.
vec3 unpack_normal(uint bits) {
    if (bits == 0x80008000u) {
        return vec3(0.0);
    }
    ivec2 s = ivec2(int(bits << 16u) >> 16, int(bits) >> 16);
    vec2 f = clamp(vec2(s) / 32767.0, -1.0, 1.0);
    vec3 n = vec3(f, 1.0 - abs(f.x) - abs(f.y));
    float t = max(-n.z, 0.0);
    n.x += n.x >= 0.0 ? -t : t;
    n.y += n.y >= 0.0 ? -t : t;
    return normalize(n);
}

#endif

#ifdef FRAGMENT

in VARYINGS fragment;

// The instance slot of the draw's first instance.
uniform uint first_slot;

layout(location = 0) out vec4 color;
#ifdef MAPS
layout(location = 1) out uvec2 id;
// The bits of two floats: distance in pixels (NO_EDGE for none), reverse raster depth.
layout(location = 2) out uvec4 diag;
#endif

// Twins of common.wgsl's functions of the same names.
vec3 towards_eye(vec3 a, vec4 eye) {
    return eye.xyz - a * eye.w;
}

vec3 shade(vec3 base, vec3 normal, float facing, vec3 light_dir, float ambient) {
    vec3 n = normal;
    if (facing < 0.0) {
        n = -n;
    }
    float diffuse = max(dot(n, light_dir), 0.0);
    return base * (ambient + (1.0 - ambient) * diffuse);
}

vec3 surface_color(Instance inst, vec3 p, vec3 normal, vec3 face_normal) {
    vec3 to_eye = towards_eye(p, inst.eye);
    vec3 n = normal;
    if (!(dot(n, n) > 1e-12)) {
        n = face_normal;
    }
    if (!(dot(n, n) > 0.0)) {
        return shade(inst.fill_color.rgb, normalize(frame.light_dir.xyz), 1.0, frame.light_dir.xyz, frame.ambient);
    }
    vec3 world = vec3(dot(inst.normal_x.xyz, n), dot(inst.normal_y.xyz, n), dot(inst.normal_z.xyz, n));
    return shade(inst.fill_color.rgb, normalize(world), dot(n, to_eye), frame.light_dir.xyz, frame.ambient);
}

float line_intensity(float d, float width) {
    float t = max(d - max(0.5 * width - 1.0, 0.0), 0.0);
    if (!(t < 2.0)) {
        return 0.0;
    }
    return min(0.5 * width, 1.0) * exp2(-2.0 * t * t);
}

float depth_fade(float depth, vec2 fade) {
    return fade.y > fade.x ? clamp((fade.y - depth) / (fade.y - fade.x), 0.0, 1.0) : 1.0;
}

void main() {
    Instance inst = instances[fragment.instance];
    float d = min(fragment.dist.x, min(fragment.dist.y, fragment.dist.z));
    vec3 surface = surface_color(inst, fragment.local, fragment.normal, fragment.face_normal);
    float depth = dot(inst.fade_row, vec4(fragment.local, 1.0));
    float i = line_intensity(d, inst.line_width) * depth_fade(depth, frame.fade);
    // Linear; the sRGB target encodes it.
    color = vec4(mix(surface, inst.wire_color.rgb, i * inst.wire_color.a), 1.0);
#ifdef MAPS
    id = uvec2(first_slot + fragment.instance, fragment.tri);
    if (d >= 0.5 * MASKED) {
        d = NO_EDGE;
    }
    diag = uvec4(floatBitsToUint(d), floatBitsToUint(gl_FragCoord.z), floatBitsToUint(3.0e38), 0u);
#endif
}

#endif
