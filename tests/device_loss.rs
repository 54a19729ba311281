//! A lost device is reported as an `Error::Device`. In a test binary of its own: the test
//! opens and destroys a second device, which on wgpu's GL backend breaks what the process's
//! other devices draw afterwards.

#[test]
fn device_loss_is_reported_as_an_error() {
    let ctx = wirepass::gpu::GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    ctx.finish().expect("a fresh device has nothing to report");
    ctx.device.destroy();
    match ctx.finish() {
        Err(wirepass::Error::Device(message)) => {
            assert!(message.contains("device lost"), "{message}")
        }
        other => panic!("expected a device-lost error, got {other:?}"),
    }
}
