//! wirepass in a browser (headless Chromium, WebGPU on its SwiftShader adapter), run by
//! `wasm-bindgen-test-runner`:
//!
//! - the frames of `cases` drawn on WebGPU and read back through futures: each within the
//!   project's bounds of the ground truth (ray-cast here, in the page), and the same as the
//!   frame the native adapter drew (`web/tests/reference/`, lavapipe);
//! - misuse in a page: a `wirepass::Error` where wirepass can tell, the device's
//!   uncaptured-error handler where only the device can, and nothing blocks;
//! - the viewer page itself: its first frame, a drag, a dropped `.glb`.
//!
//! No test passes without a WebGPU adapter: one that cannot get one fails.

#![cfg(target_arch = "wasm32")]

mod cases;

use std::sync::{Arc, Mutex};
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_futures::JsFuture;
use wasm_bindgen_test::{console_log, wasm_bindgen_test, wasm_bindgen_test_configure};
use wirepass::gpu::{read_texture_async, texture_2d};
use wirepass::world::Rendering;
use wirepass::{wgpu, DeferredPass, Error, MeshStore, OutputTarget, PassOptions};

wasm_bindgen_test_configure!(run_in_browser);

/// A WebGPU device with the default limits, its uncaptured errors collected.
async fn device() -> (wgpu::Device, wgpu::Queue, Arc<Mutex<Vec<String>>>) {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: wgpu::Backends::BROWSER_WEBGPU,
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    });
    let adapter = instance
        .request_adapter(&Default::default())
        .await
        .unwrap_or_else(|e| panic!("the browser gives no WebGPU adapter: {e}"));
    let (device, queue) = adapter
        .request_device(&wgpu::DeviceDescriptor {
            required_features: adapter.features() & wgpu::Features::PRIMITIVE_INDEX,
            required_limits: wgpu::Limits::default(),
            ..Default::default()
        })
        .await
        .unwrap_or_else(|e| panic!("no device: {e}"));
    let errors = Arc::new(Mutex::new(Vec::new()));
    let sink = errors.clone();
    device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
        sink.lock().unwrap().push(e.to_string())
    }));
    (device, queue, errors)
}

/// How the browser's frame differs from the native one: the share of pixels whose colour
/// differs by more than 8 of 255 in a channel, and the mean absolute difference (0..1).
/// (FLIP, which the native tests use, is a C++ library that does not build for wasm32.)
fn image_difference(a: &[u8], b: &[u8]) -> (f64, f64) {
    let pixels = a.len() / 4;
    let mut over = 0usize;
    let mut sum = 0u64;
    for (p, q) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        let d = (0..3).map(|k| p[k].abs_diff(q[k])).max().unwrap_or(0);
        over += usize::from(d > 8);
        sum += (0..3).map(|k| u64::from(p[k].abs_diff(q[k]))).sum::<u64>();
    }
    (
        over as f64 / pixels as f64,
        sum as f64 / (3.0 * 255.0 * pixels as f64),
    )
}

fn reference(name: &str) -> Vec<u8> {
    let png: &[u8] = match name {
        "default-scene" => include_bytes!("reference/default-scene.png"),
        "suzanne-quads" => include_bytes!("reference/suzanne-quads.png"),
        "mirrored-orthographic" => include_bytes!("reference/mirrored-orthographic.png"),
        "host-depth" => include_bytes!("reference/host-depth.png"),
        "render-pass-bgra8unorm" => include_bytes!("reference/render-pass-bgra8unorm.png"),
        other => panic!("no reference for {other}"),
    };
    image::load_from_memory(png)
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .to_rgba8()
        .into_raw()
}

