//! `gs`: the single-pass method of Bærentzen et al. (2006) exactly as published, with its
//! geometry shader over an indexed draw, on native OpenGL. wgpu has no geometry shader, so
//! the library's [`ForwardPass`](crate::gpu::ForwardPass) emulates the method with vertex
//! pulling; this is the method itself, for the benchmark and `compare` to measure the
//! deferred pass against.
//!
//! It runs in an OpenGL 3.3+ core context of its own (the per-triangle data in a storage
//! buffer where the context is 4.3 or newer, else a buffer texture), made headless through
//! EGL (`egl.rs`), rather than in wgpu's GL device: the comparison then runs beside whichever backend wgpu
//! uses (lavapipe's Vulkan by default), the context's state is this module's alone, and
//! desktop GL is what the method was written for. It draws the bytes the wgpu passes draw:
//! the mesh store is read back from the GPU, and the frame and instance records are the ones
//! every pass builds, bound as uniform blocks of the same layout (`shaders/gs.glsl`).

mod egl;

use crate::error::{Error, Result};
use crate::gpu::{FrameRecords, MeshStore, Region, BACKGROUND_ID, INSTANCE_BYTES};
use crate::scene::Scene;
use crate::style::Style;
use glow::HasContext;
use std::time::Instant;

pub use egl::GL_VERSION;

const SOURCE: &str = include_str!("../../../shaders/gs.glsl");

/// Records one draw's uniform block holds at most (`INSTANCE_CAPACITY` in gs.glsl), as the
/// deferred pass's uniform instance array.
const MOST_INSTANCES: u32 = crate::gpu::UNIFORM_INSTANCE_CAPACITY;

/// Uniform block bindings.
const FRAME_BINDING: u32 = 0;
const INSTANCES_BINDING: u32 = 1;

/// Bytes read back from the GPU at a time when the store is copied into OpenGL buffers.
const COPY_CHUNK: u64 = 64 << 20;

// glClipControl's arguments (GL 4.5, ARB_clip_control).
const UPPER_LEFT: u32 = 0x8CA2;
const ZERO_TO_ONE: u32 = 0x935F;

struct Program {
    program: glow::Program,
    win_scale: Option<glow::UniformLocation>,
    first_slot: Option<glow::UniformLocation>,
}

/// The mesh store's vertex, index and per-triangle buffers, copied into OpenGL at the same
/// offsets, so that a frame's draw list and instance records address them unchanged.
struct Store {
    /// The wgpu store's identity and version when copied.
    version: (u32, u64),
    bytes: u64,
    vertex_array: glow::VertexArray,
    buffers: [glow::Buffer; 3],
    /// The per-triangle buffer as a buffer texture, where it is not read as a storage
    /// buffer.
    info: Option<glow::Texture>,
}

/// The published geometry-shader method on OpenGL: see the [module](self) documentation.
///
/// One per thread: its context is current on the thread that made it.
pub struct GsPass {
    // Dropped before the context.
    store: Option<Store>,
    programs: [Program; 2],
    queries: [glow::Query; 2],
    /// A software renderer, timed by the wall clock (`draw_timed`).
    software: bool,
    /// OpenGL 4.3's storage buffers hold the per-triangle data, where the context has them
    /// (gs.glsl's STORAGE_INFO), else a buffer texture.
    storage_info: bool,
    capacity: u32,
    alignment: u32,
    description: String,
    gl: glow::Context,
    context: egl::Context,
}

/// One instanced draw of at most the pass's capacity of instances.
struct Draw {
    /// Byte offset of its records in the instance buffer.
    offset: u32,
    first_slot: u32,
    instances: u32,
    first_index: u32,
    index_count: u32,
    base_vertex: i32,
}

/// A frame prepared by [`GsPass::prepare`]: its records in uniform buffers and its targets.
pub struct GsFrame {
    size: (u32, u32),
    maps: bool,
    background: [f32; 4],
    order: Vec<u32>,
    version: (u32, u64),
    draws: Vec<Draw>,
    frame: glow::Buffer,
    instances: glow::Buffer,
    framebuffer: glow::Framebuffer,
    textures: Vec<glow::Texture>,
    /// Bytes of the frame and instance records' buffers.
    bytes: u64,
}

