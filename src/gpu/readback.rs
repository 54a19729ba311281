//! Copying textures back to the CPU: blocking, for native tools and tests, or as a future,
//! which a browser needs.

use crate::error::{Error, Result};
use std::future::Future;
use std::pin::Pin;
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll, Waker};

/// Reads a whole 2D texture (mip 0, layer 0) into tightly packed rows of
/// `bytes_per_texel × width` bytes, top row first. It blocks until the GPU is done: for
/// native tools and tests; [`read_texture_async`] is the one for a browser or an async host.
#[cfg(not(target_arch = "wasm32"))]
pub fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    aspect: wgpu::TextureAspect,
) -> Result<Vec<u8>> {
    let whole = ((0, 0), (texture.width(), texture.height()));
    let copy = TextureCopy::submit(device, queue, texture, aspect, whole)?;
    let bytes = map_read(device, &copy.buffer)?;
    Ok(copy.unpad(&bytes))
}

/// [`read_texture`] without blocking: the copy is submitted at once, and the future
/// completes when the GPU has mapped it. In a browser the map completes on the event loop
/// (awaiting never blocks the page); natively each poll of the future polls the device
/// without waiting, so any executor drives it.
pub async fn read_texture_async(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    aspect: wgpu::TextureAspect,
) -> Result<Vec<u8>> {
    let size = (texture.width(), texture.height());
    read_region_async(device, queue, texture, aspect, (0, 0), size).await
}

/// A texture copied into a mappable buffer, rows padded to wgpu's copy alignment.
struct TextureCopy {
    buffer: wgpu::Buffer,
    /// Bytes of one row, unpadded and padded.
    row: u32,
    padded: u32,
    height: u32,
}

/// Reads the `size` texels at `origin` of a 2D texture (mip 0, layer 0), as
/// [`read_texture_async`] does for all of them: a pick reads a few bytes, not the frame.
pub(crate) async fn read_region_async(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    aspect: wgpu::TextureAspect,
    origin: (u32, u32),
    size: (u32, u32),
) -> Result<Vec<u8>> {
    let copy = TextureCopy::submit(device, queue, texture, aspect, (origin, size))?;
    let bytes = map_read_async(device, &copy.buffer).await?;
    Ok(copy.unpad(&bytes))
}

impl TextureCopy {
    /// Copies the `size` texels at `origin` into a mappable buffer and submits the copy.
    fn submit(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        texture: &wgpu::Texture,
        aspect: wgpu::TextureAspect,
        ((x, y), (width, height)): ((u32, u32), (u32, u32)),
    ) -> Result<TextureCopy> {
        let inside =
            |at: u32, len: u32, of: u32| len > 0 && at.checked_add(len).is_some_and(|e| e <= of);
        if !inside(x, width, texture.width()) || !inside(y, height, texture.height()) {
            return Err(Error::InvalidSetting(format!(
                "the {width}x{height} texels at ({x}, {y}) are not inside the {}x{} texture",
                texture.width(),
                texture.height()
            )));
        }
        let texel = texture
            .format()
            .block_copy_size(Some(aspect))
            .ok_or_else(|| Error::Device(format!("{:?} cannot be copied", texture.format())))?;
        let row = width * texel;
        let padded =
            row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("wirepass readback"),
            size: u64::from(padded) * u64::from(height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x, y, z: 0 },
                aspect,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        queue.submit([encoder.finish()]);
        Ok(TextureCopy {
            buffer,
            row,
            padded,
            height,
        })
    }

    /// The mapped bytes without the row padding.
    fn unpad(&self, bytes: &[u8]) -> Vec<u8> {
        let mut out = Vec::with_capacity((self.row * self.height) as usize);
        for y in 0..self.height as usize {
            let start = y * self.padded as usize;
            out.extend_from_slice(&bytes[start..start + self.row as usize]);
        }
        out
    }
}

/// Copies `size` bytes of `buffer` from `offset` (both multiples of 4) into a mappable
/// buffer, after the work submitted before.
#[cfg(feature = "diagnostics")]
fn copy_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> wgpu::Buffer {
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("wirepass readback"),
        size,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, offset, &staging, 0, size);
    queue.submit([encoder.finish()]);
    staging
}

/// Reads `size` bytes of `buffer` from `offset` (both multiples of 4), once the work
/// submitted before has finished.
#[cfg(all(feature = "diagnostics", not(target_arch = "wasm32")))]
pub(crate) fn read_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> Result<Vec<u8>> {
    map_read(device, &copy_buffer(device, queue, buffer, offset, size))
}

/// [`read_buffer`] without blocking.
#[cfg(feature = "diagnostics")]
pub(crate) async fn read_buffer_async(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> Result<Vec<u8>> {
    map_read_async(device, &copy_buffer(device, queue, buffer, offset, size)).await
}

/// Maps a MAP_READ buffer, waits for it, and copies it out.
#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn map_read(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| Error::Device(format!("waiting for a readback: {e}")))?;
    rx.recv()
        .map_err(|_| Error::Device("readback was dropped".into()))?
        .map_err(|e| Error::Device(format!("mapping a readback buffer: {e}")))?;
    copy_out(buffer)
}

/// The mapped contents of a MAP_READ buffer, once the map completes, without blocking.
pub(crate) async fn map_read_async(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
) -> Result<Vec<u8>> {
    let state = Arc::new(Mutex::new(MapState::default()));
    let done = state.clone();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        if let Ok(mut s) = done.lock() {
            s.result = Some(r);
            if let Some(waker) = s.waker.take() {
                waker.wake();
            }
        }
    });
    MapFuture {
        device: device.clone(),
        state,
    }
    .await
    .map_err(|e| Error::Device(format!("mapping a readback buffer: {e}")))?;
    copy_out(buffer)
}

/// What a buffer's map callback has said, and who waits for it.
#[derive(Default)]
struct MapState {
    result: Option<std::result::Result<(), wgpu::BufferAsyncError>>,
    waker: Option<Waker>,
}

/// Completes when the map callback has run.
struct MapFuture {
    device: wgpu::Device,
    state: Arc<Mutex<MapState>>,
}

impl Future for MapFuture {
    type Output = std::result::Result<(), wgpu::BufferAsyncError>;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        // Natively the callback runs inside a device poll; in a browser, on the event loop
        // (there polling does nothing, and must not wait).
        let _ = self.device.poll(wgpu::PollType::Poll);
        let Ok(mut state) = self.state.lock() else {
            return Poll::Ready(Err(wgpu::BufferAsyncError));
        };
        if let Some(result) = state.result.take() {
            return Poll::Ready(result);
        }
        state.waker = Some(cx.waker().clone());
        if !cfg!(target_arch = "wasm32") {
            // Nothing else polls a native device: ask to be polled again.
            cx.waker().wake_by_ref();
        }
        Poll::Pending
    }
}

/// The contents of a mapped buffer, which is then unmapped.
fn copy_out(buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let view = buffer
        .get_mapped_range(..)
        .map_err(|e| Error::Device(format!("reading a readback buffer: {e}")))?;
    let out = view.to_vec();
    drop(view);
    buffer.unmap();
    Ok(out)
}