/// Each case drawn on WebGPU is within bounds of the ground truth and of the native frame:
/// ids agree with the ray cast on ≥ 99.9 % of the foreground, the distance error's p99 is
/// ≤ 0.01 px and its max ≤ 0.1 px; against lavapipe's frame, at most 0.2 % of the pixels
/// differ by more than 8/255 and the mean difference is ≤ 0.002.
#[wasm_bindgen_test]
async fn frames_equal_the_native_ones_and_the_ground_truth() {
    let (device, queue, errors) = device().await;
    for case in cases::all() {
        let frame: Rendering = cases::draw(&device, &queue, &case)
            .await
            .unwrap_or_else(|e| panic!("{}: {e}", case.name));
        assert_eq!(
            *errors.lock().unwrap(),
            Vec::<String>::new(),
            "{}",
            case.name
        );
        let truth = cases::truth(&case).unwrap_or_else(|e| panic!("{}: {e}", case.name));
        console_log!("{}", cases::check_accuracy(case.name, &truth, &frame));
        let native = reference(case.name);
        let (share, mean) = image_difference(&native, &frame.rgba);
        console_log!(
            "{}: against lavapipe, {:.4} % of pixels differ by > 8/255, mean difference {mean:.2e}",
            case.name,
            100.0 * share
        );
        assert!(
            share <= 0.002 && mean <= 0.002,
            "{}: {share} {mean}",
            case.name
        );
    }
}

/// Misuse in a page: what wirepass can check is its `Error` at once; what only the device
/// can tell (a texture of another device) reaches the uncaptured-error handler, and the call
/// returns without blocking.
#[wasm_bindgen_test]
async fn misuse_is_reported_without_blocking() {
    let (device, queue, errors) = device().await;
    let mut pass = DeferredPass::new(&device, PassOptions::default()).unwrap();
    let mut store = MeshStore::new(&device);
    let torus = wirepass::mesh::torus(500).unwrap();
    let id = store
        .insert(&device, &queue, &torus, wirepass::EdgeSelection::Polygon)
        .unwrap();
    let (lo, hi) = torus.bounds_f64();
    let view = wirepass::Camera::framing(lo, hi, 1.0).to_view(1.0);
    let instances = [wirepass::Instance::new(id, wirepass::glam::DMat4::IDENTITY)];
    let scene = wirepass::Scene::borrowed(view, &instances);
    let style = wirepass::Style::default();

    // Checked by wirepass: a zero size, a non-finite transform, a storage texture of the
    // wrong format, render without a render target.
    let e = pass.prepare(&device, &store, &scene, &style, (0, 64)).err();
    assert!(matches!(e, Some(Error::InvalidSetting(_))), "{e:?}");
    let bad = [wirepass::Instance::new(
        id,
        wirepass::glam::DMat4::from_scale(wirepass::glam::DVec3::splat(f64::NAN)),
    )];
    let e = pass
        .prepare(
            &device,
            &store,
            &wirepass::Scene::borrowed(view, &bad),
            &style,
            (64, 64),
        )
        .err();
    assert!(e.is_some(), "a NaN transform was accepted");
    let frame = pass
        .prepare(&device, &store, &scene, &style, (64, 64))
        .unwrap();
    let usage = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC;
    let wrong = texture_2d(
        &device,
        "wrong",
        (64, 64),
        wgpu::TextureFormat::Rgba32Float,
        usage,
    );
    let wrong_view = wrong.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    let e = pass
        .encode(
            &device,
            &mut encoder,
            &store,
            &frame,
            OutputTarget::Shaded(&wrong_view),
        )
        .err();
    assert!(
        matches!(e, Some(Error::InvalidSetting(_) | Error::Misuse(_))),
        "{e:?}"
    );
    // Another store's mesh.
    let other = MeshStore::new(&device);
    let e = pass
        .prepare(&device, &other, &scene, &style, (64, 64))
        .err();
    assert!(e.is_some(), "a mesh of another store was accepted");
    assert!(
        errors.lock().unwrap().is_empty(),
        "{:?}",
        errors.lock().unwrap()
    );

    // Only the device can tell: an output texture of another device. The encode returns at
    // once (it cannot wait on an error scope here) and the error reaches the handler.
    let (device2, _queue2, _) = self::device().await;
    let foreign = texture_2d(&device2, "foreign", (64, 64), pass.output_format(), usage);
    let foreign_view = foreign.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    let result = pass.encode(
        &device,
        &mut encoder,
        &store,
        &frame,
        OutputTarget::Shaded(&foreign_view),
    );
    console_log!(
        "a texture of another device: encode returned {:?}",
        result.as_ref().err()
    );
    queue.submit([encoder.finish()]);
    // Any readback completes (nothing hangs), and by then the device has reported.
    let probe = texture_2d(
        &device,
        "probe",
        (4, 4),
        wgpu::TextureFormat::Rgba8Unorm,
        usage,
    );
    read_texture_async(&device, &queue, &probe, wgpu::TextureAspect::All)
        .await
        .unwrap();
    sleep(100).await;
    let reported = errors.lock().unwrap().clone();
    console_log!(
        "the device reported {} errors, the first: {}",
        reported.len(),
        reported
            .first()
            .and_then(|e| e.lines().next())
            .unwrap_or("none")
    );
    assert!(
        result.is_err() || !reported.is_empty(),
        "a texture of another device went unreported"
    );
}

