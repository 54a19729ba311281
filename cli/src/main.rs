//! `wirepass`: render mesh wireframes on the GPU from the command line.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use wirepass::glam::Vec3;
use wirepass::gpu::GpuContext;
use wirepass::style::{DepthFade, DEFAULT_LINE_WIDTH};
use wirepass::tools::bench::Timed;
use wirepass::tools::load::{load_world, parse_size, parse_vec3, CameraPlacement, WorldOptions};
use wirepass::tools::offline::{
    draw, draw_deferred_image, draw_deferred_timed, FirstImage, Method,
};
use wirepass::tools::pipeline_cache::CacheUse;
use wirepass::tools::regression::save_rgba_png;
use wirepass::world::{Shot, World};
use wirepass::{Color, EdgeSelection, HiddenLines, Highlight, LinePattern, Result, Style, View};

#[derive(Parser)]
#[command(
    name = "wirepass",
    version,
    about = "Mesh wireframes on the GPU as a deferred compute pass"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene (a SCENE.json file, a glTF or GLB file, an OBJ, STL or PLY file,
    /// `sphere:N`, `grid:N`, `torus:N`, `cube:N`, `layers:K`, or the built-in scene).
    Render(RenderArgs),
    /// Render one scene with the CPU ray-cast ground truth and every GPU method, and report
    /// how closely each matches it (images, error maps, sheet.png, report.json).
    Compare(CompareArgs),
    /// Time every method (and the floor: visibility + id-only compute) with GPU timestamps
    /// on each scene and size; write bench.json, bench.csv and plots.
    Bench(BenchArgs),
    /// Compare two images with FLIP: print mean, p99 and max; exit non-zero over the threshold.
    Diff(DiffArgs),
    /// Write the scene's lines as a vector drawing (SVG, PDF or DXF, by -o's extension):
    /// drawn edges, outlines, hidden lines, cut and intersection lines in render's style,
    /// their visible and hidden runs found exactly in f64 on the CPU (no GPU needed).
    Drawing(DrawingArgs),
    /// Print, as JSON, what pixel --at X,Y of the scene's deferred frame shows: the object,
    /// its mesh, the file's triangle and polygon, the exact point and normal, and the drawn
    /// edge and vertex nearest it within --snap pixels.
    Pick(PickArgs),
}

fn parse_edges(s: &str) -> std::result::Result<EdgeSelection, String> {
    s.parse().map_err(|e: wirepass::Error| e.to_string())
}