/// A frame read back: 8-bit sRGB RGBA, (instance slot, stored triangle) ids, and per pixel
/// the distance (3e38 for none) and reverse depth, as the forward pass's maps hold them.
pub struct GsPixels {
    /// RGBA, top row first.
    pub rgba: Vec<u8>,
    /// (instance slot, stored triangle); [`BACKGROUND_ID`] first on background.
    pub ids: Vec<[u32; 2]>,
    /// Distance in pixels and reverse depth.
    pub diagnostic: Vec<[f32; 4]>,
}

impl GsPass {
    /// Makes the context and the programs; an [`Error::NoAdapter`] where no OpenGL
    /// [`GL_VERSION`] core context can be made.
    pub fn new() -> Result<GsPass> {
        GsPass::build(true)
    }

    /// [`new`](Self::new) drawing as on an OpenGL 3.3 driver: without `glClipControl`
    /// (OpenGL 4.5 or ARB_clip_control), whose depth range and first row the vertex stage
    /// turns instead, and without storage buffers (OpenGL 4.3), the per-triangle data read
    /// from a buffer texture: the same image, for tests of those paths on drivers that have
    /// more.
    pub fn as_on_opengl_3_3() -> Result<GsPass> {
        GsPass::build(false)
    }

    fn build(newer_if_any: bool) -> Result<GsPass> {
        let context = egl::Context::new()?;
        let gl = context.load();
        // SAFETY: `gl` belongs to the context current on this thread; every call below
        // passes objects of that context.
        unsafe {
            let version = gl.version();
            if (version.major, version.minor) < (GL_VERSION.0 as u32, GL_VERSION.1 as u32) {
                return Err(Error::NoAdapter(format!(
                    "OpenGL {}.{} is older than the {}.{} the geometry-shader method needs",
                    version.major, version.minor, GL_VERSION.0, GL_VERSION.1
                )));
            }
            let description = format!(
                "{}, OpenGL {}",
                gl.get_parameter_string(glow::RENDERER),
                gl.get_parameter_string(glow::VERSION)
            );
            let block = gl.get_parameter_i32(glow::MAX_UNIFORM_BLOCK_SIZE).max(0) as u64;
            let capacity = (block / INSTANCE_BYTES).min(u64::from(MOST_INSTANCES)) as u32;
            if capacity == 0 {
                return Err(Error::NoAdapter(format!(
                    "OpenGL's uniform blocks ({block} bytes) hold no instance record"
                )));
            }
            let alignment = gl
                .get_parameter_i32(glow::UNIFORM_BUFFER_OFFSET_ALIGNMENT)
                .max(1) as u32;
            let clip_control = newer_if_any
                && ((version.major, version.minor) >= (4, 5)
                    || gl.supported_extensions().contains("GL_ARB_clip_control"));
            let storage_info = newer_if_any && (version.major, version.minor) >= (4, 3);
            let programs = [
                program(&gl, capacity, (clip_control, storage_info), false)?,
                program(&gl, capacity, (clip_control, storage_info), true)?,
            ];
            if clip_control {
                type ClipControl = extern "system" fn(u32, u32);
                let f = context
                    .proc_address("glClipControl")
                    .ok_or_else(|| Error::NoAdapter("glClipControl is missing".into()))?;
                // SAFETY: glClipControl has this signature.
                let clip: ClipControl = std::mem::transmute(f);
                // wgpu's conventions: the first row on top, depth 0..1 of w.
                clip(UPPER_LEFT, ZERO_TO_ONE);
            }
            gl.disable(glow::DITHER);
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::GREATER);
            gl.enable(glow::FRAMEBUFFER_SRGB);
            let renderer = gl.get_parameter_string(glow::RENDERER);
            let software = egl::is_software(&renderer);
            let queries = [
                gl.create_query().map_err(gl_error)?,
                gl.create_query().map_err(gl_error)?,
            ];
            check(&gl, "setting up")?;
            Ok(GsPass {
                store: None,
                programs,
                queries,
                software,
                storage_info,
                capacity,
                alignment,
                description,
                gl,
                context,
            })
        }
    }

    /// Bytes of the store's copy in OpenGL.
    pub fn gpu_bytes(&self) -> u64 {
        self.store.as_ref().map_or(0, |s| s.bytes)
    }

    /// The OpenGL renderer and version, for reports.
    pub fn description(&self) -> &str {
        &self.description
    }

    /// Validates the scene, style and size as every pass does, copies the store into OpenGL
    /// when it changed, and makes the frame's buffers and targets (with the id and distance
    /// maps when `maps`).
    pub fn prepare(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        store: &MeshStore,
        scene: &Scene<'_>,
        style: &Style,
        (size, maps): ((u32, u32), bool),
    ) -> Result<GsFrame> {
        let records = FrameRecords::new(
            device,
            store,
            scene,
            style,
            Region::whole(size),
            false,
            None,
        )?;
        let version = (store.store_id(), store.version());
        if self.store.as_ref().map(|s| s.version) != Some(version) {
            if let Some(old) = self.store.take() {
                self.delete_store(old);
            }
            self.store = Some(self.copy_store(device, queue, store, version)?);
        }
        let gl = self.current()?;
        // SAFETY: as in `new`.
        unsafe {
            let side = gl
                .get_parameter_i32(glow::MAX_TEXTURE_SIZE)
                .min(gl.get_parameter_i32(glow::MAX_RENDERBUFFER_SIZE))
                .max(0) as u32;
            if size.0.max(size.1) > side {
                return Err(Error::OverLimit {
                    what: format!("image side of {}x{} (OpenGL)", size.0, size.1),
                    value: u64::from(size.0.max(size.1)),
                    limit_name: "GL_MAX_TEXTURE_SIZE",
                    limit: u64::from(side),
                });
            }
            // Each draw's records start at an aligned offset, with a whole block's room.
            let block = self.capacity * INSTANCE_BYTES as u32;
            let mut draws = Vec::new();
            let mut bytes: Vec<u8> = Vec::new();
            for group in &records.draws {
                let mut first = group.instances.start;
                while first < group.instances.end {
                    let count = (group.instances.end - first).min(self.capacity);
                    let offset = bytes.len().next_multiple_of(self.alignment as usize);
                    bytes.resize(offset, 0);
                    let slots = first as usize..(first + count) as usize;
                    bytes.extend_from_slice(bytemuck::cast_slice(&records.records[slots]));
                    draws.push(Draw {
                        offset: offset as u32,
                        first_slot: first,
                        instances: count,
                        first_index: group.first_index,
                        index_count: group.index_count,
                        base_vertex: group.base_vertex,
                    });
                    first += count;
                }
            }
            let end = draws.last().map_or(0, |d| d.offset + block) as usize;
            bytes.resize(end.max(block as usize), 0);
            let instances = buffer(gl, glow::UNIFORM_BUFFER, &bytes)?;
            let frame = buffer(
                gl,
                glow::UNIFORM_BUFFER,
                bytemuck::bytes_of(&records.uniforms),
            )?;
            let (framebuffer, textures) = targets(gl, size, maps)?;
            check(gl, "preparing a frame")?;
            Ok(GsFrame {
                size,
                maps,
                background: records.uniforms.background(),
                order: records.order,
                version,
                draws,
                frame,
                instances,
                framebuffer,
                textures,
                bytes: (bytes.len() + std::mem::size_of_val(&records.uniforms)) as u64,
            })
        }
    }

    fn copy_store(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        store: &MeshStore,
        version: (u32, u64),
    ) -> Result<Store> {
        let gl = self.current()?;
        let source = store.buffers();
        // SAFETY: as in `new`.
        unsafe {
            let (limit, limit_name, value) = if self.storage_info {
                let bytes = gl.get_parameter_i32(glow::MAX_SHADER_STORAGE_BLOCK_SIZE);
                let bytes = bytes.max(0) as u64;
                (
                    bytes,
                    "GL_MAX_SHADER_STORAGE_BLOCK_SIZE",
                    source.info.size(),
                )
            } else {
                let texels = gl.get_parameter_i32(glow::MAX_TEXTURE_BUFFER_SIZE).max(0) as u64;
                (texels, "GL_MAX_TEXTURE_BUFFER_SIZE", source.info.size() / 4)
            };
            if value > limit {
                return Err(Error::OverLimit {
                    what: "the store's per-triangle data in OpenGL".into(),
                    value,
                    limit_name,
                    limit,
                });
            }
            let vertex_array = gl.create_vertex_array().map_err(gl_error)?;
            gl.bind_vertex_array(Some(vertex_array));
            let mut buffers = Vec::new();
            for (from, target) in [
                (&source.vertices, glow::ARRAY_BUFFER),
                (&source.indices, glow::ELEMENT_ARRAY_BUFFER),
                (&source.info, glow::TEXTURE_BUFFER),
            ] {
                let size = i32::try_from(from.size()).map_err(|_| Error::OverLimit {
                    what: "bytes of a mesh store buffer (OpenGL)".into(),
                    value: from.size(),
                    limit_name: "i32::MAX",
                    limit: i32::MAX as u64,
                })?;
                let to = gl.create_buffer().map_err(gl_error)?;
                gl.bind_buffer(target, Some(to));
                gl.buffer_data_size(target, size, glow::STATIC_DRAW);
                let mut offset = 0;
                while offset < from.size() {
                    let n = COPY_CHUNK.min(from.size() - offset);
                    let bytes = crate::gpu::read_buffer(device, queue, from, offset, n)?;
                    self.context.make_current()?;
                    gl.buffer_sub_data_u8_slice(target, offset as i32, &bytes);
                    offset += n;
                }
                buffers.push(to);
            }
            // Per vertex: the local position, then the packed normal's bits.
            let stride = crate::gpu::VERTEX_BYTES as i32;
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(buffers[0]));
            gl.enable_vertex_attrib_array(0);
            gl.vertex_attrib_pointer_f32(0, 3, glow::FLOAT, false, stride, 0);
            gl.enable_vertex_attrib_array(1);
            gl.vertex_attrib_pointer_i32(1, 1, glow::UNSIGNED_INT, stride, 12);
            gl.bind_vertex_array(None);
            let info = if self.storage_info {
                None
            } else {
                let info = gl.create_texture().map_err(gl_error)?;
                gl.bind_texture(glow::TEXTURE_BUFFER, Some(info));
                gl.tex_buffer(glow::TEXTURE_BUFFER, glow::R32UI, Some(buffers[2]));
                Some(info)
            };
            check(gl, "copying the mesh store")?;
            Ok(Store {
                version,
                bytes: [&source.vertices, &source.indices, &source.info]
                    .iter()
                    .map(|b| b.size())
                    .sum(),
                vertex_array,
                buffers: [buffers[0], buffers[1], buffers[2]],
                info,
            })
        }
    }

    /// Clears the frame's targets and draws it; with `maps`, also the id and distance maps
    /// (a frame prepared with them).
    pub fn draw(&self, frame: &GsFrame, maps: bool) -> Result<()> {
        let store = self.check(frame)?;
        if maps && !frame.maps {
            return Err(Error::Misuse(
                "the frame was prepared without its maps".into(),
            ));
        }
        let gl = self.current()?;
        let p = &self.programs[usize::from(maps)];
        let (w, h) = (frame.size.0 as i32, frame.size.1 as i32);
        // SAFETY: as in `new`; the frame's objects belong to this context (`check`).
        unsafe {
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(frame.framebuffer));
            let attachments = [
                glow::COLOR_ATTACHMENT0,
                glow::COLOR_ATTACHMENT1,
                glow::COLOR_ATTACHMENT2,
            ];
            gl.draw_buffers(&attachments[..if maps { 3 } else { 1 }]);
            gl.viewport(0, 0, w, h);
            gl.depth_mask(true);
            gl.clear_buffer_f32_slice(glow::COLOR, 0, &frame.background);
            if maps {
                gl.clear_buffer_u32_slice(glow::COLOR, 1, &[BACKGROUND_ID, BACKGROUND_ID, 0, 0]);
                let none = crate::gpu::NO_EDGE.to_bits();
                gl.clear_buffer_u32_slice(glow::COLOR, 2, &[none, 0, none, 0]);
            }
            gl.clear_buffer_f32_slice(glow::DEPTH, 0, &[0.0]);
            gl.use_program(Some(p.program));
            gl.uniform_2_f32(
                p.win_scale.as_ref(),
                0.5 * frame.size.0 as f32,
                0.5 * frame.size.1 as f32,
            );
            if let Some(info) = store.info {
                gl.active_texture(glow::TEXTURE0);
                gl.bind_texture(glow::TEXTURE_BUFFER, Some(info));
            } else {
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 0, Some(store.buffers[2]));
            }
            gl.bind_buffer_base(glow::UNIFORM_BUFFER, FRAME_BINDING, Some(frame.frame));
            gl.bind_vertex_array(Some(store.vertex_array));
            let block = (self.capacity * INSTANCE_BYTES as u32) as i32;
            for d in &frame.draws {
                gl.bind_buffer_range(
                    glow::UNIFORM_BUFFER,
                    INSTANCES_BINDING,
                    Some(frame.instances),
                    d.offset as i32,
                    block,
                );
                gl.uniform_1_u32(p.first_slot.as_ref(), d.first_slot);
                gl.draw_elements_instanced_base_vertex(
                    glow::TRIANGLES,
                    d.index_count as i32,
                    glow::UNSIGNED_INT,
                    4 * d.first_index as i32,
                    d.instances as i32,
                    d.base_vertex,
                );
            }
            gl.bind_vertex_array(None);
            check(gl, "drawing")
        }
    }

    /// Draws the frame (colour only) from an idle pipeline and waits for it: its time on
    /// the GPU (clears included) and the CPU time to issue it, in milliseconds.
    ///
    /// The GPU time is the span between two GL timestamp queries, except on a software
    /// renderer ([`timing`](Self::timing)): llvmpipe runs the vertex and geometry stages
    /// inside the draw call, on the calling thread, and its timestamps are taken by the
    /// rasterizer threads, so they miss that work (at 200 k triangles, 18 ms of a 68 ms
    /// frame). There, as for lavapipe's timestamps (which do span the whole frame), the
    /// time from issuing the frame to `glFinish` is what the GPU took.
    pub fn draw_timed(&self, frame: &GsFrame) -> Result<(f64, f64)> {
        let gl = self.current()?;
        // SAFETY: as in `new`.
        unsafe {
            gl.finish();
            let start = Instant::now();
            gl.query_counter(self.queries[0], glow::TIMESTAMP);
            self.draw(frame, false)?;
            gl.query_counter(self.queries[1], glow::TIMESTAMP);
            let cpu = start.elapsed().as_secs_f64() * 1e3;
            gl.finish();
            let wall = start.elapsed().as_secs_f64() * 1e3;
            let t0 = gl.get_query_parameter_u64(self.queries[0], glow::QUERY_RESULT);
            let t1 = gl.get_query_parameter_u64(self.queries[1], glow::QUERY_RESULT);
            check(gl, "timing a frame")?;
            let gpu = if self.software {
                wall
            } else {
                t1.saturating_sub(t0) as f64 * 1e-6
            };
            Ok((gpu, cpu))
        }
    }

    /// How [`draw_timed`](Self::draw_timed) measures the GPU time on this renderer.
    pub fn timing(&self) -> &'static str {
        if self.software {
            "wall clock from issuing the frame to glFinish (a software renderer: its GL \
             timestamps miss the vertex and geometry stages, run in the draw call)"
        } else {
            "GL timestamp queries"
        }
    }

    /// Reads a drawn frame back (its maps: a frame prepared and drawn with them).
    pub fn read(&self, frame: &GsFrame) -> Result<GsPixels> {
        self.check(frame)?;
        if !frame.maps {
            return Err(Error::Misuse(
                "the frame was prepared without its maps".into(),
            ));
        }
        let gl = self.current()?;
        let (w, h) = (frame.size.0 as i32, frame.size.1 as i32);
        let pixels = frame.size.0 as usize * frame.size.1 as usize;
        let mut rgba = vec![0u8; 4 * pixels];
        let mut ids = vec![[0u32; 2]; pixels];
        let mut diagnostic = vec![[0f32; 4]; pixels];
        // SAFETY: as in `new`; each slice holds the whole image in the read format.
        unsafe {
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(frame.framebuffer));
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
            let read = |attachment, format, bytes: &mut [u8]| {
                gl.read_buffer(attachment);
                gl.read_pixels(
                    0,
                    0,
                    w,
                    h,
                    format,
                    if format == glow::RGBA {
                        glow::UNSIGNED_BYTE
                    } else {
                        glow::UNSIGNED_INT
                    },
                    glow::PixelPackData::Slice(Some(bytes)),
                );
            };
            read(glow::COLOR_ATTACHMENT0, glow::RGBA, &mut rgba);
            read(
                glow::COLOR_ATTACHMENT1,
                glow::RG_INTEGER,
                bytemuck::cast_slice_mut(&mut ids),
            );
            read(
                glow::COLOR_ATTACHMENT2,
                glow::RGBA_INTEGER,
                bytemuck::cast_slice_mut(&mut diagnostic),
            );
            check(gl, "reading a frame back")?;
        }
        Ok(GsPixels {
            rgba,
            ids,
            diagnostic,
        })
    }

    /// The OpenGL functions, with the pass's context made current on this thread again: a
    /// wgpu device on its GL backend makes its own context current for each of its calls.
    fn current(&self) -> Result<&glow::Context> {
        self.context.make_current()?;
        Ok(&self.gl)
    }

    fn check(&self, frame: &GsFrame) -> Result<&Store> {
        match &self.store {
            Some(s) if s.version == frame.version => Ok(s),
            _ => Err(Error::Misuse(
                "the frame was prepared with another mesh store, or before it changed".into(),
            )),
        }
    }

    /// Deletes a frame's OpenGL objects.
    pub fn release(&self, frame: GsFrame) {
        let _ = self.context.make_current();
        let gl = &self.gl;
        // SAFETY: as in `new`; the frame is not used again.
        unsafe {
            gl.delete_framebuffer(frame.framebuffer);
            for t in frame.textures {
                gl.delete_texture(t);
            }
            gl.delete_buffer(frame.frame);
            gl.delete_buffer(frame.instances);
        }
    }

    /// Deletes a copied store's OpenGL objects.
    fn delete_store(&self, store: Store) {
        let _ = self.context.make_current();
        let gl = &self.gl;
        // SAFETY: as in `new`; the store is not used again.
        unsafe {
            gl.delete_vertex_array(store.vertex_array);
            if let Some(info) = store.info {
                gl.delete_texture(info);
            }
            for b in store.buffers {
                gl.delete_buffer(b);
            }
        }
    }
}

