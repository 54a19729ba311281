//! Every WGSL module the crate can build passes naga's parser and validator, with no GPU:
//! each pass in each specialisation (`shaders::variants`), and every file in `shaders/` is
//! part of at least one of them, so a new shader is validated as soon as it is used.

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

#[test]
fn every_variant_validates() {
    let variants = wirepass::gpu::shader_modules();
    assert!(variants.len() > 100, "{} variants", variants.len());
    let failures: Vec<String> = variants
        .iter()
        .filter_map(|(name, source)| validate(source).err().map(|e| format!("{name}:\n{e}")))
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `common.wgsl` needs nothing but the constants declared from Rust.
#[test]
fn common_alone_validates() {
    let source = format!("{}\n{}", shaders::constants(), shaders::COMMON);
    validate(&source).unwrap_or_else(|e| panic!("common.wgsl:\n{e}"));
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
fn every_shader_file_is_in_a_variant() {
    let variants = wirepass::gpu::shader_modules();
    let files = shader_files();
    assert!(files.len() >= 8, "{files:?}");
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        // The first code line that no specialisation can drop.
        let line = text
            .lines()
            .find(|l| {
                let t = l.trim();
                !t.is_empty()
                    && !t.starts_with("//")
                    && !t.starts_with('#')
                    && !t.starts_with("enable")
            })
            .unwrap_or_else(|| panic!("{} has no code", file.display()))
            .replace("OUTPUT_FORMAT", "rgba8unorm");
        assert!(
            variants.iter().any(|(_, s)| s.contains(&line)),
            "{} is in no module the crate builds (looked for {line:?})",
            file.display()
        );
    }
}