/// Picking in a page: `pick_async` and `pick_rect_async` complete on the event loop and
/// say what the ground truth sees (every 4th pixel of the built-in scene: ≥ 99.9 % of the
/// foreground the same instance and file triangle once `locate` has corrected the
/// rasterizer's choice on edges, where SwiftShader's rounding differs more often than
/// lavapipe's), and the located point has the truth's depth.
#[wasm_bindgen_test]
async fn picking_works_in_the_page() {
    use wirepass::gpu::{Canvas, PickView, Picked};
    use wirepass::world::offscreen::{encode_shaded, Uploaded};
    use wirepass::world::BACKGROUND;
    let (device, queue, errors) = device().await;
    let case = cases::all().remove(0);
    let up = Uploaded::new(&device, &queue, &case.world).unwrap();
    let scene = up.scene(&case.world, case.view);
    let mut pass = DeferredPass::new(&device, PassOptions::default()).unwrap();
    let canvas = Canvas::new(cases::SIZE);
    let (frame, _image) =
        encode_shaded(&device, &queue, &case.shot(), &up, &mut pass, canvas).unwrap();

    let truth = cases::truth(&case).unwrap();
    let first = case.world.first_ids();
    let pick_view = PickView {
        view: case.view,
        image: cases::SIZE,
        vertices: wirepass::gpu::SnapVertices::Any,
        sections: Vec::new(),
    };
    let (mut foreground, mut agree, mut raster_agree, mut worst_depth) =
        (0usize, 0usize, 0usize, 0f64);
    for y in (0..cases::SIZE.1).step_by(4) {
        for x in (0..cases::SIZE.0).step_by(4) {
            let picked = frame
                .pick_async(&device, &queue, &up.store, &scene, (x, y))
                .await
                .unwrap();
            let k = (y * cases::SIZE.0 + x) as usize;
            // The exact triangle: the rasterizer's, corrected by `locate` on edges.
            let got = match picked {
                Picked::Background => BACKGROUND,
                Picked::Host => panic!("no host here"),
                Picked::Instance(hit) => {
                    let object = &case.world.objects[hit.instance];
                    let mesh = &case.world.meshes[object.mesh];
                    let at = hit.locate(&mesh.mesh, &pick_view, (x, y), 4.0).unwrap();
                    raster_agree += usize::from(first[hit.instance] + hit.triangle == truth.ids[k]);
                    let id = if at.inside {
                        first[hit.instance] + at.triangle
                    } else {
                        BACKGROUND
                    };
                    if at.inside && id == truth.ids[k] {
                        let clip = case.view.view_projection() * at.point.extend(1.0);
                        let depth = (clip.z / clip.w - f64::from(truth.depth[k])).abs();
                        worst_depth = worst_depth.max(depth);
                    }
                    id
                }
            };
            if got == BACKGROUND && truth.ids[k] == BACKGROUND {
                continue;
            }
            foreground += 1;
            agree += usize::from(got == truth.ids[k]);
            if got != truth.ids[k] {
                console_log!(
                    "pixel ({x}, {y}): picked {got}, the ground truth {} (distance to its edge {})",
                    truth.ids[k],
                    truth.edge_distance[k]
                );
            }
        }
    }
    let rect = frame
        .pick_rect_async(
            &device,
            &queue,
            &up.store,
            &scene,
            (0, 0),
            cases::SIZE,
            false,
        )
        .await
        .unwrap();
    let agreement = agree as f64 / foreground as f64;
    console_log!(
        "picking in the page: {foreground} foreground picks, the rasterizer's triangle agrees \
         on {:.5}, the located one on {agreement:.5}, depth within {worst_depth:.1e}; the whole \
         frame shows instances {:?}",
        raster_agree as f64 / foreground as f64,
        rect.instances
    );
    assert!(
        foreground > 300 && agreement >= 0.999,
        "{agree} of {foreground}"
    );
    assert!(worst_depth < 1e-6, "{worst_depth}");
    assert_eq!(rect.instances, [0, 1]);
    assert!(
        errors.lock().unwrap().is_empty(),
        "{:?}",
        errors.lock().unwrap()
    );
}

