//! A device can be created on this machine: a real GPU, or Mesa's lavapipe software
//! adapter, which `make test` installs. Outside `make test` (HAIRLOOM_REQUIRE_GPU unset) a
//! machine with no adapter skips this test with a message instead of failing.

use hairloom_render::device::{describe, headless_for_test};

#[test]
fn headless_device_is_created_and_runs_a_copy() {
    let Some(context) = headless_for_test("headless_device_is_created_and_runs_a_copy") else {
        return;
    };
    assert!(!describe(&context.adapter_info).is_empty());
    // Prove the device works: copy a buffer on the GPU and read it back.
    let data: Vec<u8> = (0..256u32).map(|i| (i * 7 % 251) as u8).collect();
    let usage = wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
    let source = context.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("copy_source"),
        size: 256,
        usage,
        mapped_at_creation: false,
    });
    context.queue.write_buffer(&source, 0, &data);
    let readback = context.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("copy_readback"),
        size: 256,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = context
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    encoder.copy_buffer_to_buffer(&source, 0, &readback, 0, 256);
    context.queue.submit([encoder.finish()]);
    let bytes = hairloom_render::device::read_buffer(&context, &readback).expect("read back");
    assert_eq!(bytes, data);
}
