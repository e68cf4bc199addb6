//! The library's layers hold: every import in `crates/cdbo/src` runs down (or within a layer),
//! and no two modules use each other. The layers are the table in `docs/design.md`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers of docs/design.md's table: module → its layer's rank (1 = lowest).
fn layers() -> BTreeMap<String, usize> {
    let design = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/design.md");
    let text = std::fs::read_to_string(&design).expect("docs/design.md");
    let mut rank = BTreeMap::new();
    for row in text.lines().filter(|l| l.starts_with("| ")) {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let Some(n) = cells[1]
            .split_whitespace()
            .next()
            .and_then(|n| n.parse().ok())
        else {
            continue;
        };
        for module in cells[2].split(',') {
            let module = module.trim().trim_matches('`');
            assert!(
                rank.insert(module.to_string(), n).is_none(),
                "{module} is in two layers"
            );
        }
    }
    assert!(
        rank.len() > 20,
        "docs/design.md gives {} modules",
        rank.len()
    );
    rank
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("the source tree") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level modules named by one `use crate::…;` item's body: `track::Track` gives
/// `track`, `{car::Car, sim::{self, Lap}}` gives `car` and `sim`.
fn used_modules(body: &str, out: &mut Vec<String>) {
    let body = body.trim();
    let Some(inner) = body.strip_prefix('{').and_then(|b| b.strip_suffix('}')) else {
        out.push(body.split("::").next().unwrap_or("").trim().to_string());
        return;
    };
    let (mut depth, mut start) = (0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                used_modules(&inner[start..i], out);
                start = i + 1;
            }
            _ => {}
        }
    }
    if !inner[start..].trim().is_empty() {
        used_modules(&inner[start..], out);
    }
}

/// The modules each file of a top-level module imports, with where: (from, to) → places.
fn imports(src: &Path) -> BTreeMap<(String, String), BTreeSet<String>> {
    let mut files = Vec::new();
    sources(src, &mut files);
    let mut edges: BTreeMap<(String, String), BTreeSet<String>> = BTreeMap::new();
    for file in files {
        let rel = file.strip_prefix(src).expect("under src");
        let from = rel
            .components()
            .next()
            .and_then(|c| c.as_os_str().to_str())
            .map(|c| c.trim_end_matches(".rs").to_string())
            .expect("a module");
        if from == "lib" {
            continue;
        }
        let text = std::fs::read_to_string(&file).expect("a source file");
        // Comments name modules freely (links in doc comments); code is what imports.
        let code: String = text
            .lines()
            .map(|l| {
                if l.trim_start().starts_with("//") {
                    ""
                } else {
                    l
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        let mut to = Vec::new();
        let mut rest = code.as_str();
        while let Some(i) = rest.find("crate::") {
            let after = &rest[i + "crate::".len()..];
            let is_use = rest[..i].trim_end().ends_with("use");
            if is_use {
                let end = after.find(';').unwrap_or(after.len());
                used_modules(&after[..end], &mut to);
            } else {
                let name: String = after
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if after[name.len()..].starts_with("::") {
                    to.push(name);
                }
            }
            rest = after;
        }
        for module in to {
            if !module.is_empty() && module != from && module != "self" && module != "Result" {
                edges
                    .entry((from.clone(), module))
                    .or_default()
                    .insert(rel.display().to_string());
            }
        }
    }
    edges
}

#[test]
fn every_import_runs_down_a_layer() {
    let rank = layers();
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let edges = imports(&src);
    let mut wrong = Vec::new();
    for ((from, to), places) in &edges {
        let (Some(a), Some(b)) = (rank.get(from), rank.get(to)) else {
            // A name that is no module of the crate (`crate::Error`) has no layer.
            if !rank.contains_key(from) {
                wrong.push(format!("{from} is in no layer of docs/design.md"));
            }
            continue;
        };
        if b > a {
            wrong.push(format!(
                "{from} (layer {a}) uses {to} (layer {b}) in {places:?}"
            ));
        } else if edges.contains_key(&(to.clone(), from.clone())) && from < to {
            wrong.push(format!("{from} and {to} use each other ({places:?})"));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn every_module_of_the_crate_is_in_a_layer() {
    let rank = layers();
    let lib = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/lib.rs"))
        .expect("lib.rs");
    let declared: BTreeSet<String> = lib
        .lines()
        .filter_map(|l| {
            let l = l.trim().trim_start_matches("pub ");
            l.strip_prefix("mod ")?
                .strip_suffix(';')
                .map(str::to_string)
        })
        .collect();
    let listed: BTreeSet<String> = rank.keys().cloned().collect();
    assert_eq!(
        declared, listed,
        "lib.rs's modules against docs/design.md's layers"
    );
}

/// The check finds what it is for: an import that runs up, and two modules that use each other.
#[test]
fn the_check_sees_an_import_up_and_a_loop() {
    let dir = std::env::temp_dir().join(format!("cdbo-layers-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("track")).unwrap();
    std::fs::write(
        dir.join("track/mod.rs"),
        "use crate::{error::Result, sim::{self, Lap}};\n// use crate::study;\n",
    )
    .unwrap();
    std::fs::write(dir.join("sim.rs"), "fn f() { crate::track::load(); }\n").unwrap();
    let edges = imports(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    let pairs: Vec<(&str, &str)> = edges
        .keys()
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    assert_eq!(
        pairs,
        [("sim", "track"), ("track", "error"), ("track", "sim")]
    );
}