/// What to draw and how it looks: shared by `render` and `compare`.
#[derive(clap::Args)]
struct SceneArgs {
    /// Scene file (.json: objects with transforms and styles, and a camera), glTF scene
    /// (.gltf, .glb: its meshes, nodes and cameras), OBJ, STL or PLY file, or procedural
    /// mesh (`sphere:20000`, `grid:1k`, `torus:5000`, `cube:2M`); default: the built-in scene.
    mesh: Option<String>,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "800x600")]
    size: String,
    /// Line width in pixels [default: 1.5, or the glTF file's own widths]; given, it
    /// overrides a glTF file's widths.
    #[arg(long, allow_hyphen_values = true)]
    line_width: Option<f32>,
    /// Line colour, #rrggbb[aa] (sRGB).
    #[arg(long, default_value = "#0a0f19")]
    wire_color: String,
    /// Surface colour, #rrggbb (sRGB).
    #[arg(long, default_value = "#c2cfdf")]
    fill_color: String,
    /// Outline colour, #rrggbb[aa] (sRGB) [default: the line colour, or the scene file's].
    #[arg(long)]
    outline_color: Option<String>,
    /// Outline width in pixels [default: the line width, or the scene file's].
    #[arg(long, allow_hyphen_values = true)]
    outline_width: Option<f32>,
    /// Pattern of the visible drawn edges: solid, dashed[:DASH,GAP] or dotted[:SPACING],
    /// lengths in pixels, running on along chains of drawn edges. Only deferred and raycast
    /// draw patterns [default: solid, or the scene file's].
    #[arg(long, value_name = "PATTERN")]
    edge_pattern: Option<String>,
    /// Pattern of the visible outlines, as --edge-pattern [default: solid, or the scene
    /// file's].
    #[arg(long, value_name = "PATTERN")]
    outline_pattern: Option<String>,
    /// Background colour, #rrggbb (sRGB).
    #[arg(long, default_value = "#ffffff")]
    background: String,
    /// Which edges to draw: all, polygon (no triangulation diagonals), authored (the
    /// file's own: glTF edge visibility or outlines), or feature[:DEGREES] (creases sharper
    /// than DEGREES, default 1, plus boundaries) [default: authored where the file has
    /// them, else polygon]. Any but authored also lets every edge be an outline again.
    #[arg(long, value_parser = parse_edges)]
    edges: Option<EdgeSelection>,
    /// Outlines (silhouettes and boundaries) at full width over the background and farther
    /// surfaces, whatever --edges selects: on or off. Only deferred and raycast draw them.
    #[arg(long, alias = "silhouettes", default_value = "on", value_parser = parse_switch, action = clap::ArgAction::Set)]
    outlines: bool,
    /// Fade lines from full strength at view depth START to nothing at END (world units).
    #[arg(long, allow_hyphen_values = true, value_name = "START:END", value_parser = parse_fade)]
    depth_fade: Option<DepthFade>,
    /// Hidden lines (the parts of the drawn lines that surfaces hide): off, solid,
    /// dashed[:DASH,GAP] or dotted[:SPACING], lengths in pixels. Only deferred and raycast
    /// draw them [default: off, or the scene file's].
    #[arg(long, value_name = "STYLE")]
    hidden: Option<String>,
    /// Hidden-line colour, #rrggbb[aa] (sRGB) [default: #7c8189cc, or the scene file's].
    #[arg(long)]
    hidden_color: Option<String>,
    /// Hidden-line width in pixels [default: 1, or the scene file's].
    #[arg(long, allow_hyphen_values = true)]
    hidden_width: Option<f32>,
    /// Opacity of the shaded surface over the background, 0..1: below 1 a see-through
    /// surface, with --hidden lines showing through it [default: 1, or the scene file's].
    #[arg(long, allow_hyphen_values = true)]
    fill_opacity: Option<f32>,
    /// Draw object N (its place in the scene: a scene file's objects in order, a glTF
    /// scene's nodes) selected: its outline in orange, 3 px, dashed where other surfaces
    /// hide it, its fill tinted; repeat it, or give a list (0,2), for several.
    #[arg(
        long,
        allow_hyphen_values = true,
        value_name = "N",
        value_delimiter = ','
    )]
    highlight: Vec<usize>,
    /// A section plane through point (px, py, pz) with normal (nx, ny, nz), world
    /// coordinates: what lies behind it is cut away, back faces seen through the cut drawn
    /// as the section face; repeat it for up to 6 (a scene file's `sections` come first).
    /// Only deferred and raycast cut.
    #[arg(long, allow_hyphen_values = true, value_name = "PX,PY,PZ,NX,NY,NZ", value_parser = parse_section)]
    section: Vec<wirepass::SectionPlane>,
    /// Colour of the section face (back faces seen through a cut), #rrggbb (sRGB).
    #[arg(long, default_value = "#d9a38c")]
    section_color: String,
    /// Colour of the cut lines, where a section plane meets a surface, #rrggbb[aa] (sRGB).
    #[arg(long, default_value = "#5a1e0f")]
    section_line_color: String,
    /// Width of the cut lines in pixels [default: the line width].
    #[arg(long, allow_hyphen_values = true)]
    section_line_width: Option<f32>,
    /// Draw intersection lines: where surfaces of a mesh pass through each other, the curve
    /// along which they meet. Only deferred and raycast draw them.
    #[arg(long)]
    intersections: bool,
    /// Colour of the intersection lines, #rrggbb[aa] (sRGB).
    #[arg(long, default_value = "#e8262a")]
    intersection_color: String,
    /// Width of the intersection lines in pixels [default: the line width].
    #[arg(long, allow_hyphen_values = true)]
    intersection_width: Option<f32>,
    #[command(flatten)]
    camera: CameraArgs,
}

fn parse_switch(s: &str) -> std::result::Result<bool, String> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("{s:?} is not on or off")),
    }
}

fn parse_section(s: &str) -> std::result::Result<wirepass::SectionPlane, String> {
    let plane = wirepass::SectionPlane::parse(s).map_err(|e| e.to_string())?;
    plane.validate(0).map_err(|e| format!("{s:?}: {e}"))?;
    Ok(plane)
}

fn parse_fade(s: &str) -> std::result::Result<DepthFade, String> {
    let bad = || format!("{s:?} is not START:END, two numbers");
    let (start, end) = s.split_once(':').ok_or_else(bad)?;
    let number = |t: &str| t.trim().parse::<f32>().map_err(|_| bad());
    Ok(DepthFade {
        start: number(start)?,
        end: number(end)?,
    })
}

