//! GPU timestamps around whole passes, for benchmarks and reports.

use crate::error::{Error, Result};

/// Timestamp queries around passes. Give each pass a span with [`GpuTimer::render_span`] or
/// [`GpuTimer::compute_span`], [`resolve`](GpuTimer::resolve) into the same encoder after the
/// last pass, submit, then [`read`](GpuTimer::read) the durations.
pub struct GpuTimer {
    set: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    readback: wgpu::Buffer,
    names: Vec<&'static str>,
    capacity: u32,
    period_ns: f64,
}

impl GpuTimer {
    /// A timer for up to `spans` passes per submission. Needs `Features::TIMESTAMP_QUERY`.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, spans: u32) -> Result<Self> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return Err(Error::MissingFeature {
                adapter: "this device".into(),
                what: "TIMESTAMP_QUERY (GPU timings)".into(),
            });
        }
        let capacity = (2 * spans).clamp(2, wgpu::QUERY_SET_MAX_QUERIES);
        let bytes = u64::from(capacity) * 8;
        let set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("wirepass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: capacity,
        });
        let buffer = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as U;
        Ok(Self {
            set,
            resolved: buffer("wirepass timestamps", U::QUERY_RESOLVE | U::COPY_SRC),
            readback: buffer("wirepass timestamps readback", U::COPY_DST | U::MAP_READ),
            names: Vec::new(),
            capacity,
            period_ns: f64::from(queue.get_timestamp_period()),
        })
    }

    fn next(&mut self, name: &'static str) -> Option<(u32, u32)> {
        let begin = 2 * self.names.len() as u32;
        if begin + 2 > self.capacity {
            return None;
        }
        self.names.push(name);
        Some((begin, begin + 1))
    }

    /// Timestamp writes for a render pass named `name` (`None` once the timer is full).
    pub fn render_span(
        &mut self,
        name: &'static str,
    ) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let (b, e) = self.next(name)?;
        Some(wgpu::RenderPassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(b),
            end_of_pass_write_index: Some(e),
        })
    }

    /// Timestamp writes for a compute pass named `name` (`None` once the timer is full).
    pub fn compute_span(
        &mut self,
        name: &'static str,
    ) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let (b, e) = self.next(name)?;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(b),
            end_of_pass_write_index: Some(e),
        })
    }

    /// Records the copy of this submission's timestamps; call after the last timed pass.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        let n = 2 * self.names.len() as u32;
        if n == 0 {
            return;
        }
        encoder.resolve_query_set(&self.set, 0..n, &self.resolved, 0);
        encoder.copy_buffer_to_buffer(&self.resolved, 0, &self.readback, 0, u64::from(n) * 8);
    }

    /// Waits for the submission and returns each span's name and duration in milliseconds,
    /// in the order the spans were made; the timer is then empty again.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read(&mut self, device: &wgpu::Device) -> Result<Vec<(&'static str, f64)>> {
        if self.names.is_empty() {
            return Ok(Vec::new());
        }
        let bytes = super::readback::map_read(device, &self.readback)?;
        Ok(self.spans(&bytes))
    }

    /// [`read`](Self::read) without blocking, as a browser needs.
    pub async fn read_async(&mut self, device: &wgpu::Device) -> Result<Vec<(&'static str, f64)>> {
        if self.names.is_empty() {
            return Ok(Vec::new());
        }
        let bytes = super::readback::map_read_async(device, &self.readback).await?;
        Ok(self.spans(&bytes))
    }

    /// The spans from the resolved timestamps' bytes; empties the timer.
    fn spans(&mut self, bytes: &[u8]) -> Vec<(&'static str, f64)> {
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes[..16 * self.names.len()]);
        self.names
            .drain(..)
            .enumerate()
            .map(|(i, name)| {
                let ticks = ticks[2 * i + 1].saturating_sub(ticks[2 * i]);
                (name, ticks as f64 * self.period_ns * 1e-6)
            })
            .collect()
    }
}
