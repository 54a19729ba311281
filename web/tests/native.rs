//! The native side of the browser tests: each frame of `cases` drawn on the machine's own
//! adapter (lavapipe in CI) is within the project's bounds of the ground truth and matches
//! the reference image the browser's frame is held against (`web/tests/reference/`, drawn
//! on lavapipe; `WIREPASS_BLESS=1` redraws them). FLIP mean ≤ 0.002, p99 ≤ 0.05: the same
//! frame on another native adapter (llvmpipe through GL) differs by rounding only.

#![cfg(not(target_arch = "wasm32"))]

mod cases;

use std::path::Path;
use wirepass::gpu::GpuContext;
use wirepass::tools::regression::{check_against_reference, Outcome, Threshold};

#[test]
fn native_frames_match_the_references_and_the_ground_truth() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("a native adapter: {e}"));
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("web-references");
    for case in cases::all() {
        let frame = pollster::block_on(cases::draw(&ctx.device, &ctx.queue, &case));
        ctx.finish()
            .unwrap_or_else(|e| panic!("{}: {e}", case.name));
        let frame = frame.unwrap_or_else(|e| panic!("{}: {e}", case.name));
        let truth = cases::truth(&case).unwrap_or_else(|e| panic!("{}: {e}", case.name));
        println!("{}", cases::check_accuracy(case.name, &truth, &frame));
        let reference = dir.join("reference").join(case.reference());
        let threshold = Threshold {
            mean: 0.002,
            p99: 0.05,
        };
        match check_against_reference(&frame.rgba, frame.size, &reference, &threshold, &out) {
            Ok(Outcome::Pass(d)) => println!("{}: FLIP against the reference {d}", case.name),
            Ok(Outcome::Blessed(path)) => println!("wrote {}", path.display()),
            Err(e) => panic!("{}: {e}", case.name),
        }
    }
}

/// A frame's time on the native adapter, measured as the browser test measures it (the
/// browser docs, docs/browser.md, quote both); printed, never asserted.
#[test]
fn frame_time_of_the_builtin_scene() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("a native adapter: {e}"));
    let start = std::time::Instant::now();
    let clock = || start.elapsed().as_secs_f64() * 1000.0;
    let ms = pollster::block_on(cases::frame_time(
        &ctx.device,
        &ctx.queue,
        (1280, 720),
        15,
        clock,
    ));
    ctx.finish().unwrap();
    println!(
        "frame time, built-in scene, 1280x720, {}: {:.1} ms (median of 15)",
        ctx.describe(),
        ms.unwrap()
    );
}

// The element's own model reader and attribute parser (the views' native twins).
#[allow(dead_code)]
#[path = "../src/model.rs"]
mod model;
#[allow(dead_code)]
#[path = "../src/settings.rs"]
mod settings;

/// An element's attributes: names and values.
type Attributes = &'static [(&'static str, &'static str)];

/// The `<wirepass-viewer>` views the browser test (`web/tests/element.py`) loads: a name, the
/// model's path in the repository (served to the page at the same path), and the element's
/// attributes.
const ELEMENT_VIEWS: [(&str, &str, Attributes); 3] = [
    (
        "element-suzanne",
        "tests/data/meshes/suzanne.obj",
        &[("camera", "30 20")],
    ),
    (
        "element-suzanne-hidden",
        "tests/data/meshes/suzanne.obj",
        &[("camera", "30 20"), ("hidden", "dashed")],
    ),
    (
        "element-boxes",
        "web/tests/data/boxes.gltf",
        &[("camera", "iso"), ("line-width", "2"), ("edges", "all")],
    ),
];

/// An element view as a case: the model read as the element reads it (a `.gltf`'s buffers
/// beside it), its attributes parsed as the element parses them, drawn at the element's
/// 320×240 through the canvas's render-pass path into its sRGB view, as the element draws.
fn element_case(name: &'static str, src: &str, attributes: &[(&str, &str)]) -> cases::Case {
    use wirepass::world::{Object, World, WorldMesh};
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let path = root.join(src);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{src}: {e}"));
    let mut resources = model::Resources::new();
    if src.ends_with(".gltf") {
        let beside = path.with_extension("bin");
        let file = beside.file_name().unwrap().to_string_lossy().to_string();
        resources.insert(file, std::fs::read(&beside).unwrap());
    }
    let file = Path::new(src).file_name().unwrap().to_string_lossy();
    let model =
        model::Model::from_file(&file, &bytes, &resources).unwrap_or_else(|e| panic!("{src}: {e}"));
    let (mut style, mut edges, mut camera) = (wirepass::Style::default(), None, "");
    for &(key, value) in attributes {
        match key {
            "edges" => edges = settings::edges(value).unwrap(),
            "camera" => camera = value,
            _ => settings::apply_style(&mut style, key, Some(value))
                .expect("a style attribute")
                .unwrap(),
        }
    }
    let world = World {
        meshes: (model.meshes.iter())
            .map(|(mesh, own)| {
                let (mesh, edges) = mesh.clone().resolve_edges(edges.or(*own));
                WorldMesh {
                    mesh: std::sync::Arc::new(mesh),
                    edges,
                    name: name.into(),
                }
            })
            .collect(),
        objects: (model.instances.iter())
            .map(|&(m, transform)| Object::new(m, transform))
            .collect(),
        sections: Vec::new(),
    };
    let aspect = f64::from(cases::SIZE.0) / f64::from(cases::SIZE.1);
    let view = settings::orbit(camera, model.bounds())
        .unwrap()
        .camera()
        .to_view(aspect);
    cases::Case {
        name,
        world,
        view,
        style,
        output: cases::Output::RenderPass(wirepass::wgpu::TextureFormat::Bgra8UnormSrgb),
        host: None,
    }
}

