//! Every WGSL module the crate can build passes naga's parser and validator, with no GPU.
//!
//! Covered: the assembled modules the passes create (`VISIBILITY`, `VISIBILITY_PULLED`, the
//! edge pass for both output formats), and every file in `shaders/`, so a new shader is
//! validated as soon as it exists. Every file except `common.wgsl` is a body that the crate
//! appends to `common.wgsl` ([`shaders::assemble`]); a body's output-format placeholder is
//! filled in and, where it calls `encode_output` without defining it (the Rust side appends
//! that per format), a definition is appended. A body written to follow another body (e.g.
//! `two_pass.wgsl` after `forward.wgsl`) validates when assembled after one of the others.

use naga::valid::{Capabilities, ValidationFlags, Validator};
use std::path::{Path, PathBuf};
use wirepass::gpu::shaders;

/// Parses and validates `source`, returning a readable error.
fn validate(source: &str) -> Result<(), String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    Validator::new(ValidationFlags::all(), Capabilities::all())
        .validate(&module)
        .map_err(|e| e.emit_to_string(source))?;
    Ok(())
}

fn check(name: &str, source: &str) {
    if let Err(e) = validate(source) {
        panic!("{name} does not validate:\n{e}");
    }
}

#[test]
fn assembled_modules_validate() {
    check("VISIBILITY", &shaders::assemble(shaders::VISIBILITY));
    check(
        "VISIBILITY_PULLED",
        &shaders::assemble(shaders::VISIBILITY_PULLED),
    );
    for format in [
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureFormat::Rgba16Float,
    ] {
        let source = shaders::edge_pass(format)
            .unwrap_or_else(|| panic!("edge_pass has no module for {format:?}"));
        check(&format!("edge_pass({format:?})"), &source);
    }
}

#[test]
fn common_alone_validates() {
    check("common.wgsl", shaders::COMMON);
}

/// A body as the Rust side completes it: placeholder format filled, `encode_output` present.
fn complete(body: &str) -> String {
    let mut body = body.replace("OUTPUT_FORMAT", "rgba8unorm");
    if body.contains("encode_output(") && !body.contains("fn encode_output") {
        body.push_str(
            "\nfn encode_output(c: vec4<f32>) -> vec4<f32> { return vec4<f32>(linear_to_srgb(c.rgb), c.a); }\n",
        );
    }
    body
}

fn shader_files() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "wgsl"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_shader_file_validates() {
    let files = shader_files();
    let read =
        |p: &PathBuf| std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let name = |p: &PathBuf| p.file_name().unwrap().to_string_lossy().into_owned();
    let bodies: Vec<(String, String)> = files
        .iter()
        .filter(|p| name(p) != "common.wgsl")
        .map(|p| (name(p), read(p)))
        .collect();
    assert!(
        bodies.len() >= 3,
        "expected the visibility and edge-pass shaders in shaders/, found {:?}",
        bodies.iter().map(|b| &b.0).collect::<Vec<_>>()
    );
    let mut failures = Vec::new();
    for (file, body) in &bodies {
        let alone = validate(&shaders::assemble(&complete(body)));
        let Err(error) = alone else { continue };
        // Maybe a body that follows another one.
        let after_another = bodies.iter().any(|(other, first)| {
            other != file
                && validate(&shaders::assemble(&complete(&format!("{first}\n{body}")))).is_ok()
        });
        if !after_another {
            failures.push(format!("{file}:\n{error}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
