//! The library's layers depend only downwards: a file of `src/` names (through `crate::`)
//! only modules of its own layer or of the layers below it. The layers, bottom up:
//!
//! 0. `error`
//! 1. `camera`, `style`, `mesh` (without its loaders)
//! 2. `edge_math`
//! 3. `mesh::formats`, the loaders
//! 4. `scene`: what a frame draws
//! 5. the pass: `gpu`
//! 6. `world`
//! 7. `truth`, the ray-cast ground truth; `drawing`, the vector drawings
//! 8. `tools`
//!
//! (`lib.rs` declares them all and is not checked.) And no two files of a layer name each
//! other, directly or round a longer circle: see `no_file_is_in_an_import_circle`.

use std::path::{Path, PathBuf};

/// The layer of a module path below `crate` (`["gpu", "deferred"]`), or `None` for one this
/// test does not know, which fails it: a new top-level module needs a place here.
fn layer(path: &[&str]) -> Option<u32> {
    Some(match path {
        ["error", ..] => 0,
        ["camera", ..] | ["style", ..] => 1,
        ["mesh", "formats", ..] => 3,
        ["mesh", ..] => 1,
        ["edge_math", ..] => 2,
        ["scene", ..] => 4,
        ["gpu", ..] => 5,
        ["world", ..] => 6,
        ["truth", ..] | ["drawing", ..] => 7,
        ["tools", ..] => 8,
        // The crate-level re-exports of the core types: `crate::Error`, `crate::Mesh`, ….
        [name, ..] if name.starts_with(char::is_uppercase) => 0,
        _ => return None,
    })
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The module path of a source file: `src/gpu/deferred.rs` → `["gpu", "deferred"]`.
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let mut parts: Vec<String> = file
        .strip_prefix(src)
        .unwrap()
        .with_extension("")
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
}

#[test]
fn every_file_names_only_its_own_layer_and_the_ones_below() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut checked = 0;
    let mut wrong = Vec::new();
    for file in &files {
        let module = module_of(&src, file);
        if module == ["lib"] {
            continue;
        }
        let names: Vec<&str> = module.iter().map(String::as_str).collect();
        let own =
            layer(&names).unwrap_or_else(|| panic!("{}: a module no layer holds", file.display()));
        let source = std::fs::read_to_string(file).unwrap();
        for path in named_paths(&source, &module) {
            let segments: Vec<&str> = path.iter().map(String::as_str).collect();
            let Some(theirs) = layer(&segments) else {
                wrong.push(format!(
                    "{}: {} is in no layer",
                    file.display(),
                    path.join("::")
                ));
                continue;
            };
            checked += 1;
            if theirs > own {
                wrong.push(format!(
                    "{} (layer {own}) names {} (layer {theirs})",
                    file.strip_prefix(&src).unwrap().display(),
                    path.join("::")
                ));
            }
        }
    }
    assert!(
        checked > 100,
        "only {checked} references found: is the scan broken?"
    );
    assert!(wrong.is_empty(), "upward references:\n{}", wrong.join("\n"));
}

/// The items a file declares (`pub`, `pub(crate)` or private: structs, enums, traits,
/// types, functions, constants and statics at any indentation).
fn declared_items(source: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in source.lines() {
        let mut t = line.trim_start();
        for prefix in ["pub(crate) ", "pub(super) ", "pub "] {
            t = t.strip_prefix(prefix).unwrap_or(t);
        }
        for keyword in [
            "struct ", "enum ", "trait ", "type ", "fn ", "const ", "static ",
        ] {
            if let Some(rest) = t.strip_prefix(keyword) {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() {
                    out.push(name);
                }
            }
        }
    }
    out
}

/// Every module path a file's code names, made absolute (below `crate`): `crate::a::b::C`,
/// `super::x::Y` and `self::z`, with `use` groups spread out, each as its segments.
fn named_paths(source: &str, module: &[String]) -> Vec<Vec<String>> {
    // `self` is the file's own module (a `mod.rs` is its folder's), `super` the one above.
    let this: Vec<String> = module.to_vec();
    let parent: Vec<String> = module[..module.len().saturating_sub(1)].to_vec();
    let mut out = Vec::new();
    for line in source.lines() {
        let code = line.split("//").next().unwrap_or("");
        for (prefix, base) in [
            ("crate::", Vec::new()),
            ("super::", parent.clone()),
            ("self::", this.clone()),
        ] {
            let mut rest = code;
            while let Some(at) = rest.find(prefix) {
                let preceded = rest[..at]
                    .chars()
                    .last()
                    .is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':');
                let after = &rest[at + prefix.len()..];
                rest = after;
                if preceded {
                    continue;
                }
                let raw: String = after
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                    .collect();
                let stem: Vec<String> = raw
                    .split("::")
                    .filter(|s| !s.is_empty())
                    .map(str::to_owned)
                    .collect();
                let group = after[raw.len()..].strip_prefix('{');
                let mut push = |tail: Vec<String>| {
                    let mut path = base.clone();
                    path.extend(stem.iter().cloned());
                    path.extend(tail);
                    // `super::*` at the top names the crate root, which is no module here.
                    if !path.is_empty() {
                        out.push(path);
                    }
                };
                match group {
                    Some(group) => {
                        for item in group.split('}').next().unwrap_or("").split(',') {
                            let tail: Vec<String> = item
                                .split(" as ")
                                .next()
                                .unwrap_or("")
                                .trim()
                                .split("::")
                                .filter(|s| !s.is_empty() && *s != "self" && *s != "*")
                                .map(str::to_owned)
                                .collect();
                            push(tail);
                        }
                    }
                    None => push(Vec::new()),
                }
            }
        }
    }
    out
}

