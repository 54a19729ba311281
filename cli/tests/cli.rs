//! The command line: a render that works, and bad input that gives one clear line and a
//! non-zero exit, never a panic.

use std::process::Command;

fn wirepass(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_wirepass"))
        .args(args)
        .output()
        .expect("the wirepass binary runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "panic for {args:?}: {stderr}");
    (out.status.success(), stderr)
}

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("wirepass-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn renders_the_built_in_scene_and_dumps_numpy_files() {
    let png = temp("scene.png");
    let dump = temp("dump");
    let (ok, err) = wirepass(&[
        "render",
        "--size",
        "64x48",
        "-o",
        png.to_str().unwrap(),
        "--dump",
        dump.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (64, 48));
    for (name, descr) in [
        ("ids.npy", "<u4"),
        ("depth.npy", "<f4"),
        ("edge_distance.npy", "<f4"),
        ("hidden_distance.npy", "<f4"),
        ("line_class.npy", "|u1"),
    ] {
        let bytes = std::fs::read(dump.join(name)).unwrap();
        assert_eq!(&bytes[..6], b"\x93NUMPY", "{name}");
        let header = String::from_utf8_lossy(&bytes[10..128.min(bytes.len())]).into_owned();
        assert!(
            header.contains(descr) && header.contains("(48, 64"),
            "{name}: {header}"
        );
        let payload = bytes.len() - (10 + u16::from_le_bytes([bytes[8], bytes[9]]) as usize);
        let bytes_per_pixel = if descr == "|u1" { 1 } else { 4 };
        assert_eq!(payload, 48 * 64 * bytes_per_pixel, "{name}");
    }
    let camera: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dump.join("camera.json")).unwrap()).unwrap();
    for key in ["size", "view", "projection", "depth", "orthographic", "eye"] {
        assert!(camera.get(key).is_some(), "camera.json lacks {key}");
    }
    assert_eq!(camera["view"].as_array().unwrap().len(), 16);
}

#[test]
fn a_render_without_a_display_says_only_what_it_wrote() {
    // No window system to probe: the command draws offscreen and says only what it wrote.
    let png = temp("quiet.png");
    let out = Command::new(env!("CARGO_BIN_EXE_wirepass"))
        .args(["render", "--size", "32x24", "-o", png.to_str().unwrap()])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("DISPLAY")
        .output()
        .unwrap();
    assert!(out.status.success());
    let said = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(said.lines().count(), 1, "{said}");
    assert!(said.starts_with("wrote "), "{said}");
}

/// `render` keeps wgpu's pipeline cache in the user's cache folder where the device has
/// one (Vulkan), makes the next run's from it, and says so in `--timings`; elsewhere it says
/// why there is none and writes nothing.
#[test]
fn render_keeps_the_pipeline_cache_between_runs() {
    let folder = temp("xdg-cache");
    let image = temp("cached.png");
    let run = || {
        let out = Command::new(env!("CARGO_BIN_EXE_wirepass"))
            .args(["render", "--size", "32x24", "--timings", "-o"])
            .arg(&image)
            .env("XDG_CACHE_HOME", &folder)
            .env_remove("WIREPASS_PIPELINE_CACHE")
            .output()
            .expect("the wirepass binary runs");
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{stderr}");
        let line = stderr.lines().find(|l| l.starts_with("pipeline cache"));
        line.unwrap_or_else(|| panic!("no pipeline cache line in:\n{stderr}"))
            .to_owned()
    };
    let (first, second) = (run(), run());
    let kept = folder.join("wirepass");
    if first.contains("none: ") {
        assert!(second.contains("none: ") && !kept.exists(), "{second}");
        return;
    }
    assert!(first.contains("0 bytes read"), "{first}");
    let files: Vec<_> = std::fs::read_dir(&kept)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let size = std::fs::metadata(&files[0]).unwrap().len();
    assert!(
        size > 0 && second.contains(&format!("{size} bytes read")),
        "{second}"
    );
}