/// `world` with objects `selected` drawn highlighted in `style` (`--highlight`, a scene
/// file's `"highlight": true`); an object the world has not is an error.
fn highlighted(mut world: World, selected: &[usize], style: &Style) -> Result<World> {
    let objects = world.objects.len();
    for &n in selected {
        let object = world.objects.get_mut(n).ok_or_else(|| {
            wirepass::Error::InvalidSetting(format!(
                "--highlight {n}: the scene has {objects} object{}, 0 to {}",
                if objects == 1 { "" } else { "s" },
                objects.saturating_sub(1)
            ))
        })?;
        object.style = object.style.highlighted(&Highlight::default(), style);
    }
    Ok(world)
}

/// Prints the loader's notes, one line each.
fn print_notes(notes: &[String]) {
    for note in notes {
        eprintln!("wirepass: note: {note}");
    }
}

impl SceneArgs {
    /// Checks the settings, then loads the scene and places the camera.
    fn load(&self) -> Result<(World, View, Style, (u32, u32))> {
        let size = parse_size(&self.size)?;
        // The command line's settings, checked before loading; a scene file's `style` fills
        // in those the command line leaves unset.
        let color = |c: &Option<String>| c.as_deref().map(Color::from_hex).transpose();
        let (outline_color, hidden_color) =
            (color(&self.outline_color)?, color(&self.hidden_color)?);
        let hidden = self.hidden.as_deref().map(LinePattern::parse).transpose()?;
        let pattern = |p: &Option<String>| p.as_deref().map(LinePattern::parse_visible).transpose();
        let (edge_pattern, outline_pattern) = (
            pattern(&self.edge_pattern)?,
            pattern(&self.outline_pattern)?,
        );
        let style = Style {
            line_width: self.line_width.unwrap_or(DEFAULT_LINE_WIDTH),
            wire_color: Color::from_hex(&self.wire_color)?,
            fill_color: Color::from_hex(&self.fill_color)?,
            background: Color::from_hex(&self.background)?,
            section_color: Color::from_hex(&self.section_color)?,
            section_line_color: Color::from_hex(&self.section_line_color)?,
            section_line_width: self.section_line_width,
            intersection_lines: self.intersections,
            intersection_line_color: Color::from_hex(&self.intersection_color)?,
            intersection_line_width: self.intersection_width,
            outlines: self.outlines,
            depth_fade: self.depth_fade,
            ..Style::default()
        };
        style.validate()?;
        let options = WorldOptions {
            edges: self.edges,
            camera: self.camera.camera,
            line_width: self.line_width,
        };
        let loaded = load_world(self.mesh.as_deref(), &options)?;
        print_notes(&loaded.notes);
        let file = loaded.style;
        let style = Style {
            outline_color: outline_color.or(file.outline_color),
            outline_width: self.outline_width.or(file.outline_width),
            edge_pattern: edge_pattern
                .or(file.edge_pattern)
                .unwrap_or(LinePattern::Solid),
            outline_pattern: outline_pattern
                .or(file.outline_pattern)
                .unwrap_or(LinePattern::Solid),
            fill_opacity: self.fill_opacity.or(file.fill_opacity).unwrap_or(1.0),
            hidden: hidden.or(file.hidden).flatten().map(|pattern| HiddenLines {
                pattern,
                color: hidden_color
                    .or(file.hidden_color)
                    .unwrap_or(HiddenLines::default().color),
                width: self.hidden_width.or(file.hidden_width).unwrap_or(1.0),
                behind_host: false,
                edges: true,
            }),
            ..style
        };
        style.validate()?;
        let selected: Vec<usize> = self
            .highlight
            .iter()
            .chain(&loaded.highlight)
            .copied()
            .collect();
        let mut world = highlighted(loaded.world, &selected, &style)?;
        world.sections.extend_from_slice(&self.section);
        world.validate()?;
        let placement = self.camera.placement();
        let file_camera = loaded.camera.filter(|_| placement.is_empty());
        if let Some(wirepass::tools::scene_file::FileCamera::Gltf(c)) = &file_camera {
            let image = f64::from(size.0) / f64::from(size.1);
            if let Some(a) = c.aspect().filter(|a| (a / image - 1.0).abs() > 0.01) {
                print_notes(&[format!(
                    "the camera's aspect ratio is {a:.3} and the image's {image:.3}: the view is \
                     stretched to fit (--size with the camera's aspect avoids that)"
                )]);
            }
        }
        let view = placement.view(&world, file_camera.as_ref(), size)?;
        Ok((world, view, style, size))
    }
}

