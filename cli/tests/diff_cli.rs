//! `wirepass diff`: exit status and messages (no GPU needed).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("diff_cli");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A `w`×`h` PNG: a grey square on white, shifted right by `shift` pixels.
fn png(name: &str, (w, h): (u32, u32), shift: u32) -> PathBuf {
    let path = dir().join(name);
    let img = image::RgbaImage::from_fn(w, h, |x, y| {
        let inside =
            (w / 4 + shift..3 * w / 4 + shift).contains(&x) && (h / 4..3 * h / 4).contains(&y);
        if inside {
            image::Rgba([60, 60, 60, 255])
        } else {
            image::Rgba([255, 255, 255, 255])
        }
    });
    img.save(&path).unwrap();
    path
}

fn diff(a: &Path, b: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_wirepass"))
        .arg("diff")
        .arg(a)
        .arg(b)
        .args(extra)
        .output()
        .unwrap()
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

#[test]
fn identical_images_pass() {
    let a = png("same.png", (64, 48), 0);
    let heat = dir().join("same-heat.png");
    let out = diff(&a, &a, &["--out", heat.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("mean 0.000000") && stdout.contains("max 0.000000"),
        "{stdout}"
    );
    assert!(heat.exists());
}

#[test]
fn clearly_different_images_fail_with_a_reason() {
    let a = png("left.png", (64, 48), 0);
    let b = png("right.png", (64, 48), 10);
    let out = diff(&a, &b, &[]);
    assert!(!out.status.success(), "{}", text(&out));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("beyond the threshold"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    // A loose enough threshold accepts them.
    let out = diff(&a, &b, &["--threshold-mean", "1", "--threshold-p99", "1"]);
    assert!(out.status.success(), "{}", text(&out));
}

#[test]
fn different_sizes_are_an_error_naming_both() {
    let a = png("small.png", (32, 32), 0);
    let b = png("wide.png", (64, 32), 0);
    let out = diff(&a, &b, &[]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.starts_with("wirepass: error:"), "{stderr}");
    assert!(
        stderr.contains("32x32") && stderr.contains("64x32"),
        "{stderr}"
    );
}

#[test]
fn a_missing_file_is_named() {
    let a = png("exists.png", (16, 16), 0);
    let missing = dir().join("no-such-image.png");
    let out = diff(&a, &missing, &[]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.starts_with("wirepass: error:"), "{stderr}");
    assert!(stderr.contains("no-such-image.png"), "{stderr}");
}
