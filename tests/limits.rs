//! Impossible settings and device limits are `wirepass::Error` values, never aborts:
//! cameras and styles that cannot make an image, image sizes of zero or over
//! `max_texture_dimension_2d`, and meshes over `max_storage_buffer_binding_size` (tested on a
//! device requested with a deliberately small limit).

mod common;

use common::gpu;
use glam::{DMat4, Vec3};
use wirepass::gpu::{DeferredPass, MeshStore, OutputTarget, PassOptions, TriangleIds};
use wirepass::mesh::Procedural;
use wirepass::{Camera, Color, EdgeSelection, Error, Instance, Scene, Style};

fn cam() -> Camera {
    Camera {
        eye: Vec3::new(0.0, 0.0, 3.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_deg: 45.0,
        near: 0.1,
        far: 10.0,
    }
}

#[test]
fn cameras_with_non_finite_or_negative_values_are_rejected() {
    // src/camera.rs tests the geometric cases (eye on target, up parallel or zero, fov 0 and
    // 180, near 0, far < near, NaN eye); these are the non-finite and negative ones.
    let cases = [
        Camera {
            target: Vec3::new(0.0, f32::INFINITY, 0.0),
            ..cam()
        },
        Camera {
            up: Vec3::new(f32::NAN, 1.0, 0.0),
            ..cam()
        },
        Camera {
            fov_y_deg: f32::NAN,
            ..cam()
        },
        Camera {
            fov_y_deg: -30.0,
            ..cam()
        },
        Camera {
            fov_y_deg: 270.0,
            ..cam()
        },
        Camera {
            near: -0.1,
            ..cam()
        },
        Camera {
            near: f32::NAN,
            ..cam()
        },
        Camera {
            near: f32::INFINITY,
            far: f32::INFINITY,
            ..cam()
        },
        Camera {
            far: f32::NAN,
            ..cam()
        },
        Camera { far: 0.1, ..cam() },
        Camera {
            // Eye and target a rounding error apart, far from the origin.
            eye: Vec3::splat(1e30),
            target: Vec3::splat(1e30),
            ..cam()
        },
    ];
    for c in cases {
        let e = c.validate().expect_err(&format!("{c:?} was accepted"));
        assert!(matches!(e, Error::InvalidCamera(_)), "{e:?}");
        assert!(e.to_string().starts_with("invalid camera: "), "{e}");
    }
    // An infinite far plane is a projection of its own, not an error.
    let infinite = Camera {
        far: f32::INFINITY,
        ..cam()
    };
    infinite.validate().unwrap();
    infinite.to_view(1.5).validate().unwrap();
}

#[test]
fn styles_that_cannot_make_an_image_are_rejected() {
    let nan = Color([f32::NAN, 0.0, 0.0, 1.0]);
    let cases: Vec<(Style, &str)> = vec![
        (
            Style {
                line_width: f32::INFINITY,
                ..Style::default()
            },
            "line width",
        ),
        (
            Style {
                line_width: -0.5,
                ..Style::default()
            },
            "line width",
        ),
        (
            Style {
                ambient: 1.5,
                ..Style::default()
            },
            "ambient",
        ),
        (
            Style {
                ambient: -0.1,
                ..Style::default()
            },
            "ambient",
        ),
        (
            Style {
                ambient: f32::NAN,
                ..Style::default()
            },
            "ambient",
        ),
        (
            Style {
                light_view_dir: Vec3::ZERO,
                ..Style::default()
            },
            "light direction",
        ),
        (
            Style {
                light_view_dir: Vec3::new(f32::NAN, 1.0, 0.0),
                ..Style::default()
            },
            "light direction",
        ),
        (
            Style {
                wire_color: nan,
                ..Style::default()
            },
            "colour",
        ),
        (
            Style {
                fill_color: Color([0.0, f32::INFINITY, 0.0, 1.0]),
                ..Style::default()
            },
            "colour",
        ),
        (
            Style {
                background: nan,
                ..Style::default()
            },
            "colour",
        ),
    ];
    assert!(Style::default().validate().is_ok());
    // A zero-width line is allowed: it draws no line.
    let thin = Style {
        line_width: 0.0,
        ..Style::default()
    };
    assert!(thin.validate().is_ok());
    for (style, word) in cases {
        let e = style
            .validate()
            .expect_err(&format!("{style:?} was accepted"));
        assert!(matches!(e, Error::InvalidSetting(_)), "{e:?}");
        assert!(e.to_string().contains(word), "'{e}' lacks '{word}'");
    }
}

#[test]
fn image_sizes_are_checked_against_the_device() {
    let ctx = gpu();
    let device = &ctx.device;
    let mesh = Procedural::Sphere(200).build().unwrap();
    let mut store = MeshStore::new(device);
    let id = store
        .insert(device, &ctx.queue, &mesh, EdgeSelection::Polygon)
        .unwrap();
    let scene = Scene::new(cam().to_view(1.0), vec![Instance::new(id, DMat4::IDENTITY)]);
    let mut pass = DeferredPass::new(device, PassOptions::default()).unwrap();
    let style = Style::default();
    for size in [(0, 10), (10, 0), (0, 0)] {
        let e = pass
            .prepare(device, &store, &scene, &style, size)
            .err()
            .unwrap();
        assert!(matches!(e, Error::InvalidSetting(_)), "{size:?}: {e:?}");
        assert!(e.to_string().contains("zero side"), "{e}");
    }
    let limit = device.limits().max_texture_dimension_2d;
    for (size, excess) in [((limit + 1, 16), 1), ((16, limit + 100), 100)] {
        let e = pass
            .prepare(device, &store, &scene, &style, size)
            .err()
            .unwrap();
        match &e {
            Error::OverLimit {
                limit_name,
                value,
                limit: l,
                ..
            } => {
                assert_eq!(*limit_name, "max_texture_dimension_2d");
                assert_eq!(*l, u64::from(limit));
                assert_eq!(value - l, excess);
            }
            e => panic!("{size:?}: {e:?}"),
        }
        let msg = e.to_string();
        assert!(
            msg.contains(&format!("max_texture_dimension_2d = {limit}"))
                && msg.contains(&format!("(by {excess})")),
            "{msg}"
        );
    }
    // The limit itself is fine, and a failed prepare leaves the pass usable.
    pass.prepare(device, &store, &scene, &style, (limit, 1))
        .unwrap();
    pass.prepare(device, &store, &scene, &style, (32, 24))
        .unwrap();
    ctx.finish().unwrap();
}

/// A device with `limits`, on the test adapter, kept for the whole run: on wgpu's GL
/// backend, dropping a second device breaks what the other tests' device draws afterwards.
fn device_with(limits: wgpu::Limits) -> &'static (wgpu::Device, wgpu::Queue) {
    Box::leak(Box::new(
        pollster::block_on(gpu().adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("wirepass lowered limits"),
            required_limits: limits,
            ..Default::default()
        }))
        .expect("a device with lower limits than the adapter's"),
    ))
}