#[derive(clap::Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// How to draw: deferred (visibility buffer + compute edge pass), forward (single-pass
    /// altitudes, Bærentzen et al. 2006; divides by w as published), two-pass (biased fill,
    /// then 1 px edge lines), raycast (the f64 CPU ground truth; slow).
    #[arg(long, default_value = "deferred", value_parser = parse_method)]
    method: Method,
    /// Output PNG.
    #[arg(short, long, default_value = "wireframe.png")]
    output: PathBuf,
    /// Also write ids.npy (global triangle ids), depth.npy, edge_distance.npy,
    /// hidden_distance.npy, line_class.npy (deferred and raycast: 0 no line, 1 drawn edge, 2
    /// outline, 3 hidden line, 4 section cut line, 5 intersection line) and camera.json (the
    /// view and projection matrices used) into this directory.
    #[arg(long)]
    dump: Option<PathBuf>,
    /// Print where the time to the image goes (deferred method): reading the scene, each
    /// mesh's preprocessing and upload, the pipelines built, the first frame (where a
    /// driver that compiles shaders on first use compiles them), the readback; and the
    /// process's peak memory.
    #[arg(long)]
    timings: bool,
}

fn parse_method(s: &str) -> std::result::Result<Method, String> {
    s.parse().map_err(|e: wirepass::Error| e.to_string())
}

fn render_command(args: &RenderArgs) -> Result<()> {
    let start = Instant::now();
    let (world, view, style, size) = args.scene.load()?;
    let read = start.elapsed();
    let context = Instant::now();
    let ctx = GpuContext::new()?;
    let context = context.elapsed();
    let shot = Shot {
        world: &world,
        view,
        style: &style,
        size,
    };
    // The image alone where nothing else is asked for: no maps to compute and read back.
    let image_only = args.method == Method::Deferred && args.dump.is_none();
    if args.timings && args.method != Method::Deferred {
        return Err(wirepass::Error::InvalidSetting(
            "--timings times the deferred method only".into(),
        ));
    }
    let (frame, first) = if image_only {
        let (rgba, first) = draw_deferred_image(&ctx, &shot)?;
        save_rgba_png(&args.output, &rgba, size)?;
        (None, Some(first))
    } else if args.timings {
        let (frame, first) = draw_deferred_timed(&ctx, &shot)?;
        frame.save_png(&args.output)?;
        (Some(frame), Some(first))
    } else {
        let frame = draw(&ctx, &shot, args.method)?;
        frame.save_png(&args.output)?;
        (Some(frame), None)
    };
    if let (true, Some(first)) = (args.timings, &first) {
        print_timings(
            (read, context, start.elapsed()),
            first,
            world.triangle_count(),
        );
    }
    if let (Some(dir), Some(frame)) = (&args.dump, &frame) {
        frame.dump(dir, &view)?;
    }
    eprintln!(
        "wrote {} ({}, {}x{}, {} objects, {} triangles, {})",
        args.output.display(),
        args.method.name(),
        size.0,
        size.1,
        world.objects.len(),
        world.triangle_count(),
        ctx.describe()
    );
    Ok(())
}

/// Prints `render --timings`: the steps to the first image, one a line, in milliseconds.
fn print_timings(
    (read, context, total): (Duration, Duration, Duration),
    first: &FirstImage,
    triangles: u64,
) {
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let line = |what: &str, d: Duration| eprintln!("{what:<44}{:>9.1} ms", ms(d));
    line("read the scene", read);
    line("open the GPU", context);
    for (k, u) in first.uploads.iter().enumerate() {
        for (step, d) in u.steps() {
            // With all cores, the crossings are found while the first three steps run.
            let beside = if step == "crossings" {
                " (beside the three above)"
            } else {
                ""
            };
            line(&format!("mesh {k}: {step}{beside}"), d);
        }
    }
    line("all uploads, wall clock", first.upload);
    line("make the pass", first.pass);
    line("prepare the frame", first.prepare);
    line(
        &format!("build {} more pipelines", first.warm_up.pipelines),
        first.warm_up.elapsed,
    );
    line("first frame (shader compilation)", first.frame);
    match &first.pipeline_cache {
        CacheUse::Used {
            path,
            loaded,
            saved,
        } => eprintln!(
            "{:<44}{loaded} bytes read, {saved} written ({})",
            "pipeline cache",
            path.display()
        ),
        CacheUse::Unused(why) => eprintln!("{:<44}none: {why}", "pipeline cache"),
    }
    line("read back", first.readback);
    line("total, with the PNG", total);
    if let Some(peak) = peak_memory() {
        eprintln!(
            "{:<44}{:>9.1} MB ({:.0} bytes a triangle)",
            "peak memory",
            peak as f64 / 1e6,
            peak as f64 / triangles.max(1) as f64
        );
    }
}