/// `render` without `--dump` draws the image alone, without the maps: the same image as a
/// render that dumps them. `--timings` says where the time went, a line a step.
#[test]
fn the_image_alone_is_the_image_with_maps_and_timings_name_each_step() {
    let (alone, with_maps) = (temp("alone.png"), temp("with_maps.png"));
    let dump = temp("with_maps_dump");
    let mesh = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/meshes/suzanne.obj"
    );
    let scene = ["render", mesh, "--size", "96x72"];
    let (ok, timings) =
        wirepass(&[&scene[..], &["--timings", "-o", alone.to_str().unwrap()]].concat());
    assert!(ok, "{timings}");
    let (ok, err) = wirepass(
        &[
            &scene[..],
            &[
                "-o",
                with_maps.to_str().unwrap(),
                "--dump",
                dump.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert!(ok, "{err}");
    let pixels = |p: &std::path::Path| image::open(p).unwrap().to_rgba8().into_raw();
    assert_eq!(pixels(&alone), pixels(&with_maps));
    for step in [
        "read the scene",
        "mesh 0: adjacency",
        "mesh 0: crossings",
        "mesh 0: edges: patches, chains",
        "first frame",
        "total, with the PNG",
    ] {
        assert!(timings.contains(step), "no {step:?} in:\n{timings}");
    }
    assert!(timings.contains(" bytes a triangle)"), "{timings}");
    let (ok, err) = wirepass(&[&scene[..], &["--timings", "--method", "forward"]].concat());
    assert!(!ok && err.lines().count() == 1, "{err}");
}

#[test]
fn a_baseline_that_is_not_one_is_a_clear_error() {
    let bad = temp("not-a-baseline.json");
    std::fs::write(&bad, "{\"ratios\": 3}").unwrap();
    let out = temp("bench-against");
    for path in [bad.to_str().unwrap(), "/nonexistent/baseline.json"] {
        let (ok, err) = wirepass(&[
            "bench",
            "sphere:200",
            "--frames",
            "1",
            "--out",
            out.to_str().unwrap(),
            "--against",
            path,
        ]);
        assert!(!ok && err.lines().count() == 1, "{err}");
        assert!(
            err.contains("baseline") || err.contains("nonexistent"),
            "{err}"
        );
    }
}

#[test]
fn bad_settings_give_one_clear_line() {
    let out = temp("bad.png");
    let o = out.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["render", "--size", "0x10", "-o", o], "zero side"),
        (&["render", "--size", "100x", "-o", o], "WIDTHxHEIGHT"),
        (
            &["render", "--size", "1000000x10", "-o", o],
            "max_texture_dimension_2d",
        ),
        (
            &["render", "--eye", "1,1,1", "--target", "1,1,1", "-o", o],
            "same point",
        ),
        (&["render", "--up", "0,0,0", "-o", o], "zero vector"),
        (
            &[
                "render", "--eye", "0,5,0", "--target", "0,0,0", "--up", "0,1,0", "-o", o,
            ],
            "parallel",
        ),
        (&["render", "--fov", "0", "-o", o], "fov"),
        (&["render", "--fov", "180", "-o", o], "fov"),
        (&["render", "--near", "0", "-o", o], "near"),
        (&["render", "--near", "2", "--far", "1", "-o", o], "far"),
        (&["render", "--line-width", "-1", "-o", o], "line width"),
        (&["render", "--wire-color", "red", "-o", o], "colour"),
        (&["render", "--eye", "1,2", "-o", o], "x,y,z"),
        (&["render", "sphere:2", "-o", o], "sphere"),
        (&["render", "box:10", "-o", o], "procedural"),
        (&["render", "cube:10", "-o", o], "needs 12"),
        (
            &["render", "/no/such/mesh.obj", "-o", o],
            "/no/such/mesh.obj",
        ),
        (&["render", "--method", "magic", "-o", o], "method"),
        (&["render", "--outlines", "maybe", "-o", o], "on or off"),
        (&["render", "--depth-fade", "5", "-o", o], "START:END"),
        (&["render", "--depth-fade", "5:1", "-o", o], "depth fade"),
        (&["render", "--line-width", "1000", "-o", o], "line width"),
        (
            &["render", "--hidden", "wavy", "-o", o],
            "hidden-line style",
        ),
        (
            &["render", "--hidden", "dashed:0,2", "-o", o],
            "hidden line pattern",
        ),
        (
            &[
                "render",
                "--hidden",
                "solid",
                "--hidden-width",
                "0",
                "-o",
                o,
            ],
            "hidden line width",
        ),
        (&["render", "--fill-opacity", "2", "-o", o], "fill opacity"),
        (
            &["render", "--outline-width", "-2", "-o", o],
            "outline width",
        ),
        (&["render", "--outline-color", "blue", "-o", o], "colour"),
        (&["render", "--highlight", "7", "-o", o], "--highlight 7"),
        (
            &["render", "--edge-pattern", "off", "-o", o],
            "line pattern",
        ),
        (
            &["render", "--outline-pattern", "dotted:0", "-o", o],
            "outline pattern",
        ),
    ];
    for (args, expect) in cases {
        let (ok, err) = wirepass(args);
        assert!(!ok, "{args:?} succeeded");
        assert!(
            err.contains(expect),
            "{args:?}: expected {expect:?} in {err:?}"
        );
        // Software drivers may print their own notices (e.g. about XDG_RUNTIME_DIR); the
        // program itself says exactly one line.
        let lines: Vec<_> = err
            .lines()
            .filter(|l| l.starts_with("wirepass: error:") || l.starts_with("error: invalid value"))
            .collect();
        assert_eq!(lines.len(), 1, "{args:?}: {err}");
    }
}