/// A browser without WebGPU (here `navigator.gpu` hidden for the test, then restored) gets a
/// message on the page saying so, and `start` rejects with it: no blank canvas, no panic.
#[wasm_bindgen_test]
async fn a_browser_without_webgpu_gets_a_message() {
    use js_sys::{Object, Reflect};
    let window = web_sys::window().unwrap();
    let navigator: JsValue = window.navigator().into();
    let hidden = Object::new();
    Reflect::set(&hidden, &"value".into(), &JsValue::UNDEFINED).unwrap();
    Reflect::set(&hidden, &"configurable".into(), &true.into()).unwrap();
    let target: &Object = navigator.unchecked_ref();
    Object::define_property(target, &JsValue::from_str("gpu"), &hidden);
    let document = window.document().unwrap();
    let root: web_sys::HtmlElement = document.create_element("div").unwrap().unchecked_into();
    document.body().unwrap().append_child(&root).unwrap();
    let started = wirepass_web::start(root.clone()).await;
    // Restore the browser's own navigator.gpu for the other tests.
    Reflect::delete_property(target, &JsValue::from_str("gpu")).unwrap();
    assert!(!Reflect::get(&navigator, &"gpu".into())
        .unwrap()
        .is_undefined());

    let message = started
        .err()
        .and_then(|e| e.as_string())
        .expect("start rejects");
    console_log!("without WebGPU: {message}");
    assert!(message.contains("WebGPU"), "{message}");
    let shown = root
        .query_selector(".wirepass-error")
        .unwrap()
        .and_then(|p| p.text_content())
        .unwrap_or_default();
    assert_eq!(shown, message);
    assert!(root.query_selector("canvas").unwrap().is_none());
}

async fn sleep(ms: i32) {
    let promise = js_sys::Promise::new(&mut |resolve, _| {
        web_sys::window()
            .unwrap()
            .set_timeout_with_callback_and_timeout_and_arguments_0(&resolve, ms)
            .unwrap();
    });
    JsFuture::from(promise).await.unwrap();
}

/// Waits until `done` holds, for at most `seconds`.
async fn until(what: &str, seconds: f64, done: impl Fn() -> bool) {
    let start = js_sys::Date::now();
    while !done() {
        assert!(
            js_sys::Date::now() - start < seconds * 1000.0,
            "timed out waiting for {what}"
        );
        sleep(20).await;
    }
}

/// The shares of a frame that show the background, the shaded surface and lines.
fn content(rgba: &[u8]) -> (f64, f64, f64) {
    let style = wirepass::Style::default();
    let pixels = (rgba.len() / 4) as f64;
    let share =
        |f: &dyn Fn(&[u8]) -> bool| rgba.chunks_exact(4).filter(|p| f(p)).count() as f64 / pixels;
    let sky = style.background.to_srgb8();
    let background = share(&|p| (0..3).all(|k| p[k].abs_diff(sky[k]) <= 2));
    let dark = wirepass::Color(style.fill_color.0.map(|c| c * style.ambient * 0.5)).to_srgb8();
    let lines = share(&|p| (0..3).all(|k| p[k] < dark[k]));
    (background, 1.0 - background - lines, lines)
}