impl GsFrame {
    /// For each instance slot of the id map, the index of the instance in the scene.
    pub fn instance_order(&self) -> &[u32] {
        &self.order
    }

    /// Bytes of the frame's buffers and targets: colour and depth, 4 bytes a pixel each, and
    /// with the maps 24 more.
    pub fn gpu_bytes(&self) -> u64 {
        let pixels = u64::from(self.size.0) * u64::from(self.size.1);
        let per_pixel = if self.maps { 32 } else { 8 };
        pixels * per_pixel + self.bytes
    }
}

impl Drop for GsPass {
    fn drop(&mut self) {
        if let Some(old) = self.store.take() {
            self.delete_store(old);
        }
        let _ = self.context.make_current();
        let gl = &self.gl;
        // SAFETY: the context is still current (it is dropped after this).
        unsafe {
            for p in &self.programs {
                gl.delete_program(p.program);
            }
            for q in self.queries {
                gl.delete_query(q);
            }
        }
    }
}

/// Compiles and links gs.glsl's three stages; with `maps`, the fragment stage also writes
/// the id and distance maps.
unsafe fn program(
    gl: &glow::Context,
    capacity: u32,
    (clip_control, storage_info): (bool, bool),
    maps: bool,
) -> Result<Program> {
    let program = gl.create_program().map_err(gl_error)?;
    let mut shaders = Vec::new();
    for (kind, stage) in [
        (glow::VERTEX_SHADER, "VERTEX"),
        (glow::GEOMETRY_SHADER, "GEOMETRY"),
        (glow::FRAGMENT_SHADER, "FRAGMENT"),
    ] {
        let version = if storage_info {
            "430 core\n#define STORAGE_INFO"
        } else {
            "330 core"
        };
        let mut source =
            format!("#version {version}\n#define INSTANCE_CAPACITY {capacity}\n#define {stage}\n");
        if maps {
            source += "#define MAPS\n";
        }
        if !clip_control {
            source += "#define NO_CLIP_CONTROL\n";
        }
        source += "#line 1\n";
        source += SOURCE;
        let shader = gl.create_shader(kind).map_err(gl_error)?;
        gl.shader_source(shader, &source);
        gl.compile_shader(shader);
        if !gl.get_shader_compile_status(shader) {
            let log = gl.get_shader_info_log(shader);
            return Err(Error::Device(format!(
                "compiling gs.glsl ({stage}): {}",
                log.trim()
            )));
        }
        gl.attach_shader(program, shader);
        shaders.push(shader);
    }
    gl.link_program(program);
    for s in shaders {
        gl.detach_shader(program, s);
        gl.delete_shader(s);
    }
    if !gl.get_program_link_status(program) {
        return Err(Error::Device(format!(
            "linking gs.glsl: {}",
            gl.get_program_info_log(program).trim()
        )));
    }
    for (name, binding) in [("Frame", FRAME_BINDING), ("Instances", INSTANCES_BINDING)] {
        if let Some(index) = gl.get_uniform_block_index(program, name) {
            gl.uniform_block_binding(program, index, binding);
        }
    }
    gl.use_program(Some(program));
    gl.uniform_1_i32(gl.get_uniform_location(program, "info").as_ref(), 0);
    Ok(Program {
        program,
        win_scale: gl.get_uniform_location(program, "WIN_SCALE"),
        first_slot: gl.get_uniform_location(program, "first_slot"),
    })
}