/// Every option that takes numbers takes negative ones, not only --eye.
#[test]
fn numbers_may_start_with_a_minus() {
    let out = temp("minus.png");
    let o = out.to_str().unwrap();
    let (ok, err) = wirepass(&[
        "render",
        "--size",
        "64x48",
        "--section",
        "-0.02,0.1,0,1,0,0",
        "--eye",
        "-2,1.5,3",
        "--target",
        "0,0,0",
        "-o",
        o,
    ]);
    assert!(ok, "{err}");
    let (ok, err) = wirepass(&["render", "--highlight", "-1", "-o", o]);
    assert!(!ok && err.contains("--highlight"), "{err}");
}

/// Runs `wirepass bench ARGS --out OUT` and returns its bench.json.
fn bench_json(args: &[&str], out: &std::path::Path) -> serde_json::Value {
    let mut all = vec!["bench"];
    all.extend_from_slice(args);
    all.extend(["--out", out.to_str().unwrap()]);
    let (ok, err) = wirepass(&all);
    assert!(ok, "{err}");
    serde_json::from_slice(&std::fs::read(out.join("bench.json")).unwrap()).unwrap()
}

/// A bench run small enough for a test: a 2 k-triangle sphere, 64×48, two frames.
const TINY_BENCH: [&str; 7] = [
    "sphere:2000",
    "--size",
    "64x48",
    "--frames",
    "2",
    "--warmup",
    "0",
];

