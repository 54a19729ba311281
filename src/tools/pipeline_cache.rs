//! wgpu's pipeline cache ([`PassOptions::pipeline_cache`](crate::gpu::PassOptions)) kept in
//! a file between runs of the tools: `$XDG_CACHE_HOME/wirepass/` (else `~/.cache/wirepass/`),
//! one file per adapter, named by wgpu's key for it. Only Vulkan devices have one
//! (`Features::PIPELINE_CACHE`); `WIREPASS_PIPELINE_CACHE=off` leaves it out.

use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use std::path::PathBuf;

/// A pipeline cache made from what an earlier run saved.
pub struct PipelineCacheFile {
    /// The cache, to give the passes.
    pub cache: wgpu::PipelineCache,
    /// Where it is kept.
    pub path: PathBuf,
    /// The bytes the earlier run left (0 on a first run).
    pub loaded: usize,
}

/// What a run did with the pipeline cache, for `--timings`.
#[derive(Clone, Debug)]
pub enum CacheUse {
    /// Made from `loaded` bytes of `path`; `saved` bytes written back.
    Used {
        /// Where it is kept.
        path: PathBuf,
        /// Bytes read.
        loaded: usize,
        /// Bytes written.
        saved: usize,
    },
    /// None, and why.
    Unused(String),
}

/// The adapter's pipeline cache, made from its file where an earlier run left one; `Err`
/// says why there is none (not an error of the run).
pub fn open(ctx: &GpuContext) -> std::result::Result<PipelineCacheFile, String> {
    if std::env::var("WIREPASS_PIPELINE_CACHE").is_ok_and(|v| v == "off") {
        return Err("off (WIREPASS_PIPELINE_CACHE=off)".into());
    }
    let info = ctx.adapter.get_info();
    if !ctx
        .device
        .features()
        .contains(wgpu::Features::PIPELINE_CACHE)
    {
        return Err(format!(
            "the {:?} backend has none (wgpu's PipelineCache is Vulkan's)",
            info.backend
        ));
    }
    let key = wgpu::util::pipeline_cache_key(&info)
        .ok_or_else(|| format!("wgpu names no cache for the {:?} backend", info.backend))?;
    let folder = std::env::var_os("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .ok_or("neither XDG_CACHE_HOME nor HOME is set")?;
    let path = folder.join("wirepass").join(format!("{key}.bin"));
    let data = std::fs::read(&path).ok();
    // SAFETY: the data is what `save` wrote for this adapter's key, read whole; wgpu checks
    // its header against the adapter and driver, and `fallback` makes an empty cache of
    // data it cannot use instead of an error.
    let cache = unsafe {
        ctx.device
            .create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
                label: Some("wirepass pipeline cache"),
                data: data.as_deref(),
                fallback: true,
            })
    };
    Ok(PipelineCacheFile {
        cache,
        path,
        loaded: data.map_or(0, |d| d.len()),
    })
}

impl PipelineCacheFile {
    /// Writes what the cache holds now over its file (through a temporary file, so a run
    /// that stops midway leaves the old one whole); the bytes written.
    pub fn save(&self) -> Result<usize> {
        let Some(data) = self.cache.get_data() else {
            return Ok(0);
        };
        let io = |source| Error::Io {
            path: self.path.clone(),
            source,
        };
        if let Some(folder) = self.path.parent() {
            std::fs::create_dir_all(folder).map_err(io)?;
        }
        let temporary = self
            .path
            .with_extension(format!("{}.part", std::process::id()));
        std::fs::write(&temporary, &data).map_err(io)?;
        std::fs::rename(&temporary, &self.path).map_err(io)?;
        Ok(data.len())
    }

    /// This file's use by a run that saved `saved` bytes.
    pub fn used(&self, saved: usize) -> CacheUse {
        CacheUse::Used {
            path: self.path.clone(),
            loaded: self.loaded,
            saved,
        }
    }
}
