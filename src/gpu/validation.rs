//! The device's own validation, where wirepass can wait for it.
//!
//! What wirepass can check itself (formats, sizes, usages, sample counts, a frame of
//! another pass, a mesh of another store) it checks before calling wgpu, on every platform.
//! What only the device can decide (a texture of another device in a host's bind group, a
//! shader a driver rejects) is caught natively by a validation error scope, whose result
//! wirepass waits for, so it becomes a [`crate::Error`]. A browser cannot wait: on the web
//! these calls run without a scope, and such an error reaches the device's uncaptured-error
//! handler (`wgpu::Device::on_uncaptured_error`), as every wgpu error the host does not
//! scope does.

/// A validation error scope around a group of device calls (none on the web).
pub(crate) struct Validation {
    #[cfg(not(target_arch = "wasm32"))]
    scope: wgpu::ErrorScopeGuard,
}

impl Validation {
    /// Starts catching the device's validation errors.
    #[cfg_attr(target_arch = "wasm32", allow(unused_variables))]
    pub(crate) fn begin(device: &wgpu::Device) -> Validation {
        Validation {
            #[cfg(not(target_arch = "wasm32"))]
            scope: device.push_error_scope(wgpu::ErrorFilter::Validation),
        }
    }

    /// The first validation error of the calls since [`begin`](Self::begin), natively;
    /// `None` on the web, where the device's handler gets it.
    pub(crate) fn end(self) -> Option<wgpu::Error> {
        #[cfg(not(target_arch = "wasm32"))]
        return pollster::block_on(self.scope.pop());
        #[cfg(target_arch = "wasm32")]
        None
    }
}