/// The process's peak resident memory in bytes, where the system says (Linux).
fn peak_memory() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

#[derive(clap::Args)]
struct PickArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// The pixel, X,Y (0,0 is the top-left pixel).
    #[arg(long, value_parser = parse_pixel)]
    at: (u32, u32),
    /// Snapping radius for the nearest drawn edge and vertex, in pixels.
    #[arg(long, allow_hyphen_values = true, default_value = "8")]
    snap: f64,
}

fn parse_pixel(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || format!("{s:?} is not X,Y, two whole numbers");
    let (x, y) = s.split_once(',').ok_or_else(bad)?;
    Ok((
        x.trim().parse().map_err(|_| bad())?,
        y.trim().parse().map_err(|_| bad())?,
    ))
}

fn pick_command(args: &PickArgs) -> Result<()> {
    if !(args.snap >= 0.0 && args.snap.is_finite()) {
        return Err(wirepass::Error::InvalidSetting(format!(
            "--snap {} is not a finite number of pixels, 0 or more",
            args.snap
        )));
    }
    let (world, view, style, size) = args.scene.load()?;
    let ctx = GpuContext::new()?;
    let shot = Shot {
        world: &world,
        view,
        style: &style,
        size,
    };
    let report = wirepass::tools::pick::pick(&ctx, &shot, args.at, args.snap)?;
    println!("{}", report.to_json());
    Ok(())
}

#[derive(clap::Args)]
struct DrawingArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// An orthographic view of the whole scene instead of the camera: front (from +z),
    /// back, top (from +y), bottom, right (from +x), left or iso.
    #[arg(long, value_name = "NAME", conflicts_with_all = ["eye", "target", "up", "fov", "near", "far", "camera"])]
    view: Option<String>,
    /// Draw to scale 1:N on a page in millimetres (orthographic views: --view, or a scene
    /// file's orthographic camera); without it the page is in pixels of --size.
    #[arg(long, value_name = "1:N")]
    scale: Option<String>,
    /// The world's unit for --scale: mm, cm, m or in.
    #[arg(long, default_value = "mm", value_name = "UNIT")]
    unit: String,
    /// Output file: .svg, .pdf or .dxf.
    #[arg(short, long, default_value = "drawing.svg")]
    output: PathBuf,
    /// Print where the time went and how large the drawing is.
    #[arg(long)]
    timings: bool,
}

/// The N of a scale given as `1:N` (or `N`).
fn parse_scale(s: &str) -> Result<f64> {
    let n = s.strip_prefix("1:").unwrap_or(s);
    match n.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(wirepass::Error::InvalidSetting(format!(
            "--scale {s:?} is not 1:N with N a number > 0"
        ))),
    }
}

fn drawing_command(args: &DrawingArgs) -> Result<()> {
    use wirepass::drawing::{Drawing, Page};
    let start = Instant::now();
    // Checked before the scene is read, so a typo costs nothing.
    let scale = args.scale.as_deref().map(parse_scale).transpose()?;
    let unit_mm = match args.unit.as_str() {
        "mm" => 1.0,
        "cm" => 10.0,
        "m" => 1000.0,
        "in" => 25.4,
        other => {
            return Err(wirepass::Error::InvalidSetting(format!(
                "--unit {other:?} is not mm, cm, m or in"
            )))
        }
    };
    let ext = args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("svg" | "pdf" | "dxf")) {
        return Err(wirepass::Error::InvalidSetting(format!(
            "-o {}: a drawing is written as .svg, .pdf or .dxf",
            args.output.display()
        )));
    }
    let (world, view, style, size) = args.scene.load()?;
    let view = match &args.view {
        Some(name) => wirepass::tools::load::named_view(&world, name, size)?,
        None => view,
    };
    let read = start.elapsed();
    let shot = Shot {
        world: &world,
        view,
        style: &style,
        size,
    };
    let drawing = Drawing::new(&shot)?;
    let page = match scale {
        Some(n) => Page::to_scale(&view, size, unit_mm, n)?,
        None => Page::pixels(),
    };
    let write = Instant::now();
    drawing.write(&args.output, &page)?;
    let write = write.elapsed();
    let bytes = std::fs::metadata(&args.output).map_or(0, |m| m.len());
    let points: usize = drawing.paths.iter().map(|p| p.points.len()).sum();
    if args.timings {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        eprintln!("read the scene       {:9.1} ms", ms(read));
        eprintln!(
            "occluders            {:9.1} ms",
            ms(drawing.timings.occluders)
        );
        eprintln!("lines and visibility {:9.1} ms", ms(drawing.timings.lines));
        eprintln!("write the file       {:9.1} ms", ms(write));
        eprintln!("total                {:9.1} ms", ms(start.elapsed()));
    }
    eprintln!(
        "wrote {} ({} paths, {} points, {} bytes; {} objects, {} triangles)",
        args.output.display(),
        drawing.paths.len(),
        points,
        bytes,
        world.objects.len(),
        world.triangle_count()
    );
    Ok(())
}

