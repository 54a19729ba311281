//! The pass's work, held to a recorded table: on fixed scenes, what the trace pass and the
//! edge pass's later dispatches take on (tiles, refined pixels, listed clusters, lines and
//! pieces, overflowed clusters) and the pipelines the frame builds are deterministic, so a
//! change that makes the pass do more shows here, on any machine, where a time would not.
//!
//! The table is `tests/data/work.txt`. A number more than 10 % above its record fails, and
//! so does one more than 10 % below (record the gain, so that it is kept); a change that
//! moves one updates the table in the same commit, with the reason in its message:
//!
//! ```sh
//! WIREPASS_RECORD_WORK=1 cargo test --test work
//! ```

mod common;

use common::{frame_work, gpu, load, spot_beside_suzanne, SIDE_BY_SIDE, THROUGH};
use glam::DVec3;
use wirepass::gpu::{DeferredPass, EdgeWork, PassOptions, Tuning};
use wirepass::tools::offline::Uploaded;
use wirepass::world::World;
use wirepass::{Camera, EdgeSelection, HiddenLines, SectionPlane, Style};

const TABLE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/work.txt");

/// The counters, in the table's column order.
const COLUMNS: [&str; 9] = [
    "tiles",
    "traced",
    "refined",
    "clusters",
    "lines",
    "pieces",
    "overflowed",
    "chained",
    "pipelines",
];

/// A fixed scene: a world framed at a size, drawn in a style, maybe cut by a plane through
/// its centre.
struct Case {
    name: &'static str,
    world: World,
    size: (u32, u32),
    style: Style,
    section: bool,
}

fn cases() -> Vec<Case> {
    let sphere = |n| wirepass::mesh::sphere(n).unwrap();
    let hidden = Style {
        hidden: Some(HiddenLines::default()),
        ..Style::default()
    };
    let crossing = Style {
        intersection_lines: true,
        ..Style::default()
    };
    let case = |name, mesh, edges, size, style, section| Case {
        name,
        world: World::single(mesh, edges),
        size,
        style,
        section,
    };
    let wide = (1280, 720);
    let small = (640, 480);
    let feature = EdgeSelection::Feature(30.0);
    vec![
        case(
            "sphere-20k",
            sphere(20_000),
            EdgeSelection::Polygon,
            wide,
            Style::default(),
            false,
        ),
        case(
            "sphere-2m",
            sphere(2_000_000),
            EdgeSelection::Polygon,
            wide,
            Style::default(),
            false,
        ),
        case(
            "bunny",
            load("stanford-bunny.obj"),
            EdgeSelection::Polygon,
            wide,
            Style::default(),
            false,
        ),
        case(
            "fandisk-hidden",
            load("fandisk.obj"),
            feature,
            small,
            hidden,
            false,
        ),
        case(
            "fandisk-section",
            load("fandisk.obj"),
            feature,
            small,
            Style::default(),
            true,
        ),
        case(
            "suzanne-crossings",
            load("suzanne.obj"),
            EdgeSelection::Polygon,
            small,
            crossing,
            false,
        ),
        // Instances whose bounds meet but whose surfaces do not cross are drawn as any two
        // are; those that pass through each other draw every edge where it is visible.
        Case {
            name: "instances-apart",
            world: spot_beside_suzanne(SIDE_BY_SIDE),
            size: small,
            style: Style::default(),
            section: false,
        },
        Case {
            name: "instances-crossed",
            world: spot_beside_suzanne(THROUGH),
            size: small,
            style: Style::default(),
            section: false,
        },
    ]
}

