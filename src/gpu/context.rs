//! Headless device creation for the CLI, tools and tests. Library users who own a device
//! skip this and hand their own `Device`/`Queue` to the passes.

use crate::error::{Error, Result};
use std::sync::{Arc, Mutex};

/// A device and queue on the best adapter the environment allows.
pub struct GpuContext {
    /// The adapter the device was created on.
    pub adapter: wgpu::Adapter,
    /// The logical device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    errors: Arc<Mutex<Vec<String>>>,
}

/// Features wirepass uses where the adapter has them; none is required.
pub(crate) const OPTIONAL_FEATURES: wgpu::Features = wgpu::Features::PRIMITIVE_INDEX
    .union(wgpu::Features::TIMESTAMP_QUERY)
    .union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS)
    .union(wgpu::Features::POLYGON_MODE_LINE)
    .union(wgpu::Features::PIPELINE_CACHE);

impl GpuContext {
    /// Opens a device. `WGPU_BACKEND` (e.g. `vulkan`, `gl`) restricts the backends and
    /// `WGPU_ADAPTER_NAME` picks an adapter by a case-insensitive substring of its name.
    /// Otherwise the best adapter wins: discrete, integrated, virtual, then CPU, with Vulkan
    /// before GL among equals, so a machine without a Vulkan driver still gets Mesa's llvmpipe
    /// through GL.
    pub fn new() -> Result<Self> {
        pollster::block_on(Self::new_async())
    }

    async fn new_async() -> Result<Self> {
        // Without WGPU_BACKEND, native backends are tried first and GL only when they offer
        // nothing: probing EGL is slow and noisy where a Vulkan driver exists.
        let tries = match std::env::var("WGPU_BACKEND") {
            Ok(list) => {
                let b = wgpu::Backends::from_comma_list(&list);
                if b.is_empty() {
                    return Err(Error::NoAdapter(format!(
                        "WGPU_BACKEND={list:?} names no known backend (vulkan, gl, metal, dx12)"
                    )));
                }
                vec![b]
            }
            Err(_) => vec![wgpu::Backends::PRIMARY, wgpu::Backends::GL],
        };
        let wanted = std::env::var("WGPU_ADAPTER_NAME")
            .ok()
            .map(|s| s.to_lowercase());
        let mut adapters = Vec::new();
        let mut backends = wgpu::Backends::empty();
        for b in tries {
            backends |= b;
            let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
            desc.backends = b;
            desc.flags = wgpu::InstanceFlags::from_build_config().with_env();
            adapters = wgpu::Instance::new(desc).enumerate_adapters(b).await;
            if let Some(name) = &wanted {
                adapters.retain(|a| a.get_info().name.to_lowercase().contains(name));
            }
            if !adapters.is_empty() {
                break;
            }
        }
        adapters.sort_by_key(|a| rank(&a.get_info()));
        let Some(adapter) = adapters.into_iter().next() else {
            let mut why = format!("none on backends {backends:?}");
            if let Some(name) = wanted {
                why += &format!(" matching WGPU_ADAPTER_NAME={name:?}");
            }
            why += "; install a Vulkan driver (e.g. mesa-vulkan-drivers) or an EGL/GL driver";
            return Err(Error::NoAdapter(why));
        };
        let limits = adapter.limits();
        Self::from_adapter(adapter, limits).await
    }

    /// Opens a device on `adapter` with `limits` in place of the adapter's own, e.g. lowered
    /// ones to exercise how a mesh past a limit is handled.
    pub fn with_limits(adapter: wgpu::Adapter, limits: wgpu::Limits) -> Result<Self> {
        pollster::block_on(Self::from_adapter(adapter, limits))
    }

    async fn from_adapter(adapter: wgpu::Adapter, limits: wgpu::Limits) -> Result<Self> {
        let info = adapter.get_info();
        let downlevel = adapter.get_downlevel_capabilities();
        if !downlevel
            .flags
            .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
        {
            return Err(Error::MissingFeature {
                adapter: info.name,
                what: "compute shaders (DownlevelFlags::COMPUTE_SHADERS)".into(),
            });
        }
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("wirepass"),
                required_features: adapter.features() & OPTIONAL_FEATURES,
                required_limits: limits,
                ..Default::default()
            })
            .await
            .map_err(|e| Error::Device(format!("{}: {e}", info.name)))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut v) = sink.lock() {
                v.push(e.to_string());
            }
        }));
        let lost = errors.clone();
        device.set_device_lost_callback(move |reason, message| {
            if let Ok(mut v) = lost.lock() {
                v.push(format!("device lost ({reason:?}): {message}"));
            }
        });
        Ok(Self {
            adapter,
            device,
            queue,
            errors,
        })
    }

    /// One line naming the adapter and backend, for logs and reports.
    pub fn describe(&self) -> String {
        let i = self.adapter.get_info();
        format!("{} ({:?}, {:?})", i.name, i.backend, i.device_type)
    }

    /// Waits for all submitted work and turns any error the device reported since the
    /// last call (validation, out of memory, device loss) into an [`Error::Device`].
    pub fn finish(&self) -> Result<()> {
        let poll = self.device.poll(wgpu::PollType::wait_indefinitely());
        let mut reported = self
            .errors
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default();
        if let Err(e) = poll {
            reported.push(e.to_string());
        }
        if reported.is_empty() {
            Ok(())
        } else {
            Err(Error::Device(reported.join("; ")))
        }
    }
}

/// Sort key: lower is better.
fn rank(info: &wgpu::AdapterInfo) -> (u8, u8) {
    let kind = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    };
    let backend = match info.backend {
        wgpu::Backend::Vulkan | wgpu::Backend::Metal | wgpu::Backend::Dx12 => 0,
        _ => 1,
    };
    (kind, backend)
}