/// A buffer holding `bytes`.
unsafe fn buffer(gl: &glow::Context, target: u32, bytes: &[u8]) -> Result<glow::Buffer> {
    let b = gl.create_buffer().map_err(gl_error)?;
    gl.bind_buffer(target, Some(b));
    gl.buffer_data_u8_slice(target, bytes, glow::STATIC_DRAW);
    Ok(b)
}

/// The frame's framebuffer: sRGB colour, 32-bit float depth and, with `maps`, the id
/// (`RG32UI`) and diagnostic (`RGBA32UI`) maps, as the forward pass's targets.
unsafe fn targets(
    gl: &glow::Context,
    (w, h): (u32, u32),
    maps: bool,
) -> Result<(glow::Framebuffer, Vec<glow::Texture>)> {
    let framebuffer = gl.create_framebuffer().map_err(gl_error)?;
    gl.bind_framebuffer(glow::FRAMEBUFFER, Some(framebuffer));
    let mut formats = vec![(
        glow::COLOR_ATTACHMENT0,
        glow::SRGB8_ALPHA8,
        glow::RGBA,
        glow::UNSIGNED_BYTE,
    )];
    if maps {
        formats.push((
            glow::COLOR_ATTACHMENT1,
            glow::RG32UI,
            glow::RG_INTEGER,
            glow::UNSIGNED_INT,
        ));
        formats.push((
            glow::COLOR_ATTACHMENT2,
            glow::RGBA32UI,
            glow::RGBA_INTEGER,
            glow::UNSIGNED_INT,
        ));
    }
    formats.push((
        glow::DEPTH_ATTACHMENT,
        glow::DEPTH_COMPONENT32F,
        glow::DEPTH_COMPONENT,
        glow::FLOAT,
    ));
    let mut textures = Vec::new();
    for (attachment, internal, format, ty) in formats {
        let t = gl.create_texture().map_err(gl_error)?;
        gl.bind_texture(glow::TEXTURE_2D, Some(t));
        gl.tex_image_2d(
            glow::TEXTURE_2D,
            0,
            internal as i32,
            w as i32,
            h as i32,
            0,
            format,
            ty,
            glow::PixelUnpackData::Slice(None),
        );
        gl.tex_parameter_i32(
            glow::TEXTURE_2D,
            glow::TEXTURE_MIN_FILTER,
            glow::NEAREST as i32,
        );
        gl.tex_parameter_i32(
            glow::TEXTURE_2D,
            glow::TEXTURE_MAG_FILTER,
            glow::NEAREST as i32,
        );
        gl.framebuffer_texture_2d(glow::FRAMEBUFFER, attachment, glow::TEXTURE_2D, Some(t), 0);
        textures.push(t);
    }
    let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
    if status != glow::FRAMEBUFFER_COMPLETE {
        return Err(Error::Device(format!(
            "the OpenGL framebuffer is incomplete (status {status:#x})"
        )));
    }
    Ok((framebuffer, textures))
}

/// The first OpenGL error since the last check, named with what was being done.
unsafe fn check(gl: &glow::Context, doing: &str) -> Result<()> {
    match gl.get_error() {
        glow::NO_ERROR => Ok(()),
        e => Err(Error::Device(format!("OpenGL error {e:#x} {doing}"))),
    }
}

fn gl_error(e: String) -> Error {
    Error::Device(format!("OpenGL: {e}"))
}