/// The files of `src/` name one another only downwards: no file reaches itself through the
/// files it names. A path is taken to the file of its longest module prefix, and a name
/// through a folder's `mod.rs` (a re-export) to the file of that folder that declares it;
/// `mod.rs` files themselves only declare and re-export, so edges from them are left out.
#[test]
fn no_file_is_in_an_import_circle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let modules: Vec<Vec<String>> = files.iter().map(|f| module_of(&src, f)).collect();
    // The code a file builds into the library: its unit tests (a `#[cfg(test)]` module, at
    // the end) may name what they like.
    let sources: Vec<String> = files
        .iter()
        .map(|f| {
            let s = std::fs::read_to_string(f).unwrap();
            match s.find("#[cfg(test)]\nmod tests") {
                Some(at) => s[..at].to_owned(),
                None => s,
            }
        })
        .collect();
    let items: Vec<Vec<String>> = sources.iter().map(|s| declared_items(s)).collect();
    let is_hub = |i: usize| {
        files[i]
            .file_name()
            .is_some_and(|n| n == "mod.rs" || n == "lib.rs")
    };
    let index_of = |path: &[String]| modules.iter().position(|m| m.as_slice() == path);
    // The file a path names.
    let resolve = |path: &[String]| -> Option<usize> {
        let (len, file) = (0..=path.len())
            .rev()
            .find_map(|k| index_of(&path[..k]).map(|i| (k, i)))?;
        if !is_hub(file) || len == path.len() {
            return Some(file);
        }
        // A name re-exported by a folder's mod.rs: the one file of the folder declaring it.
        let name = &path[len];
        let folder = &modules[file];
        let declaring: Vec<usize> = (0..files.len())
            .filter(|&j| j != file && modules[j].starts_with(folder) && items[j].contains(name))
            .collect();
        match declaring.as_slice() {
            [one] => Some(*one),
            _ => Some(file),
        }
    };
    let lib = index_of(&["lib".to_owned()]);
    let mut edges: Vec<Vec<usize>> = vec![Vec::new(); files.len()];
    for i in 0..files.len() {
        if is_hub(i) {
            continue;
        }
        for path in named_paths(&sources[i], &modules[i]) {
            if let Some(j) = resolve(&path) {
                if j != i && Some(j) != lib && !edges[i].contains(&j) {
                    edges[i].push(j);
                }
            }
        }
    }
    let linked: usize = edges.iter().map(Vec::len).sum();
    assert!(
        linked > 150,
        "only {linked} links between files: is the scan broken?"
    );
    // Depth-first search for a back edge; the circle is the stack from its target.
    let name = |i: usize| files[i].strip_prefix(&src).unwrap().display().to_string();
    let mut state = vec![0u8; files.len()]; // 0 new, 1 on the stack, 2 done
    let mut circles = Vec::new();
    fn visit(
        i: usize,
        edges: &[Vec<usize>],
        state: &mut [u8],
        stack: &mut Vec<usize>,
        circles: &mut Vec<Vec<usize>>,
    ) {
        state[i] = 1;
        stack.push(i);
        for &j in &edges[i] {
            if state[j] == 1 {
                let from = stack.iter().position(|&k| k == j).unwrap();
                circles.push(stack[from..].to_vec());
            } else if state[j] == 0 {
                visit(j, edges, state, stack, circles);
            }
        }
        stack.pop();
        state[i] = 2;
    }
    for i in 0..files.len() {
        if state[i] == 0 {
            visit(i, &edges, &mut state, &mut Vec::new(), &mut circles);
        }
    }
    let described: Vec<String> = circles
        .iter()
        .map(|c| {
            let mut names: Vec<String> = c.iter().map(|&i| name(i)).collect();
            names.push(name(c[0]));
            names.join(" → ")
        })
        .collect();
    assert!(
        described.is_empty(),
        "import circles:\n{}",
        described.join("\n")
    );
}

#[test]
fn paths_are_made_absolute_and_groups_spread() {
    let module = ["gpu".to_owned(), "frame".to_owned()];
    let source = "use super::{canvas::Region, mesh_store::MeshStore as S};\n\
                  use crate::{error::Result, scene::Scene};\n\
                  // crate::tools in a comment\n\
                  let x = self::helper(); my_crate::other(); // super::ignored\n";
    let found: Vec<String> = named_paths(source, &module)
        .iter()
        .map(|p| p.join("::"))
        .collect();
    assert_eq!(
        found,
        [
            "gpu::canvas::Region",
            "gpu::mesh_store::MeshStore",
            "error::Result",
            "scene::Scene",
            "gpu::frame::helper"
        ]
    );
    assert_eq!(
        declared_items("pub(crate) fn f() {}\n    const K: u32 = 1;"),
        ["f", "K"]
    );
}