/// The counters of one frame of `case`, drawn by a new pass split for a software
/// rasterizer (so that a GPU counts the same pieces), into a storage texture.
fn measure(case: &Case) -> [u64; 9] {
    let ctx = gpu();
    let (device, queue) = (&ctx.device, &ctx.queue);
    let world = &case.world;
    let up = Uploaded::new(device, queue, world).unwrap();
    let aspect = f64::from(case.size.0) / f64::from(case.size.1);
    let (lo, hi) = world.bounds();
    let view = Camera::framing(lo, hi, aspect).to_view(aspect);
    let mut scene = up.scene(world, view);
    if case.section {
        let plane = SectionPlane::new((lo + hi) / 2.0, DVec3::new(0.3, -1.0, 0.2));
        scene = scene.with_sections(vec![plane]);
    }
    let options = PassOptions {
        tuning: Tuning::Software,
        ..PassOptions::default()
    };
    let mut pass = DeferredPass::new(device, options).unwrap();
    let EdgeWork {
        tiles,
        traced_tiles,
        refined,
        traced_clusters,
        outline_lines,
        traced_pieces,
        overflowed,
        chained_outlines,
        ..
    } = frame_work(&mut pass, &up.store, &scene, &case.style, case.size);
    ctx.finish().unwrap();
    [
        tiles,
        traced_tiles,
        refined,
        traced_clusters,
        outline_lines,
        traced_pieces,
        overflowed,
        chained_outlines,
        pass.pipelines_built() as u32,
    ]
    .map(u64::from)
}

/// The recorded table: each scene's name and counters.
fn recorded() -> Vec<(String, [u64; 9])> {
    let text = std::fs::read_to_string(TABLE).unwrap_or_default();
    text.lines()
        .filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let mut words = l.split_whitespace();
            let name = words.next().unwrap().to_owned();
            let numbers: Vec<u64> = words.map(|w| w.parse().unwrap()).collect();
            let row: [u64; 9] = numbers
                .try_into()
                .unwrap_or_else(|n| panic!("{TABLE}: {name} has {n:?}, not 9 numbers"));
            (name, row)
        })
        .collect()
}

fn write_table(rows: &[(&str, [u64; 9])]) {
    let mut text = String::from(
        "# The pass's work on fixed scenes (tests/work.rs): lavapipe or llvmpipe, Tuning::Software.\n\
         # A number more than 10 % off its record fails tests/work.rs until this table is\n\
         # updated in the same commit, with the reason in its message:\n\
         #   WIREPASS_RECORD_WORK=1 cargo test --test work\n\
         # tiles: 8x8 output tiles with foreground; traced: tiles the trace pass's lines\n\
         # reach; refined: pixels the refine dispatch decides; clusters: clusters the trace\n\
         # cull lists; lines: lines it lists pieces of; pieces: pieces it lists; overflowed:\n\
         # clusters the piece list had no room for; chained: outline edges the outline\n\
         # chains were found for; pipelines: pipelines the frame built.\n",
    );
    text += &format!("# {:<20}", "scene");
    for c in COLUMNS {
        text += &format!(" {c:>10}");
    }
    text += "\n";
    for (name, row) in rows {
        text += &format!("{name:<22}");
        for v in row {
            text += &format!(" {v:>10}");
        }
        text += "\n";
    }
    std::fs::write(TABLE, text).unwrap();
}

#[test]
fn the_pass_does_the_recorded_work() {
    let cases = cases();
    let measured: Vec<(&str, [u64; 9])> = cases.iter().map(|c| (c.name, measure(c))).collect();
    for (name, row) in &measured {
        println!("{name}: {row:?}");
    }
    if std::env::var_os("WIREPASS_RECORD_WORK").is_some() {
        write_table(&measured);
        return;
    }
    let table = recorded();
    let mut off = Vec::new();
    for (name, row) in &measured {
        let Some((_, record)) = table.iter().find(|(n, _)| n == name) else {
            off.push(format!("{name}: not in the table"));
            continue;
        };
        for ((column, &now), &then) in COLUMNS.iter().zip(row).zip(record) {
            // Small counts move by a few on a change of rounding: 10 % or 2, whichever is
            // more.
            let slack = (then / 10).max(2);
            if now > then + slack || now + slack < then {
                off.push(format!("{name} {column}: {then} recorded, {now} now"));
            }
        }
    }
    assert!(
        off.is_empty(),
        "the pass's work moved by more than 10 % (record it with WIREPASS_RECORD_WORK=1 \
         cargo test --test work, and say why in the commit):\n  {}",
        off.join("\n  ")
    );
}