#[derive(clap::Args)]
struct CompareArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Directory for the images, error maps, sheet.png and report.json.
    #[arg(long)]
    out: PathBuf,
}

fn compare_command(args: &CompareArgs) -> Result<()> {
    let (world, view, style, size) = args.scene.load()?;
    let ctx = GpuContext::new()?;
    let shot = Shot {
        world: &world,
        view,
        style: &style,
        size,
    };
    let report = wirepass::tools::compare::run(&ctx, &shot, &args.out)?;
    println!(
        "{}x{}, {} triangles, {}; ground truth (raycast) {:.2} s",
        size.0,
        size.1,
        world.triangle_count(),
        ctx.describe(),
        report.reference_seconds
    );
    println!("{}", wirepass::tools::compare::table(&report));
    eprintln!("wrote {}", args.out.join("report.json").display());
    Ok(())
}

#[derive(clap::Args)]
struct BenchArgs {
    /// Scenes: scene files, glTF or GLB files, OBJ, STL or PLY files, or procedural meshes
    /// (`sphere:20000 sphere:2M`); default: the built-in scene. Each is framed by the
    /// automatic camera.
    scenes: Vec<String>,
    /// Which edges to draw (all, polygon, authored, feature[:DEGREES]) [default: authored
    /// where the file has them, else polygon].
    #[arg(long, value_parser = parse_edges)]
    edges: Option<EdgeSelection>,
    /// Line width in pixels [default: 1.5, or the glTF file's own widths].
    #[arg(long)]
    line_width: Option<f32>,
    /// Image sizes, comma separated: 1280x720,1920x1080.
    #[arg(long, default_value = "1280x720")]
    size: String,
    /// Timed frames per scene, size and method (after warm-up frames).
    #[arg(long, default_value_t = 20)]
    frames: u32,
    /// Untimed frames first.
    #[arg(long, default_value_t = 3)]
    warmup: u32,
    /// Directory for bench.json, bench.csv and the plots.
    #[arg(long)]
    out: PathBuf,
    /// Time the deferred method with its trace pass (on), without (off, the same lines
    /// the forward baselines draw), or both (`on,off`); the methods that draw no outline
    /// (forward, two-pass, gs) are timed with the first setting only.
    #[arg(long, alias = "silhouettes", default_value = "on", value_delimiter = ',', value_parser = parse_switch)]
    outlines: Vec<bool>,
    /// Also time the deferred method drawing these edge selections, comma separated
    /// (`polygon,feature:30`), each on its own upload, beside --edges in the same run.
    #[arg(long, value_delimiter = ',', value_parser = parse_edges)]
    compare_edges: Vec<EdgeSelection>,
    /// Time only these methods, comma separated: floor, deferred, render-pass, forward,
    /// two-pass, gs [default: all of them].
    #[arg(long, value_delimiter = ',', value_parser = parse_timed)]
    methods: Vec<Timed>,
    /// Hidden lines for the deferred method (off, solid, dashed[:DASH,GAP],
    /// dotted[:SPACING]); the other methods draw none.
    #[arg(long, default_value = "off", value_name = "STYLE")]
    hidden: String,
    /// Pattern of the visible drawn edges for the deferred method (solid,
    /// dashed[:DASH,GAP], dotted[:SPACING]); the other methods draw them solid.
    #[arg(long, default_value = "solid", value_name = "PATTERN")]
    edge_pattern: String,
    /// Print this run's ratios (deferred ÷ gs, edge ÷ floor, …) against a baseline of
    /// record (bench/baseline.json), flagging those that worsened by more than 15 %.
    #[arg(long, value_name = "BASELINE")]
    against: Option<PathBuf>,
    /// Write this run's ratios as a baseline of record to this file, marked with --commit
    /// and --date (bench/tables.sh does).
    #[arg(long, value_name = "BASELINE", requires_all = ["commit", "date"])]
    record: Option<PathBuf>,
    /// The commit a recorded baseline was measured at.
    #[arg(long)]
    commit: Option<String>,
    /// The day a recorded baseline was measured.
    #[arg(long)]
    date: Option<String>,
}