#[test]
fn a_mesh_over_the_storage_binding_limit_is_an_error_not_an_abort() {
    let small: u32 = 1 << 16;
    let mesh: wirepass::Mesh = "sphere:20000"
        .parse::<Procedural>()
        .unwrap()
        .build()
        .unwrap();
    // With the WebGPU defaults' 8 storage buffers per stage a store cannot be split over two
    // bindings; with the adapter's own it can, but not over more than two.
    let cases = [
        (wgpu::Limits::default(), "max_storage_buffer_binding_size"),
        (
            gpu().adapter.limits(),
            "max_storage_buffer_binding_size × 2",
        ),
    ];
    for (limits, name) in cases {
        let (device, queue) = device_with(wgpu::Limits {
            max_storage_buffer_binding_size: small.into(),
            ..limits
        });
        assert_eq!(
            device.limits().max_storage_buffer_binding_size,
            u64::from(small)
        );
        let mut store = MeshStore::new(device);
        let e = match store.insert(device, queue, &mesh, EdgeSelection::Polygon) {
            Ok(_) => panic!("a {}-triangle mesh fit in 64 KiB", mesh.triangle_count()),
            Err(e) => e,
        };
        match &e {
            Error::OverLimit {
                limit_name,
                value,
                limit,
                ..
            } => {
                assert_eq!(*limit_name, name);
                assert!(*limit >= u64::from(small));
                assert!(value > limit);
            }
            e => panic!("{e:?}"),
        }
        let msg = e.to_string();
        assert!(msg.contains(name) && msg.contains("(by "), "{msg}");
        // A mesh that fits still uploads to the same store.
        let tiny = Procedural::Sphere(200).build().unwrap();
        store
            .insert(device, queue, &tiny, EdgeSelection::Polygon)
            .unwrap();
    }
}

#[test]
fn a_mesh_too_wide_for_f32_is_reported_as_such() {
    // Every coordinate is finite, but the extent overflows f32: framing it used to give an
    // infinite eye and the message "invalid camera: eye [inf, inf, inf] is not finite".
    let mesh = wirepass::Mesh::new(
        vec![
            Vec3::new(-3e38, 0.0, 0.0),
            Vec3::new(3e38, 0.0, 0.0),
            Vec3::new(0.0, 3e38, 0.0),
        ],
        None,
        vec![[0, 1, 2]],
        None,
    )
    .unwrap();
    for args in [
        wirepass::tools::load::CameraPlacement::default(),
        wirepass::tools::load::CameraPlacement {
            eye: Some(Vec3::new(0.0, 0.0, 1e3)),
            ..Default::default()
        },
    ] {
        let e = args.camera(mesh.bounds_f64(), (64, 48)).unwrap_err();
        assert!(matches!(e, Error::InvalidMesh(_)), "{e:?}");
        assert!(e.to_string().contains("more than f32"), "{e}");
    }
}