/// A pixel inside one triangle of `truth`, well away from its lines: the nearest to the
/// image's centre whose 5×5 neighbourhood shows that triangle and no line.
fn quiet_pixel(truth: &wirepass::world::Rendering) -> (u32, u32) {
    let (w, h) = truth.size;
    let at = |x: u32, y: u32| (y * w + x) as usize;
    let quiet = |x: u32, y: u32| {
        let id = truth.ids[at(x, y)];
        id != wirepass::gpu::BACKGROUND_ID
            && (x - 2..=x + 2).all(|i| {
                (y - 2..=y + 2).all(|j| truth.ids[at(i, j)] == id)
                    && truth.edge_distance[at(x, y)] > 4.0
            })
    };
    let mut pixels: Vec<(u32, u32)> = (2..h - 2)
        .flat_map(|y| (2..w - 2).map(move |x| (x, y)))
        .collect();
    let centre =
        |&(x, y): &(u32, u32)| (x as i64 - w as i64 / 2).pow(2) + (y as i64 - h as i64 / 2).pow(2);
    pixels.sort_by_key(centre);
    pixels
        .into_iter()
        .find(|&(x, y)| quiet(x, y))
        .expect("a quiet pixel")
}

/// The element's views drawn natively match the references its browser test holds the
/// element's `snapshot()` to, and are within the project's bounds of the ground truth;
/// `web/tests/reference/element.json` lists the views for the browser test with the pixel
/// it clicks and the ground truth's instance and triangle there (`WIREPASS_BLESS=1` writes
/// it anew).
#[test]
fn element_views_match_the_references_and_the_ground_truth() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("a native adapter: {e}"));
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference");
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("web-references");
    let mut listed = Vec::new();
    for (name, src, attributes) in ELEMENT_VIEWS {
        let case = element_case(name, src, attributes);
        let frame = pollster::block_on(cases::draw(&ctx.device, &ctx.queue, &case));
        ctx.finish().unwrap_or_else(|e| panic!("{name}: {e}"));
        let frame = frame.unwrap_or_else(|e| panic!("{name}: {e}"));
        let truth = cases::truth(&case).unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("{}", cases::check_accuracy(name, &truth, &frame));
        let threshold = Threshold {
            mean: 0.002,
            p99: 0.05,
        };
        let reference = dir.join(case.reference());
        match check_against_reference(&frame.rgba, frame.size, &reference, &threshold, &out) {
            Ok(Outcome::Pass(d)) => println!("{name}: FLIP against the reference {d}"),
            Ok(Outcome::Blessed(path)) => println!("wrote {}", path.display()),
            Err(e) => panic!("{name}: {e}"),
        }
        let pixel = quiet_pixel(&truth);
        let id = truth.ids[(pixel.1 * truth.size.0 + pixel.0) as usize];
        let (instance, triangle) = case.world.locate(&case.world.first_ids(), id);
        let attributes: Vec<String> = (attributes.iter())
            .map(|(k, v)| format!("{{\"name\": \"{k}\", \"value\": \"{v}\"}}"))
            .collect();
        listed.push(format!(
            "  {{\"name\": \"{name}\", \"src\": \"{src}\", \"attributes\": [{}], \
             \"pick\": {{\"pixel\": [{}, {}], \"instance\": {instance}, \"triangle\": {triangle}}}}}",
            attributes.join(", "),
            pixel.0,
            pixel.1
        ));
    }
    let json = format!("[\n{}\n]\n", listed.join(",\n"));
    let path = dir.join("element.json");
    if std::env::var_os("WIREPASS_BLESS").is_some() {
        std::fs::write(&path, &json).unwrap();
        println!("wrote {}", path.display());
    } else {
        let recorded = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (WIREPASS_BLESS=1 writes it)", path.display()));
        assert_eq!(recorded, json, "{} is out of date", path.display());
    }
}
