// The benchmark floor, after common.wgsl and scene.wgsl: the least any deferred pass can
// cost. It reads each pixel's id and writes a flat colour, with no geometry, shading or line
// work.

#if MODE_FLOOR
@group(0) @binding(20) var out_color: texture_storage_2d<OUTPUT_FORMAT, write>;

@compute @workgroup_size(8, 8)
fn floor_main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if !all(vec2<f32>(gid.xy) < frame.output_size) {
        return;
    }
    let id = textureLoad(ids, gid.xy + vec2<u32>(frame.output_offset), 0).x;
    let color = select(frame.fill_color, frame.background, id >= HOST_ID);
    textureStore(out_color, gid.xy, encode_output(color));
}
#endif
