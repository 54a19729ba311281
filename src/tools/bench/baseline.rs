//! A run's ratios (deferred ÷ gs, edge ÷ floor, …) and the baseline of record they are
//! compared against.

use super::run::{same_shot, switch, Run};
use crate::error::{Error, Result};

/// One ratio of a benchmark run, the unit the baseline keeps (`bench/baseline.json`): the
/// scene and size it was measured on, what it divides by what, and whether the deferred
/// method drew outlines. Every ratio is one where lower is better.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Ratio {
    /// Scene name as given.
    pub scene: String,
    /// Image size, `WxH`.
    pub size: String,
    /// What is divided by what: `deferred ÷ gs`, `deferred ÷ forward`, `edge ÷ floor`,
    /// `render-pass ÷ deferred`, `edge ÷ edge at SCENE` (the edge pass against its time on the
    /// scene of fewest triangles of the same procedural kind and size: flat in triangles is
    /// 1).
    pub ratio: String,
    /// `on` or `off`.
    pub outlines: String,
    /// The ratio.
    pub value: f64,
}

/// The kind of a procedural scene (`sphere` of `sphere:20000`), none for a file.
fn family(r: &Run) -> Option<&str> {
    let (kind, _) = r.scene.split_once(':')?;
    (!r.scene.contains(['/', '\\', '.'])).then_some(kind)
}

/// The ratios of a run, each measured within it (the methods interleaved frame by frame).
pub fn ratios(runs: &[Run]) -> Vec<Ratio> {
    let timed = |r: &&Run| r.skipped.is_none() && r.total_median_ms > 0.0;
    let find = |shot: &Run, method: &str, outlines: Option<bool>| {
        runs.iter().filter(timed).find(|r| {
            same_shot(r, shot) && r.method == method && outlines.is_none_or(|o| r.outlines == o)
        })
    };
    let edge = |r: &Run| r.passes.get("edge").map(|s| s.median_ms);
    let mut out = Vec::new();
    let mut push = |r: &Run, ratio: String, value: Option<f64>| {
        if let Some(value) = value.filter(|v| v.is_finite()) {
            out.push(Ratio {
                scene: r.scene.clone(),
                size: format!("{}x{}", r.size[0], r.size[1]),
                ratio,
                outlines: switch(r.outlines).to_owned(),
                value,
            });
        }
    };
    for d in runs.iter().filter(timed).filter(|r| r.method == "deferred") {
        let total = |r: Option<&Run>| r.map(|r| r.total_median_ms);
        for other in ["gs", "forward"] {
            push(
                d,
                format!("deferred ÷ {other}"),
                total(find(d, other, None)).map(|t| d.total_median_ms / t),
            );
        }
        let floor = find(d, "floor", Some(d.outlines)).or_else(|| find(d, "floor", None));
        push(
            d,
            "edge ÷ floor".into(),
            floor.and_then(|f| Some(edge(d)? / edge(f)?)),
        );
        let host = total(find(d, "render-pass", Some(d.outlines)));
        push(
            d,
            "render-pass ÷ deferred".into(),
            host.map(|h| h / d.total_median_ms),
        );
        // The edge pass against the scene of fewest triangles of the same family (the
        // procedural meshes of one kind, `sphere:N`) and size.
        let fewest = runs
            .iter()
            .filter(timed)
            .filter(|r| r.method == "deferred" && r.size == d.size && r.outlines == d.outlines)
            .filter(|r| family(r).is_some() && family(r) == family(d))
            .min_by_key(|r| r.triangles);
        if let Some(f) = fewest.filter(|f| f.scene != d.scene) {
            let name = format!("edge ÷ edge at {}", f.scene);
            push(d, name, edge(d).zip(edge(f)).map(|(a, b)| a / b));
        }
    }
    out
}

/// A table of a run's ratios, one row per scene, size and setting.
pub fn ratios_markdown(ratios: &[Ratio]) -> String {
    let mut names: Vec<&str> = Vec::new();
    for r in ratios {
        if !names.contains(&r.ratio.as_str()) {
            names.push(&r.ratio);
        }
    }
    let mut out = String::from("| scene | size | outlines |");
    for n in &names {
        out += &format!(" {n} |");
    }
    out += "\n|---|---|---|";
    out += &"---:|".repeat(names.len());
    out += "\n";
    let mut rows: Vec<(&str, &str, &str)> = Vec::new();
    for r in ratios {
        let key = (r.scene.as_str(), r.size.as_str(), r.outlines.as_str());
        if !rows.contains(&key) {
            rows.push(key);
        }
    }
    for (scene, size, outlines) in rows {
        out += &format!("| {scene} | {size} | {outlines} |");
        for n in &names {
            let value = ratios.iter().find(|r| {
                r.scene == scene && r.size == size && r.outlines == outlines && r.ratio == *n
            });
            out += &value.map_or(" – |".to_owned(), |r| format!(" {:.2} |", r.value));
        }
        out += "\n";
    }
    out
}