fn changed(a: &[u8], b: &[u8]) -> f64 {
    let n = a
        .chunks_exact(4)
        .zip(b.chunks_exact(4))
        .filter(|(p, q)| (0..3).any(|k| p[k].abs_diff(q[k]) > 16))
        .count();
    n as f64 / (a.len() / 4) as f64
}

/// A small glTF binary: a cube and its mirror image, from positions and indices.
fn cubes_glb() -> Vec<u8> {
    let cube = wirepass::mesh::cube(12).unwrap();
    let mut bin: Vec<u8> = Vec::new();
    for p in cube.positions() {
        bin.extend(p.to_array().iter().flat_map(|c| c.to_le_bytes()));
    }
    let positions = bin.len();
    for t in cube.triangles() {
        bin.extend(t.iter().flat_map(|i| i.to_le_bytes()));
    }
    let (lo, hi) = cube.bounds();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],
        "nodes":[{{"mesh":0,"translation":[-1.2,0,0]}},{{"mesh":0,"translation":[1.2,0,0],"scale":[-1,1,1],"rotation":[0.3,0,0,0.954]}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "buffers":[{{"byteLength":{}}}],
        "bufferViews":[{{"buffer":0,"byteLength":{positions}}},{{"buffer":0,"byteOffset":{positions},"byteLength":{}}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":[{},{},{}],"max":[{},{},{}]}},
        {{"bufferView":1,"componentType":5125,"count":{},"type":"SCALAR"}}]}}"#,
        bin.len(),
        bin.len() - positions,
        cube.positions().len(),
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
        3 * cube.triangles().len()
    );
    let mut json = json.into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend((total as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(bin);
    glb
}

fn pointer(kind: &str, x: f64, y: f64, buttons: u16) -> web_sys::PointerEvent {
    let init = web_sys::PointerEventInit::new();
    init.set_pointer_id(7);
    init.set_client_x(x as i32);
    init.set_client_y(y as i32);
    init.set_button(0);
    init.set_buttons(buttons);
    init.set_bubbles(true);
    init.set_cancelable(true);
    init.set_is_primary(true);
    web_sys::PointerEvent::new_with_event_init_dict(kind, &init).unwrap()
}

/// The viewer page: its first frame shows the built-in scene (background, surface, lines);
/// a drag with the mouse turns the view; a `.glb` dropped on the page is shown.
#[wasm_bindgen_test]
async fn the_viewer_page_draws_turns_and_shows_a_dropped_glb() {
    let document = web_sys::window().unwrap().document().unwrap();
    let root: web_sys::HtmlElement = document.create_element("div").unwrap().unchecked_into();
    root.style().set_property("width", "640px").unwrap();
    root.style().set_property("height", "480px").unwrap();
    document.body().unwrap().append_child(&root).unwrap();
    let viewer = wirepass_web::start(root.clone())
        .await
        .unwrap_or_else(|e| panic!("the viewer did not start: {e:?}"));
    console_log!(
        "viewer on {}, canvas {}x{}",
        viewer.adapter(),
        viewer.width(),
        viewer.height()
    );
    until("the first frame", 30.0, || viewer.frames() > 0).await;
    assert_eq!(viewer.error(), None);
    let first = viewer.snapshot().await.unwrap();
    let (background, surface, lines) = content(&first);
    console_log!("first frame: {background:.3} background, {surface:.3} surface, {lines:.4} lines");
    assert!(background > 0.05 && surface > 0.05 && lines > 0.002);

    // A click on the surface picks it: the toolbar says which triangle.
    let canvas_el: web_sys::HtmlElement = root
        .query_selector("canvas")
        .unwrap()
        .unwrap()
        .unchecked_into();
    let rect = canvas_el.get_bounding_client_rect();
    let sky = wirepass::Style::default().background.to_srgb8();
    let w = viewer.width() as usize;
    let surface_pixel = first
        .chunks_exact(4)
        .enumerate()
        .position(|(i, p)| {
            // Well inside the surface: this pixel and its neighbours are neither sky nor line.
            let plain = |q: &[u8]| (0..3).any(|k| q[k].abs_diff(sky[k]) > 40) && q[0] > 100;
            i > w
                && i + w < first.len() / 4
                && plain(p)
                && plain(&first[4 * (i - w)..])
                && plain(&first[4 * (i + w)..])
        })
        .expect("a surface pixel");
    let (sx, sy) = ((surface_pixel % w) as f64, (surface_pixel / w) as f64);
    let (cx, cy) = (rect.left() + sx + 0.5, rect.top() + sy + 0.5);
    canvas_el
        .dispatch_event(&pointer("pointerdown", cx, cy, 1))
        .unwrap();
    canvas_el
        .dispatch_event(&pointer("pointerup", cx, cy, 0))
        .unwrap();
    until("a pick", 30.0, || {
        viewer.picked().is_some() || viewer.error().is_some()
    })
    .await;
    assert_eq!(viewer.error(), None);
    let picked = viewer.picked().unwrap();
    console_log!("a click at ({sx}, {sy}) picked {picked}");
    assert!(picked.contains("triangle"), "{picked}");

    // A drag of 120 px to the right across the canvas.
    let canvas: web_sys::HtmlElement = root
        .query_selector("canvas")
        .unwrap()
        .unwrap()
        .unchecked_into();
    let rect = canvas.get_bounding_client_rect();
    let (x, y) = (rect.left() + 300.0, rect.top() + 200.0);
    let frames = viewer.frames();
    canvas
        .dispatch_event(&pointer("pointerdown", x, y, 1))
        .unwrap();
    for step in 1..=6 {
        canvas
            .dispatch_event(&pointer("pointermove", x + 20.0 * f64::from(step), y, 1))
            .unwrap();
    }
    canvas
        .dispatch_event(&pointer("pointerup", x + 120.0, y, 0))
        .unwrap();
    until("a frame after the drag", 30.0, || viewer.frames() > frames).await;
    let turned = viewer.snapshot().await.unwrap();
    let moved = changed(&first, &turned);
    console_log!("the drag changed {:.1} % of the pixels", 100.0 * moved);
    assert!(moved > 0.02, "the drag did not turn the view ({moved})");

    // A .glb dropped on the page, as a browser delivers it.
    let bytes = js_sys::Uint8Array::from(cubes_glb().as_slice());
    let parts = js_sys::Array::of1(&bytes);
    let file = web_sys::File::new_with_u8_array_sequence(&parts, "cubes.glb").unwrap();
    let transfer = web_sys::DataTransfer::new().unwrap();
    transfer.items().add_with_file(&file).unwrap();
    let init = web_sys::DragEventInit::new();
    init.set_bubbles(true);
    init.set_cancelable(true);
    init.set_data_transfer(Some(&transfer));
    let drop = web_sys::DragEvent::new_with_event_init_dict("drop", &init).unwrap();
    let frames = viewer.frames();
    canvas.dispatch_event(&drop).unwrap();
    until("the dropped file", 30.0, || {
        viewer.model_name() == "cubes.glb" || viewer.error().is_some()
    })
    .await;
    assert_eq!(viewer.error(), None);
    until("a frame of the dropped file", 30.0, || {
        viewer.frames() > frames
    })
    .await;
    let dropped = viewer.snapshot().await.unwrap();
    let (background, surface, lines) = content(&dropped);
    console_log!("cubes.glb: {background:.3} background, {surface:.3} surface, {lines:.4} lines");
    assert!(background > 0.05 && surface > 0.05 && lines > 0.002);
    assert!(
        changed(&turned, &dropped) > 0.05,
        "the dropped file is not shown"
    );

    // A file that cannot be read is an error on the page, and the model stays.
    let e = viewer
        .load("broken.stl".into(), b"solid x\nfacet".to_vec())
        .await;
    assert!(e.is_err());
    assert!(
        viewer.error().is_some_and(|e| e.contains("broken.stl")),
        "{:?}",
        viewer.error()
    );
    assert_eq!(viewer.model_name(), "cubes.glb");

    // Back to the built-in scene.
    viewer.load_builtin().unwrap();
    assert_eq!(viewer.model_name(), "the built-in scene");

    // `H` cycles the hidden lines: dashed ones show through the surfaces.
    let frames = viewer.frames();
    until("a frame of the built-in scene", 30.0, || {
        viewer.frames() > frames
    })
    .await;
    let plain = viewer.snapshot().await.unwrap();
    let init = web_sys::KeyboardEventInit::new();
    init.set_key("h");
    let key = web_sys::KeyboardEvent::new_with_keyboard_event_init_dict("keydown", &init).unwrap();
    let frames = viewer.frames();
    let window: web_sys::EventTarget = web_sys::window().unwrap().into();
    window.dispatch_event(&key).unwrap();
    assert_eq!(viewer.hidden(), "dashed");
    until("a frame with hidden lines", 30.0, || {
        viewer.frames() > frames
    })
    .await;
    let hidden = viewer.snapshot().await.unwrap();
    let shown = changed(&plain, &hidden);
    console_log!(
        "dashed hidden lines changed {:.2} % of the pixels",
        100.0 * shown
    );
    assert!(shown > 0.005, "the hidden lines are not shown ({shown})");

    // "Export SVG": the view as a drawing of the canvas's size.
    let svg = viewer.export_svg().unwrap();
    console_log!("the drawing of the view: {} bytes", svg.len());
    assert!(
        svg.starts_with("<?xml") && svg.contains("<path"),
        "{}",
        &svg[..svg.len().min(300)]
    );
    let view_box = format!("viewBox=\"0 0 {} {}\"", viewer.width(), viewer.height());
    assert!(svg.contains(&view_box), "{}", &svg[..svg.len().min(300)]);
    assert!(svg.contains("<g id=\"outlines\""));

    // `S` cuts the scene open through the orbit's centre: the section face shows; `]` moves
    // the cut, `Backspace` takes it away again.
    let press = |k: &str| {
        let init = web_sys::KeyboardEventInit::new();
        init.set_key(k);
        let key =
            web_sys::KeyboardEvent::new_with_keyboard_event_init_dict("keydown", &init).unwrap();
        window.dispatch_event(&key).unwrap();
    };
    let section = wirepass::Style::default().section_color.to_srgb8();
    let faces = |rgba: &[u8]| {
        let n = rgba
            .chunks_exact(4)
            .filter(|p| (0..3).all(|k| p[k].abs_diff(section[k]) <= 2))
            .count();
        n as f64 / (rgba.len() / 4) as f64
    };
    let mut shots = Vec::new();
    for (key, planes) in [("s", 1), ("]", 1), ("Backspace", 0)] {
        let frames = viewer.frames();
        press(key);
        assert_eq!(viewer.sections(), planes, "after {key}");
        until("a frame after a section key", 30.0, || {
            viewer.frames() > frames
        })
        .await;
        shots.push(viewer.snapshot().await.unwrap());
    }
    let (cut, moved, uncut) = (&shots[0], &shots[1], &shots[2]);
    console_log!(
        "section: {:.2} % section face, {:.2} % of the pixels changed; moved: {:.2} % changed",
        100.0 * faces(cut),
        100.0 * changed(&hidden, cut),
        100.0 * changed(cut, moved)
    );
    assert!(
        faces(cut) > faces(&hidden) + 0.004,
        "no section face ({} cut, {} uncut)",
        faces(cut),
        faces(&hidden)
    );
    assert!(
        changed(cut, moved) > 0.001,
        "moving the cut changed nothing"
    );
    assert_eq!(changed(&hidden, uncut), 0.0, "the cut is not gone");
}

/// A frame's time in the page (docs/browser.md quotes it beside the native one): not a test of
/// speed, which no test asserts, but a reported figure must be measured, so it runs here.
#[wasm_bindgen_test]
async fn frame_time_of_the_builtin_scene() {
    let (device, queue, errors) = device().await;
    let clock = || {
        web_sys::window()
            .and_then(|w| w.performance())
            .map_or(0.0, |p| p.now())
    };
    let ms = cases::frame_time(&device, &queue, (1280, 720), 15, clock)
        .await
        .unwrap();
    console_log!(
        "frame time, built-in scene, 1280x720, WebGPU in the browser: {ms:.1} ms (median of 15)"
    );
    assert!(
        errors.lock().unwrap().is_empty(),
        "{:?}",
        errors.lock().unwrap()
    );
}
