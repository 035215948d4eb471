//! The library's module graph, read from its sources: data flows one way (no cycle between the
//! top-level modules) and no detector depends on the synthetic-part generator (`synth` is test
//! data only). Test code (`#[cfg(test)]` items) and comments are not counted.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("source folder") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The source without comment lines and `#[cfg(test)]` items (a `mod x;` line or a braced block).
fn non_test_code(source: &str) -> String {
    let lines: Vec<&str> = source.lines().collect();
    let mut kept = Vec::new();
    let mut j = 0;
    while j < lines.len() {
        let line = lines[j].trim();
        if line == "#[cfg(test)]" {
            j += 1;
            if lines.get(j).is_some_and(|l| l.trim_end().ends_with(';')) {
                j += 1;
                continue;
            }
            let (mut depth, mut opened) = (0i64, false);
            while j < lines.len() {
                let l = lines[j];
                depth += l.matches('{').count() as i64 - l.matches('}').count() as i64;
                opened |= l.contains('{');
                j += 1;
                if opened && depth <= 0 {
                    break;
                }
            }
            continue;
        }
        if !line.starts_with("//") {
            kept.push(lines[j]);
        }
        j += 1;
    }
    kept.join("\n")
}

/// Top-level module → the other top-level modules it names as `crate::name`.
fn module_graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in files {
        let rel = file.strip_prefix(&src).expect("under src");
        let top = rel
            .components()
            .next()
            .and_then(|c| c.as_os_str().to_str())
            .expect("component")
            .trim_end_matches(".rs")
            .to_string();
        let code = non_test_code(&std::fs::read_to_string(&file).expect("source"));
        let deps = graph.entry(top.clone()).or_default();
        for (at, _) in code.match_indices("crate::") {
            let name: String = code[at + 7..]
                .chars()
                .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                .collect();
            if !name.is_empty() && name != top {
                deps.insert(name);
            }
        }
    }
    graph
}

#[test]
fn the_module_graph_has_no_cycle() {
    let graph = module_graph();
    assert!(graph.len() >= 12, "found only {:?}", graph.keys());
    // Depth-first search with colours: a grey module reached again closes a cycle.
    fn visit<'a>(
        m: &'a str,
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<&'a str, u8>,
        path: &mut Vec<&'a str>,
    ) {
        match state.get(m) {
            Some(2) => return,
            Some(1) => panic!("module cycle: {} -> {m}", path.join(" -> ")),
            _ => {}
        }
        state.insert(m, 1);
        path.push(m);
        for d in graph.get(m).into_iter().flatten() {
            visit(d, graph, state, path);
        }
        path.pop();
        state.insert(m, 2);
    }
    let mut state = BTreeMap::new();
    for m in graph.keys() {
        visit(m, &graph, &mut state, &mut Vec::new());
    }
}

#[test]
fn no_detector_depends_on_the_synthetic_parts() {
    let graph = module_graph();
    let users: Vec<&String> = graph
        .iter()
        .filter(|(m, deps)| m.as_str() != "synth" && deps.contains("synth"))
        .map(|(m, _)| m)
        .collect();
    assert!(users.is_empty(), "modules importing synth: {users:?}");
    // The base layers import nothing above them.
    for (m, allowed) in [
        ("geometry", &[][..]),
        ("spatial", &["geometry"][..]),
        ("estimate", &["geometry", "spatial"][..]),
    ] {
        let deps = &graph[m];
        assert!(
            deps.iter().all(|d| allowed.contains(&d.as_str())),
            "{m} imports {deps:?}, only {allowed:?} allowed"
        );
    }
}