/// The baseline of record: the ratios of a run, with where and when they were measured.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Baseline {
    /// The adapter the wgpu methods ran on, and the OpenGL renderer gs ran on.
    pub adapter: String,
    /// The commit measured.
    pub commit: String,
    /// The day it was measured.
    pub date: String,
    /// The ratios.
    pub ratios: Vec<Ratio>,
}

impl Baseline {
    /// Reads a baseline, with a clear error for a file that is not one.
    pub fn read(path: &std::path::Path) -> Result<Baseline> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_owned(),
            source,
        })?;
        serde_json::from_str(&text).map_err(|e| {
            Error::InvalidSetting(format!("{}: not a bench baseline: {e}", path.display()))
        })
    }

    /// Writes the baseline as JSON.
    pub fn write(&self, path: &std::path::Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| Error::InvalidSetting(format!("{}: {e}", path.display())))?;
        std::fs::write(path, text + "\n").map_err(|source| Error::Io {
            path: path.to_owned(),
            source,
        })
    }
}

/// How much worse than its baseline a ratio may get before `--against` flags it.
pub const WORSE: f64 = 1.15;

/// A table of this run's ratios against `baseline`'s (those measured on the same scene, size
/// and setting), each flagged where it worsened by more than [`WORSE`]; and how many were.
pub fn against(baseline: &Baseline, now: &[Ratio]) -> (String, usize) {
    let mut out = format!(
        "Against the baseline ({}, {}, {}):\n\n\
         | scene | size | outlines | ratio | baseline | now | change | |\n\
         |---|---|---|---|---:|---:|---:|---|\n",
        baseline.adapter, baseline.commit, baseline.date
    );
    let mut worse = 0;
    let mut compared = 0;
    for r in now {
        let Some(b) = baseline.ratios.iter().find(|b| {
            b.scene == r.scene && b.size == r.size && b.ratio == r.ratio && b.outlines == r.outlines
        }) else {
            continue;
        };
        compared += 1;
        let change = r.value / b.value;
        let flag = if change > WORSE {
            worse += 1;
            "worse"
        } else {
            ""
        };
        out += &format!(
            "| {} | {} | {} | {} | {:.2} | {:.2} | {:+.0} % | {flag} |\n",
            r.scene,
            r.size,
            r.outlines,
            r.ratio,
            b.value,
            r.value,
            100.0 * (change - 1.0)
        );
    }
    if compared == 0 {
        out += "| – | – | – | no ratio of this run is in the baseline | | | | |\n";
    }
    out += &format!(
        "\n{compared} ratios compared, {worse} worse by more than {:.0} %.\n",
        100.0 * (WORSE - 1.0)
    );
    (out, worse)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ratio more than 15 % above its baseline is flagged; one within it, or better, is
    /// not; ratios of other scenes or settings are not compared.
    #[test]
    fn against_flags_ratios_that_worsened() {
        let ratio = |scene: &str, outlines: &str, value| Ratio {
            scene: scene.into(),
            size: "1280x720".into(),
            ratio: "deferred ÷ gs".into(),
            outlines: outlines.into(),
            value,
        };
        let baseline = Baseline {
            adapter: "lavapipe".into(),
            commit: "abc1234".into(),
            date: "2026-12-06".into(),
            ratios: vec![
                ratio("a", "on", 0.6),
                ratio("a", "off", 0.5),
                ratio("b", "on", 1.0),
            ],
        };
        let now = [
            ratio("a", "on", 0.7),
            ratio("a", "off", 0.55),
            ratio("b", "on", 0.9),
            ratio("c", "on", 9.0),
        ];
        let (table, worse) = against(&baseline, &now);
        assert_eq!(worse, 1, "{table}");
        assert!(table.contains("3 ratios compared, 1 worse"), "{table}");
        assert!(
            table.contains("| a | 1280x720 | on | deferred ÷ gs | 0.60 | 0.70 | +17 % | worse |")
        );
        assert!(!table.contains("| c |"), "{table}");
    }
}