#[test]
fn a_far_explicit_eye_gets_finite_planes() {
    // The distance to the mesh used to be an f32 length whose squares overflowed, giving
    // "invalid camera: near inf must be > 0" for --eye 1e30,1e30,1e30.
    let mesh = Procedural::Sphere(200).build().unwrap();
    let args = wirepass::tools::load::CameraPlacement {
        eye: Some(Vec3::splat(1e30)),
        ..Default::default()
    };
    let cam = args.camera(mesh.bounds_f64(), (64, 48)).unwrap();
    assert!(cam.near.is_finite() && cam.far.is_finite() && cam.near < cam.far);
}

/// A mesh 1e-30 or 1e30 across renders as the same mesh at unit size does: framing works
/// in f64, and nothing on the way (normals, clip coordinates, the edge math) underflows or
/// overflows in f32.
#[test]
fn meshes_of_tiny_and_huge_extent_render_like_a_unit_one() {
    let torus = Procedural::Torus(3000).build().unwrap();
    let at_scale = |scale: f32| {
        let positions = torus.positions().iter().map(|p| *p * scale).collect();
        let triangles = torus.triangles().to_vec();
        wirepass::Mesh::new(positions, None, triangles, None).unwrap()
    };
    let size = (160, 120);
    let draw = |mesh: &wirepass::Mesh| {
        let scene = common::TestScene::new(
            mesh,
            common::framing(mesh, size),
            Style::default(),
            size,
            EdgeSelection::Polygon,
        );
        scene.draw(wirepass::tools::offline::Method::Deferred)
    };
    let reference = draw(&at_scale(1.0));
    let covered = reference
        .ids
        .iter()
        .filter(|&&id| id != wirepass::world::BACKGROUND)
        .count();
    assert!(
        covered > 2000,
        "the unit torus covers only {covered} pixels"
    );
    for scale in [1e-30f32, 1e30] {
        let scaled = at_scale(scale);
        let camera = common::framing(&scaled, size);
        camera
            .validate()
            .unwrap_or_else(|e| panic!("x{scale:e}: the framing camera: {e}"));
        let frame = draw(&scaled);
        let same_ids = frame
            .ids
            .iter()
            .zip(&reference.ids)
            .filter(|(a, b)| a == b)
            .count();
        let agreement = same_ids as f64 / reference.ids.len() as f64;
        let diff = wirepass::tools::regression::difference(
            wirepass::tools::regression::Rgba::new(&reference.rgba, size).unwrap(),
            wirepass::tools::regression::Rgba::new(&frame.rgba, size).unwrap(),
        )
        .unwrap();
        println!("extent x{scale:e}: id agreement {agreement:.5}, FLIP {diff}");
        assert!(agreement >= 0.999, "x{scale:e}: id agreement {agreement}");
        assert!(
            diff.mean <= 0.002 && diff.p99 <= 0.02,
            "x{scale:e}: FLIP {diff}"
        );
    }
}

#[test]
fn triangle_ids_without_primitive_index_pull_vertices_or_are_an_error() {
    // A device without optional features: no PRIMITIVE_INDEX.
    let (device, queue) = device_with(gpu().adapter.limits());
    assert!(!device.features().contains(wgpu::Features::PRIMITIVE_INDEX));
    let with = |triangle_ids| {
        DeferredPass::new(
            device,
            PassOptions {
                triangle_ids,
                ..PassOptions::default()
            },
        )
    };
    match with(TriangleIds::PrimitiveIndex) {
        Err(Error::MissingFeature { what, .. }) => assert!(what.contains("PRIMITIVE_INDEX")),
        other => panic!("expected a missing feature, got {:?}", other.err()),
    }
    // Auto and VertexPulling draw with pulled vertices.
    let mesh: wirepass::Mesh = "sphere:2000"
        .parse::<Procedural>()
        .unwrap()
        .build()
        .unwrap();
    let mut store = MeshStore::new(device);
    let id = store
        .insert(device, queue, &mesh, EdgeSelection::Polygon)
        .unwrap();
    let scene = Scene::new(cam().to_view(1.0), vec![Instance::new(id, DMat4::IDENTITY)]);
    for ids in [TriangleIds::Auto, TriangleIds::VertexPulling] {
        let mut pass = with(ids).unwrap();
        let frame = pass
            .prepare(device, &store, &scene, &Style::default(), (64, 64))
            .unwrap();
        let usage = wgpu::TextureUsages::STORAGE_BINDING;
        let output =
            wirepass::gpu::texture_2d(device, "out", (64, 64), pass.output_format(), usage);
        let view = output.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        pass.encode(
            device,
            &mut encoder,
            &store,
            &frame,
            OutputTarget::Shaded(&view),
        )
        .unwrap();
        queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    }
}