fn parse_timed(s: &str) -> std::result::Result<Timed, String> {
    s.parse().map_err(|e: wirepass::Error| e.to_string())
}

fn bench_command(args: &BenchArgs) -> Result<()> {
    // The baseline is read before the run, so that a bad path fails at once.
    let baseline = args
        .against
        .as_deref()
        .map(wirepass::tools::bench::Baseline::read)
        .transpose()?;
    let sizes = args
        .size
        .split(',')
        .map(parse_size)
        .collect::<Result<Vec<_>>>()?;
    let specs: Vec<Option<&str>> = if args.scenes.is_empty() {
        vec![None]
    } else {
        args.scenes.iter().map(|s| Some(s.as_str())).collect()
    };
    let ctx = GpuContext::new()?;
    let settings = specs.len() * sizes.len() * args.outlines.len();
    let progress = indicatif::ProgressBar::new(settings as u64);
    if !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        progress.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let mut runs = Vec::new();
    for spec in specs {
        let name = spec.unwrap_or("built-in");
        progress.set_message(format!("loading {name}"));
        let options = WorldOptions {
            edges: args.edges,
            camera: None,
            line_width: args.line_width,
        };
        let loaded = load_world(spec, &options)?;
        print_notes(&loaded.notes);
        let (world, selected) = (loaded.world, loaded.highlight);
        for &size in &sizes {
            for (k, &outlines) in args.outlines.iter().enumerate() {
                let switch = if outlines { "on" } else { "off" };
                progress.set_message(format!(
                    "{name} at {}x{}, outlines {switch}",
                    size.0, size.1
                ));
                let style = Style {
                    outlines,
                    line_width: args.line_width.unwrap_or(DEFAULT_LINE_WIDTH),
                    hidden: LinePattern::parse(&args.hidden)?.map(|pattern| HiddenLines {
                        pattern,
                        ..HiddenLines::default()
                    }),
                    edge_pattern: LinePattern::parse_visible(&args.edge_pattern)?,
                    ..Style::default()
                };
                style.validate()?;
                let world = highlighted(world.clone(), &selected, &style)?;
                // Only the deferred methods draw outlines: the others once.
                let mut methods = args.methods.clone();
                if k > 0 {
                    if methods.is_empty() {
                        methods = Timed::ALL.to_vec();
                    }
                    methods.retain(|m| m.draws_outlines());
                    if methods.is_empty() {
                        progress.inc(1);
                        continue;
                    }
                }
                let timing = wirepass::tools::bench::Timing {
                    frames: args.frames,
                    warmup: args.warmup,
                    edges: args.compare_edges.clone(),
                    methods,
                };
                runs.extend(wirepass::tools::bench::bench(
                    &ctx, name, &world, size, &style, timing,
                )?);
                progress.inc(1);
            }
        }
    }
    progress.finish_and_clear();
    let device = wirepass::tools::bench::DeviceInfo::of(&ctx);
    if args.edge_pattern != "solid" {
        println!("Edges: {} (deferred only).\n", args.edge_pattern);
    }
    if args.hidden != "off" {
        println!("Hidden lines: {} (deferred only).\n", args.hidden);
    }
    print!(
        "{}",
        wirepass::tools::bench::report_markdown(&device, &runs)
    );
    wirepass::tools::bench::write_outputs(&args.out, &device, &runs)?;
    let ratios = wirepass::tools::bench::ratios(&runs);
    if let Some(baseline) = &baseline {
        let (table, _) = wirepass::tools::bench::against(baseline, &ratios);
        println!("\n{table}");
    }
    if let (Some(path), Some(commit), Some(date)) = (&args.record, &args.commit, &args.date) {
        // The OpenGL renderer gs ran on, without how it was timed.
        let gl = runs.iter().find_map(|r| r.gl.as_deref());
        let adapter = match gl.and_then(|gl| gl.split("; timed by").next()) {
            Some(gl) => format!("{}; gs on {gl}", device.describe()),
            None => device.describe(),
        };
        let record = wirepass::tools::bench::Baseline {
            adapter,
            commit: commit.clone(),
            date: date.clone(),
            ratios,
        };
        record.write(path)?;
    }
    eprintln!("wrote {}", args.out.display());
    Ok(())
}