#[test]
fn bench_times_only_the_methods_asked_for() {
    let out = temp("bench-methods");
    let json = bench_json(
        &[&TINY_BENCH[..], &["--methods", "floor,deferred"]].concat(),
        &out,
    );
    let methods: Vec<_> = json["runs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["method"].as_str().unwrap().to_owned())
        .collect();
    assert_eq!(methods, ["floor", "deferred"]);

    let (ok, err) = wirepass(&["bench", "--methods", "deferred,fast", "--out", "x"]);
    assert!(!ok);
    let first = err.lines().next().unwrap_or_default();
    assert!(
        first.contains("\"fast\"") && first.contains("two-pass"),
        "{err}"
    );
}

#[test]
fn bench_writes_table_json_csv_and_plots() {
    let out = temp("bench");
    let args = ["sphere:2000", "grid:500", "--size", "64x48,96x64"];
    let json = bench_json(
        &[&args[..], &["--frames", "2", "--warmup", "1"]].concat(),
        &out,
    );
    assert!(json["device"]["name"].is_string());
    let runs = json["runs"].as_array().unwrap();
    // 2 scenes × 2 sizes × (floor, deferred, render-pass, forward, two-pass, gs).
    assert_eq!(runs.len(), 24);
    for run in runs {
        for key in [
            "scene",
            "triangles",
            "size",
            "method",
            "passes",
            "total_median_ms",
            "gpu_bytes",
        ] {
            assert!(run.get(key).is_some(), "run lacks {key}: {run}");
        }
        let total = run["total_median_ms"].as_f64().unwrap();
        assert!(total.is_finite() && total >= 0.0);
        for stats in run["passes"].as_object().unwrap().values() {
            let (p10, median, p90) = (
                stats["p10_ms"].as_f64().unwrap(),
                stats["median_ms"].as_f64().unwrap(),
                stats["p90_ms"].as_f64().unwrap(),
            );
            assert!(p10 <= median && median <= p90, "{stats}");
        }
    }
    let methods: std::collections::BTreeSet<_> =
        runs.iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert_eq!(
        methods.into_iter().collect::<Vec<_>>(),
        [
            "deferred",
            "floor",
            "forward",
            "gs",
            "render-pass",
            "two-pass"
        ]
    );
    let gs = runs.iter().find(|r| r["method"] == "gs").unwrap();
    assert!(gs["gl"].as_str().unwrap().contains("OpenGL"), "{gs}");
    let csv = std::fs::read_to_string(out.join("bench.csv")).unwrap();
    assert!(csv.lines().count() > 20);
    let report = std::fs::read_to_string(out.join("bench.md")).unwrap();
    assert!(report.contains("| deferred ÷ gs |"), "{report}");
    // The ratios of the run, in the report and as the baseline's records.
    assert!(report.contains("| render-pass ÷ deferred |"), "{report}");
    let ratios: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("ratios.json")).unwrap()).unwrap();
    let names: std::collections::BTreeSet<_> = ratios
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["ratio"].as_str().unwrap())
        .collect();
    for name in [
        "deferred ÷ gs",
        "deferred ÷ forward",
        "edge ÷ floor",
        "render-pass ÷ deferred",
    ] {
        assert!(names.contains(name), "{names:?}");
    }
    for plot in ["time_vs_triangles.png", "time_vs_pixels.png"] {
        let img = image::open(out.join(plot)).unwrap();
        assert!(img.width() > 100, "{plot}");
    }
}

