//! The `Frame` uniform block of `common.wgsl`.

use crate::camera::Camera;
use crate::style::Style;
use glam::{DMat4, DVec3, Mat4, Vec4};

/// Mirror of WGSL `struct Frame`; field order and padding match it.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    view_proj: [[f32; 4]; 4],
    depth_row: [f32; 4],
    eye: [f32; 4],
    light_dir: [f32; 4],
    wire_color: [f32; 4],
    fill_color: [f32; 4],
    background: [f32; 4],
    size: [f32; 2],
    line_width: f32,
    ambient: f32,
    fade: [f32; 2],
    index_split: u32,
    silhouettes: u32,
    triangles: u32,
    _pad: [u32; 3],
}

impl FrameUniforms {
    /// Checks the size against `device`, the camera and the style, then writes the frame's
    /// uniforms for `mesh` into `buffer`: the shared first step of every pass's `prepare`.
    pub(crate) fn validate_and_write(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        buffer: &wgpu::Buffer,
        mesh: &super::GpuMesh,
        (camera, style, size): (&Camera, &Style, (u32, u32)),
    ) -> crate::Result<()> {
        super::check_size(device, size)?;
        camera.validate()?;
        style.validate()?;
        let uniforms = Self {
            index_split: mesh.split,
            triangles: mesh.triangles,
            ..Self::new(camera, style, size, mesh.origin())
        };
        queue.write_buffer(buffer, 0, bytemuck::bytes_of(&uniforms));
        Ok(())
    }

    /// Uniforms for one frame. `origin` is the mesh-local origin its positions were rebased to
    /// (see [`crate::gpu::GpuMesh`]): the translation is folded into the matrix in f64, so
    /// meshes far from the world origin keep their precision.
    pub fn new(camera: &Camera, style: &Style, size: (u32, u32), origin: DVec3) -> Self {
        let m: DMat4 = camera.view_projection(size.0, size.1) * DMat4::from_translation(origin);
        let depth_row = m.row(3) - m.row(2);
        let light = light_world_dir(camera, style);
        let eye = camera.eye.as_dvec3() - origin;
        Self {
            view_proj: m.as_mat4().to_cols_array_2d(),
            depth_row: depth_row.as_vec4().to_array(),
            eye: eye.as_vec3().extend(1.0).to_array(),
            light_dir: light.as_vec3().extend(0.0).to_array(),
            wire_color: style.wire_color.0,
            fill_color: style.fill_color.0,
            background: style.background.0,
            size: [size.0 as f32, size.1 as f32],
            line_width: style.line_width,
            ambient: style.ambient,
            fade: style.fade_range(),
            index_split: u32::MAX,
            silhouettes: u32::from(style.silhouettes),
            triangles: 0,
            _pad: [0; 3],
        }
    }

    /// The f32 matrix the GPU uses (mesh-local → clip).
    pub fn view_proj(&self) -> Mat4 {
        Mat4::from_cols_array_2d(&self.view_proj)
    }

    /// The reverse-Z depth row.
    pub fn depth_row(&self) -> Vec4 {
        Vec4::from_array(self.depth_row)
    }
}

/// The style's view-space light direction in world axes, unit length.
pub fn light_world_dir(camera: &Camera, style: &Style) -> DVec3 {
    let inv = camera.view().inverse();
    inv.transform_vector3(style.light_view_dir.as_dvec3())
        .normalize_or_zero()
}
