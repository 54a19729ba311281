//! `wirepass`: render mesh wireframes on the GPU from the command line.

use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;
use wirepass::cli::{load_mesh, parse_size, CameraArgs};
use wirepass::gpu::GpuContext;
use wirepass::render::{render, Method, Scene};
use wirepass::{Color, EdgeSelection, Result, Style};

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
    /// Render a mesh (an OBJ file, `sphere:N`, `grid:N`, `torus:N`, or the built-in scene).
    Render(RenderArgs),
    /// Render one scene with the CPU ray-cast ground truth and every GPU method, and report
    /// how closely each matches it (images, error maps, sheet.png, report.json).
    Compare(CompareArgs),
}

#[derive(Clone, Copy, ValueEnum)]
enum Edges {
    /// Every triangle edge.
    All,
    /// Only the edges of the file's polygons (no triangulation diagonals).
    Polygon,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// OBJ file or procedural mesh (`sphere:20000`, `grid:1k`, `torus:5000`); default: built-in scene.
    mesh: Option<String>,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "800x600")]
    size: String,
    /// Line width in pixels.
    #[arg(long, default_value_t = 1.5, allow_hyphen_values = true)]
    line_width: f32,
    /// Line colour, #rrggbb[aa] (sRGB).
    #[arg(long, default_value = "#0a0f19")]
    wire_color: String,
    /// Surface colour, #rrggbb (sRGB).
    #[arg(long, default_value = "#c2cfdf")]
    fill_color: String,
    /// Background colour, #rrggbb (sRGB).
    #[arg(long, default_value = "#ffffff")]
    background: String,
    /// How to draw: deferred (visibility buffer + compute edge pass), forward (single-pass
    /// altitudes, Bærentzen et al. 2006; divides by w like the seeds), two-pass (biased fill,
    /// then 1 px edge lines), raycast (the f64 CPU ground truth; slow).
    #[arg(long, default_value = "deferred", value_parser = parse_method)]
    method: Method,
    /// Which edges to draw.
    #[arg(long, value_enum, default_value = "polygon")]
    edges: Edges,
    /// Output PNG.
    #[arg(short, long, default_value = "wireframe.png")]
    output: PathBuf,
    /// Also write ids.npy, depth.npy, edge_distance.npy and camera.json into this directory.
    #[arg(long)]
    dump: Option<PathBuf>,
    #[command(flatten)]
    camera: CameraArgs,
}

fn parse_method(s: &str) -> std::result::Result<Method, String> {
    s.parse().map_err(|e: wirepass::Error| e.to_string())
}

fn render_command(args: &RenderArgs) -> Result<()> {
    let size = parse_size(&args.size)?;
    let style = Style {
        line_width: args.line_width,
        wire_color: Color::from_hex(&args.wire_color)?,
        fill_color: Color::from_hex(&args.fill_color)?,
        background: Color::from_hex(&args.background)?,
        ..Style::default()
    };
    style.validate()?;
    let mesh = load_mesh(args.mesh.as_deref())?;
    let camera = args.camera.camera(&mesh, size)?;
    let ctx = GpuContext::new()?;
    let edges = match args.edges {
        Edges::All => EdgeSelection::All,
        Edges::Polygon => EdgeSelection::Polygon,
    };
    let scene = Scene {
        mesh: &mesh,
        camera,
        style,
        size,
        edges,
    };
    let frame = render(&ctx, &scene, args.method)?;
    frame.save_png(&args.output)?;
    if let Some(dir) = &args.dump {
        frame.dump(dir, &camera)?;
    }
    eprintln!(
        "wrote {} ({}, {}x{}, {} triangles, {})",
        args.output.display(),
        args.method.name(),
        size.0,
        size.1,
        mesh.triangle_count(),
        ctx.describe()
    );
    Ok(())
}

#[derive(clap::Args)]
struct CompareArgs {
    /// OBJ file or procedural mesh (`sphere:20000`, `grid:1k`, `torus:5000`); default: built-in scene.
    mesh: Option<String>,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "640x480")]
    size: String,
    /// Line width in pixels.
    #[arg(long, default_value_t = 1.5, allow_hyphen_values = true)]
    line_width: f32,
    /// Which edges to draw.
    #[arg(long, value_enum, default_value = "polygon")]
    edges: Edges,
    /// Directory for the images, error maps, sheet.png and report.json.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    camera: CameraArgs,
}

fn compare_command(args: &CompareArgs) -> Result<()> {
    let size = parse_size(&args.size)?;
    let style = Style {
        line_width: args.line_width,
        ..Style::default()
    };
    style.validate()?;
    let mesh = load_mesh(args.mesh.as_deref())?;
    let camera = args.camera.camera(&mesh, size)?;
    let ctx = GpuContext::new()?;
    let edges = match args.edges {
        Edges::All => EdgeSelection::All,
        Edges::Polygon => EdgeSelection::Polygon,
    };
    let scene = Scene {
        mesh: &mesh,
        camera,
        style,
        size,
        edges,
    };
    let report = wirepass::compare::run(&ctx, &scene, &args.out)?;
    println!(
        "{}x{}, {} triangles, {}; ground truth (raycast) {:.2} s",
        size.0,
        size.1,
        mesh.triangle_count(),
        ctx.describe(),
        report.reference_seconds
    );
    println!("{}", wirepass::compare::table(&report));
    eprintln!("wrote {}", args.out.join("report.json").display());
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Render(args) => render_command(args),
        Command::Compare(args) => compare_command(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("wirepass: error: {e}");
            ExitCode::FAILURE
        }
    }
}