#[test]
fn feature_edges_from_the_command_line() {
    let png = temp("fandisk.png");
    let (ok, err) = wirepass(&[
        "render",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../tests/data/meshes/fandisk.obj"
        ),
        "--edges",
        "feature:30",
        "--line-width",
        "3",
        "--size",
        "128x96",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (ok, err) = wirepass(&[
        "render",
        "--edges",
        "feature:400",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("feature:DEGREES"), "{err}");
}

/// Reads a little-endian u32 `.npy` file (the dumps' id map).
fn read_u32_npy(path: &std::path::Path) -> Vec<u32> {
    let bytes = std::fs::read(path).unwrap();
    let header = 10 + u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    bytes[header..]
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

#[test]
fn renders_a_scene_file_with_global_ids_in_the_dump() {
    let scene = temp("two.json");
    std::fs::write(
        &scene,
        r#"{"objects": [
            {"mesh": "sphere:200", "transform": {"translate": [-1.2, 0, 0]}},
            {"mesh": "sphere:200", "transform": {"translate": [1.2, 0, 0], "scale": [1, 1.5, 1]},
             "edges": "all", "line_width": 3}
        ],
        "camera": {"eye": [0, 0, 6], "orthographic": {"height": 4, "near": 0.1, "far": 20}}}"#,
    )
    .unwrap();
    let png = temp("two.png");
    let dump = temp("two-dump");
    let (ok, err) = wirepass(&[
        "render",
        scene.to_str().unwrap(),
        "--size",
        "96x64",
        "-o",
        png.to_str().unwrap(),
        "--dump",
        dump.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(err.contains("2 objects"), "{err}");
    let ids = read_u32_npy(&dump.join("ids.npy"));
    assert_eq!(ids.len(), 96 * 64);
    // The sphere has 200 triangles: the second object's ids follow the first's.
    let triangles = wirepass::mesh::sphere(200).unwrap().triangle_count() as u32;
    let first = ids.iter().filter(|&&id| id < triangles).count();
    let second = ids
        .iter()
        .filter(|&&id| (triangles..2 * triangles).contains(&id))
        .count();
    assert!(first > 100 && second > 100, "{first} and {second} pixels");
    assert!(ids.iter().all(|&id| id < 2 * triangles || id == u32::MAX));
    let camera: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dump.join("camera.json")).unwrap()).unwrap();
    assert_eq!(camera["orthographic"], true);
    // The file's style: hidden lines, which the command line can turn off again.
    let styled = temp("styled.json");
    std::fs::write(
        &styled,
        r#"{"objects": [{"mesh": "torus:800", "edges": "all"},
                        {"mesh": "sphere:200", "transform": {"translate": [0, 0, -1.5]}}],
            "camera": {"eye": [0, 0, 6], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 40,
                       "near": 0.1, "far": 20},
            "style": {"hidden": "solid", "hidden_width": 2}}"#,
    )
    .unwrap();
    // Pixels of a dumped distance map within `within` px of a line.
    let line_pixels = |map: &str, within: f32, extra: &[&str]| {
        let dir = temp(&format!("styled-dump{}", extra.len()));
        let mut args = vec![
            "render",
            styled.to_str().unwrap(),
            "--size",
            "96x64",
            "-o",
            png.to_str().unwrap(),
            "--dump",
            dir.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let (ok, err) = wirepass(&args);
        assert!(ok, "{err}");
        let bytes = std::fs::read(dir.join(map)).unwrap();
        let header = u16::from_le_bytes([bytes[8], bytes[9]]) as usize + 10;
        bytes[header..]
            .chunks_exact(4)
            .filter(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]) <= within)
            .count()
    };
    let hidden_pixels = |extra: &[&str]| line_pixels("hidden_distance.npy", f32::MAX, extra);
    assert!(hidden_pixels(&[]) > 50, "the file's hidden lines");
    assert_eq!(hidden_pixels(&["--hidden", "off"]), 0);
    // The sphere behind the torus, highlighted: its outline shows through, hidden lines off.
    assert!(hidden_pixels(&["--hidden", "off", "--highlight", "1"]) > 20);
    // A bad field in the file is one line naming the file and the field.
    let bad = temp("bad.json");
    std::fs::write(
        &bad,
        r#"{"objects": [{"mesh": "sphere:200", "transform": [1, 0]}]}"#,
    )
    .unwrap();
    let (ok, err) = wirepass(&["render", bad.to_str().unwrap(), "-o", png.to_str().unwrap()]);
    assert!(!ok);
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("wirepass: error:"))
        .collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(
        lines[0].contains("bad.json") && lines[0].contains("objects[0].transform"),
        "{err}"
    );
}