#[derive(clap::Args)]
struct DiffArgs {
    /// Reference image (PNG).
    a: PathBuf,
    /// Image to test against it (PNG).
    b: PathBuf,
    /// Largest accepted mean FLIP error (0..1).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.001)]
    threshold_mean: f32,
    /// Largest accepted 99th-percentile FLIP error (0..1).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.05)]
    threshold_p99: f32,
    /// Write the FLIP heat map (magma: black = same) to this PNG.
    #[arg(long)]
    out: Option<PathBuf>,
}

fn diff_command(args: &DiffArgs) -> Result<()> {
    use wirepass::tools::regression::{difference, heat_map, load_rgba, Rgba, Threshold};
    let (a, a_size) = load_rgba(&args.a)?;
    let (b, b_size) = load_rgba(&args.b)?;
    let (a, b) = (Rgba::new(&a, a_size)?, Rgba::new(&b, b_size)?);
    let diff = difference(a, b).map_err(|e| {
        wirepass::Error::InvalidSetting(format!(
            "{} and {}: {e}",
            args.a.display(),
            args.b.display()
        ))
    })?;
    println!(
        "mean {:.6} p99 {:.6} max {:.6}",
        diff.mean, diff.p99, diff.max
    );
    if let Some(out) = &args.out {
        heat_map(a, b, out)?;
        eprintln!("wrote {}", out.display());
    }
    let threshold = Threshold {
        mean: args.threshold_mean,
        p99: args.threshold_p99,
    };
    if let Some(why) = diff.exceeds(&threshold) {
        eprintln!("wirepass: images differ beyond the threshold: {why}");
        std::process::exit(1);
    }
    Ok(())
}

fn main() -> ExitCode {
    // Mesa's Vulkan device-selection layer connects to the Wayland and X servers to find the
    // display's GPU, and libwayland prints an error on a machine without one; every command
    // here draws offscreen and ranks the adapters itself, so it asks the loader to leave the
    // layer out (unless the caller says otherwise). Set before any thread starts.
    if std::env::var_os("NODEVICE_SELECT").is_none() {
        std::env::set_var("NODEVICE_SELECT", "1");
    }
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Render(args) => render_command(args),
        Command::Compare(args) => compare_command(args),
        Command::Bench(args) => bench_command(args),
        Command::Diff(args) => diff_command(args),
        Command::Pick(args) => pick_command(args),
        Command::Drawing(args) => drawing_command(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("wirepass: error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Camera options as given on the command line; unset ones come from the automatic framing.
#[derive(Clone, Debug, Default, clap::Args)]
struct CameraArgs {
    /// Eye position x,y,z; without it the camera frames the mesh automatically.
    #[arg(long, value_parser = parse_vec3_arg, allow_hyphen_values = true)]
    eye: Option<Vec3>,
    /// Point looked at, x,y,z (default: centre of the mesh bounds).
    #[arg(long, value_parser = parse_vec3_arg, allow_hyphen_values = true)]
    target: Option<Vec3>,
    /// Up direction x,y,z (default 0,1,0).
    #[arg(long, value_parser = parse_vec3_arg, allow_hyphen_values = true)]
    up: Option<Vec3>,
    /// Vertical field of view in degrees (default 40).
    #[arg(long, allow_hyphen_values = true)]
    fov: Option<f32>,
    /// Near plane distance.
    #[arg(long, allow_hyphen_values = true)]
    near: Option<f32>,
    /// Far plane distance.
    #[arg(long, allow_hyphen_values = true)]
    far: Option<f32>,
    /// Use the file's N-th camera (a glTF file's, counting from 0 in node order); without
    /// it and the options above, the file's first camera, if it has one.
    #[arg(long, value_name = "N", conflicts_with_all = ["eye", "target", "up", "fov", "near", "far"])]
    camera: Option<usize>,
}

fn parse_vec3_arg(s: &str) -> std::result::Result<Vec3, String> {
    parse_vec3(s).map_err(|e| e.to_string())
}

impl CameraArgs {
    /// The placement these options give.
    fn placement(&self) -> CameraPlacement {
        CameraPlacement {
            eye: self.eye,
            target: self.target,
            up: self.up,
            fov: self.fov,
            near: self.near,
            far: self.far,
            camera: self.camera,
        }
    }
}