/// Runs `wirepass` and returns (success, stdout, stderr).
fn wirepass_out(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_wirepass"))
        .args(args)
        .output()
        .expect("the wirepass binary runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "panic for {args:?}: {stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    (out.status.success(), stdout, stderr)
}

#[test]
fn pick_prints_what_a_pixel_shows_as_json() {
    let args = |at: &'static str| ["pick", "sphere:2000", "--size", "160x120", "--at", at];
    let (ok, out, err) = wirepass_out(&args("80,60"));
    assert!(ok, "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}"));
    assert_eq!(json["shows"], "object", "{out}");
    assert_eq!(json["object"], 0);
    assert_eq!(json["pixel"], serde_json::json!([80, 60]));
    assert!(json["triangle"].as_u64().is_some_and(|t| t < 2100), "{out}");
    let v = |key: &str| -> Vec<f64> {
        json[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let n = v("normal");
    assert!(
        (n.iter().map(|x| x * x).sum::<f64>() - 1.0).abs() < 1e-9,
        "{out}"
    );
    // The centre of the framed unit sphere is on its near side, facing the eye.
    let p = v("point");
    assert!(
        (p.iter().map(|x| x * x).sum::<f64>().sqrt() - 1.0).abs() < 0.01,
        "{out}"
    );
    assert!(
        json["edge"]["distance_px"]
            .as_f64()
            .is_some_and(|d| d <= 8.0),
        "{out}"
    );

    let (ok, out, err) = wirepass_out(&args("0,0"));
    assert!(ok, "{err}");
    assert!(out.contains("\"shows\": \"background\""), "{out}");

    for bad in ["160,0", "3", "a,b"] {
        let (ok, _, err) = wirepass_out(&args(bad));
        assert!(!ok, "--at {bad} was accepted");
        let lines: Vec<_> = err
            .lines()
            .filter(|l| !l.contains("XDG_RUNTIME_DIR"))
            .collect();
        assert!(!lines.is_empty() && lines[0].contains("error"), "{err}");
    }
}

/// Where no OpenGL context can be made (here: a libEGL that is not there), the benchmark and
/// `compare` report `gs` skipped with the reason, and time and judge the other methods.
#[test]
fn gs_is_skipped_with_its_reason_where_opengl_is_missing() {
    let missing = "/nonexistent/libEGL.so.1";
    let out = temp("bench-without-gl");
    let bench = Command::new(env!("CARGO_BIN_EXE_wirepass"))
        .env("WIREPASS_EGL_LIBRARY", missing)
        .args(["bench", "sphere:500", "--size", "64x48", "--frames", "1"])
        .args(["--warmup", "0", "--methods", "forward,gs", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&bench.stdout);
    assert!(
        bench.status.success(),
        "{}",
        String::from_utf8_lossy(&bench.stderr)
    );
    let gs_row = stdout
        .lines()
        .find(|l| l.starts_with("| sphere:500 ") && l.contains("| gs |"))
        .unwrap_or_default();
    assert!(
        gs_row.contains("skipped") && gs_row.contains(missing),
        "{stdout}"
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("bench.json")).unwrap()).unwrap();
    let runs = json["runs"].as_array().unwrap();
    let forward = runs.iter().find(|r| r["method"] == "forward").unwrap();
    assert!(forward["total_median_ms"].as_f64().unwrap() > 0.0);
    let gs = runs.iter().find(|r| r["method"] == "gs").unwrap();
    assert!(gs["skipped"].as_str().unwrap().contains(missing), "{gs}");

    let out = temp("compare-without-gl");
    let compare = Command::new(env!("CARGO_BIN_EXE_wirepass"))
        .env("WIREPASS_EGL_LIBRARY", missing)
        .args(["compare", "sphere:500", "--size", "64x48", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(compare.status.success());
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    let skipped = report["methods"]["gs"]["skipped"]
        .as_str()
        .unwrap_or_default();
    assert!(skipped.contains(missing), "{report}");
    assert!(report["methods"]["forward"]["id_agreement"].is_number());
}

/// `--outlines on,off` times the deferred method and the floor both ways, the methods
/// that draw no outline once; the summary puts the two deferred totals side by side.
#[test]
fn bench_times_outlines_on_and_off_in_one_run() {
    let out = temp("bench-outlines");
    let json = bench_json(
        &[
            &TINY_BENCH[..],
            &["--outlines", "on,off", "--methods", "deferred,gs"],
        ]
        .concat(),
        &out,
    );
    let runs: Vec<(String, bool)> = json["runs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["method"].as_str().unwrap().to_owned(),
                r["outlines"].as_bool().unwrap(),
            )
        })
        .collect();
    let expected = [("deferred", true), ("gs", true), ("deferred", false)];
    assert_eq!(runs, expected.map(|(m, o)| (m.to_owned(), o)));
    let report = std::fs::read_to_string(out.join("bench.md")).unwrap();
    let row = report
        .lines()
        .find(|l| l.starts_with("| sphere:2000 | 1980 | 64x48 | – |"))
        .unwrap_or_else(|| panic!("no summary row: {report}"));
    // deferred, deferred without outlines and gs each have a time; edge ÷ floor has none
    // (the floor was not timed), deferred ÷ gs both ratios.
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    for k in [5, 6, 9] {
        assert!(cells[k].parse::<f64>().is_ok(), "{k}: {row}");
    }
    assert_eq!(cells[10], "–", "{row}");
    assert_eq!(cells[11].matches('×').count(), 2, "{row}");
}

/// `--edge-pattern` and `--outline-pattern` dash the visible lines: a cube's feature edges
/// dashed 2 px every 10 px keep about (2 + 1) / 10 of the solid lines' cores.
#[test]
fn patterns_dash_the_visible_lines() {
    let core = |extra: &[&str]| {
        let dir = temp(&format!("pattern-dump{}", extra.len()));
        let png = temp(&format!("pattern{}.png", extra.len()));
        let mut args = vec![
            "render",
            "cube:300",
            "--edges",
            "feature:30",
            "--size",
            "160x120",
            "-o",
            png.to_str().unwrap(),
            "--dump",
            dir.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let (ok, err) = wirepass(&args);
        assert!(ok, "{err}");
        let bytes = std::fs::read(dir.join("edge_distance.npy")).unwrap();
        let header = u16::from_le_bytes([bytes[8], bytes[9]]) as usize + 10;
        bytes[header..]
            .chunks_exact(4)
            .filter(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]) <= 0.5)
            .count() as f64
    };
    let solid = core(&[]);
    let dashed = core(&[
        "--edge-pattern",
        "dashed:2,8",
        "--outline-pattern",
        "dashed:2,8",
    ]);
    let share = dashed / solid;
    assert!((0.2..0.45).contains(&share), "{dashed} of {solid} pixels");
}

#[test]
fn drawing_writes_svg_pdf_and_dxf_and_refuses_what_it_cannot_draw() {
    let mesh = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/meshes/fandisk.obj"
    );
    for ext in ["svg", "pdf", "dxf"] {
        let out = temp(&format!("drawing.{ext}"));
        let (ok, err) = wirepass(&[
            "drawing",
            mesh,
            "--edges",
            "feature:30",
            "--hidden",
            "dashed",
            "--view",
            "iso",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{ext}: {err}");
        let bytes = std::fs::read(&out).unwrap();
        let head = String::from_utf8_lossy(&bytes[..16.min(bytes.len())]).into_owned();
        let expected = match ext {
            "svg" => "<?xml",
            "pdf" => "%PDF",
            _ => "  0\nSECTION",
        };
        assert!(head.starts_with(expected), "{ext}: {head:?}");
    }
    let scaled = temp("scaled.svg");
    let (ok, err) = wirepass(&[
        "drawing",
        mesh,
        "--view",
        "front",
        "--scale",
        "1:2",
        "-o",
        scaled.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(std::fs::read_to_string(&scaled).unwrap().contains("mm\""));
    for (args, says) in [
        (vec!["drawing", mesh, "-o", "out.png"], ".svg, .pdf or .dxf"),
        (
            vec!["drawing", mesh, "--view", "sideways", "-o", "x.svg"],
            "view \"sideways\"",
        ),
        (
            vec!["drawing", mesh, "--scale", "1:0", "-o", "x.svg"],
            "--scale",
        ),
        (
            vec!["drawing", mesh, "--scale", "1:10", "-o", "x.svg"],
            "orthographic",
        ),
        (
            vec!["drawing", mesh, "--unit", "furlong", "-o", "x.svg"],
            "--unit",
        ),
        (
            vec!["drawing", mesh, "-o", "/nonexistent/dir/x.svg"],
            "/nonexistent/dir/x.svg",
        ),
    ] {
        let (ok, err) = wirepass(&args);
        assert!(!ok, "{args:?} succeeded");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
}
