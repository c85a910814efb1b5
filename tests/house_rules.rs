//! The house rules, checked on `src/**/*.rs` (code outside `#[cfg(test)]` items and files named
//! `tests.rs` or declared by a `#[cfg(test)] mod x;`):
//!
//! - (a) no source file over [`MAX_FILE_LINES`] lines;
//! - (b) no function over [`MAX_FN_LINES`] lines, from its `fn` line to its closing brace;
//! - (c) no module imports against the layer order [`LAYERS`] (`use crate::x…`, `crate::x::…`
//!   paths, `super::…` paths that climb to the root): a module may use its own layer and the
//!   layers below;
//! - (d) no import circles between sibling modules of one folder (`super::b` in `a` and
//!   `super::a` in `b`, or longer circles), the crate root's top-level modules included.
//!
//! The checker is a small lexer (comments, strings and char literals blanked; braces matched),
//! not a Rust parser; its own known-answer tests are at the end of this file. Every violation
//! is listed, not just the first.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

const MAX_FILE_LINES: usize = 800;
const MAX_FN_LINES: usize = 150;

/// Top-level modules by layer, lowest first. A module may import its own layer and the layers
/// below it, never one above. Settled from the imports as they are:
///
/// 0. primitives that import nothing of ours: `time` (Nanos), `names`, `rng`, `assign`,
///    `progress` (the library's progress traits);
/// 1. `geometry` (camera models, poses; no longer imports `log`) and `groundtruth` (the JSON
///    ground-truth contract; imports nothing, read by `frames`, `synth` and the pipelines);
/// 2. `log` (session files; uses `time`, `geometry` for `CameraInfo` ↔ `CameraModel`);
/// 3. `frames` (sensor frames decoded from a log, ground truth joined);
/// 4. the stages' algorithms, which may share a layer: `calib`, `learn`, `vision`, `track`,
///    `laser`, `audio` (two-microphone delays and directions), `anchoring` (seed 003's
///    multi-modal person anchors and attention: imports `laser`, `vision`, `audio`, `track`);
/// 5. `eval` (metrics and statistics: pure functions of data);
/// 6. `synth` (writes logs through `log`; returns the preview's data, draws nothing);
/// 7. `report` (tables, figures, the preview sheet drawn from `synth`'s data, atomic writes);
/// 8. `run` (the runner: plan, per-session cache, aggregation, REPORT.md);
/// 9. `pipelines` (one experiment each, on `run`);
/// 10. `cli` (the binary: clap, progress bars; `src/main.rs` and `src/cli/`).
const LAYERS: &[&[&str]] = &[
    &["time", "names", "rng", "assign", "progress", "storage"],
    &["geometry", "groundtruth"],
    &["log"],
    &["frames"],
    &[
        "calib",
        "learn",
        "vision",
        "track",
        "laser",
        "audio",
        "anchoring",
    ],
    &["eval"],
    &["synth"],
    &["report"],
    &["run"],
    &["pipelines"],
    &["cli"],
];

fn layer(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

// ---------------------------------------------------------------------------------------------
// lexing

/// The source with comments, string and char literals blanked (newlines kept), so that braces
/// and paths can be found by position.
fn mask(src: &str) -> Vec<char> {
    let b: Vec<char> = src.chars().collect();
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    let blank = |c: char| if c == '\n' { '\n' } else { ' ' };
    let mut out: Vec<char> = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                out.push(' ');
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.extend([' ', ' ']);
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.extend([' ', ' ']);
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
        } else if c == 'r'
            && matches!(next, Some('"' | '#'))
            && (i == 0 || !ident(b[i - 1]) || (b[i - 1] == 'b' && (i < 2 || !ident(b[i - 2]))))
        {
            let mut j = i + 1;
            while b.get(j) == Some(&'#') {
                j += 1;
            }
            if b.get(j) != Some(&'"') {
                out.push(c); // a raw identifier r#name
                i += 1;
                continue;
            }
            let hashes = j - i - 1;
            out.extend(std::iter::repeat_n(' ', j - i));
            out.push('"');
            i = j + 1;
            while i < b.len() {
                if b[i] == '"' && (1..=hashes).all(|h| b.get(i + h) == Some(&'#')) {
                    out.push('"');
                    out.extend(std::iter::repeat_n(' ', hashes));
                    i += 1 + hashes;
                    break;
                }
                out.push(blank(b[i]));
                i += 1;
            }
        } else if c == '"' {
            out.push('"');
            i += 1;
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < b.len() {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
            if i < b.len() {
                out.push('"');
                i += 1;
            }
        } else if c == '\'' && next == Some('\\') {
            // an escaped char literal: '\n', '\'', '\u{1F600}'
            let mut j = i + 3;
            while j < b.len() && b[j] != '\'' {
                j += 1;
            }
            out.extend(std::iter::repeat_n(' ', (j + 1).min(b.len()) - i));
            i = j + 1;
        } else if c == '\'' && b.get(i + 2) == Some(&'\'') {
            out.extend([' ', ' ', ' ']); // a char literal 'x' (lifetimes have no closing quote)
            i += 3;
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

#[derive(Debug, Clone)]
struct Tok {
    text: String,
    line: usize,
}

/// Identifiers (and numbers), `::`, and single punctuation characters, with 1-based lines.
fn tokens(masked: &[char]) -> Vec<Tok> {
    let mut toks = Vec::new();
    let mut line = 1;
    let mut i = 0;
    while i < masked.len() {
        let c = masked[i];
        if c == '\n' {
            line += 1;
            i += 1;
        } else if c.is_whitespace() {
            i += 1;
        } else if c.is_alphanumeric() || c == '_' {
            let start = i;
            while i < masked.len() && (masked[i].is_alphanumeric() || masked[i] == '_') {
                i += 1;
            }
            toks.push(Tok {
                text: masked[start..i].iter().collect(),
                line,
            });
        } else if c == ':' && masked.get(i + 1) == Some(&':') {
            toks.push(Tok {
                text: "::".into(),
                line,
            });
            i += 2;
        } else {
            toks.push(Tok {
                text: c.to_string(),
                line,
            });
            i += 1;
        }
    }
    toks
}

fn is_ident(s: &str) -> bool {
    s.chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
}

/// Index of the token closing the bracket opened at `open`.
fn matching(toks: &[Tok], open: usize) -> usize {
    let (o, c) = match toks[open].text.as_str() {
        "(" => ("(", ")"),
        "[" => ("[", "]"),
        _ => ("{", "}"),
    };
    let mut depth = 0usize;
    for (k, t) in toks.iter().enumerate().skip(open) {
        if t.text == o {
            depth += 1;
        } else if t.text == c {
            depth -= 1;
            if depth == 0 {
                return k;
            }
        }
    }
    toks.len() - 1
}

/// From `start`, the first `{` or `;` outside parentheses and brackets (the end of an item's
/// head): its index.
fn item_head_end(toks: &[Tok], start: usize) -> Option<usize> {
    let mut k = start;
    while k < toks.len() {
        match toks[k].text.as_str() {
            "(" | "[" => k = matching(toks, k),
            "{" | ";" => return Some(k),
            _ => {}
        }
        k += 1;
    }
    None
}

// ---------------------------------------------------------------------------------------------
// one file

/// What the checker needs of one file.
struct Scanned {
    /// Token index ranges (inclusive) of `#[cfg(test)]` items.
    test_ranges: Vec<(usize, usize)>,
    /// Names of `#[cfg(test)] mod name;` declarations (their files are test code).
    test_mod_files: Vec<String>,
    toks: Vec<Tok>,
    lines: usize,
}

fn scan(src: &str) -> Scanned {
    let toks = tokens(&mask(src));
    let mut test_ranges = Vec::new();
    let mut test_mod_files = Vec::new();
    let text = |k: usize| toks.get(k).map_or("", |t| t.text.as_str());
    let mut k = 0;
    while k < toks.len() {
        let cfg_test = ["#", "[", "cfg", "(", "test", ")", "]"]
            .iter()
            .enumerate()
            .all(|(d, s)| text(k + d) == *s);
        if !cfg_test {
            k += 1;
            continue;
        }
        let mut j = k + 7;
        while text(j) == "#" && text(j + 1) == "[" {
            j = matching(&toks, j + 1) + 1;
        }
        let Some(end) = item_head_end(&toks, j) else {
            break;
        };
        let end = if text(end) == "{" {
            matching(&toks, end)
        } else {
            if let Some(m) = (j..end).find(|&m| text(m) == "mod") {
                test_mod_files.push(text(m + 1).to_string());
            }
            end
        };
        test_ranges.push((k, end));
        k = end + 1;
    }
    Scanned {
        test_ranges,
        test_mod_files,
        toks,
        lines: src.lines().count(),
    }
}

impl Scanned {
    fn in_test(&self, k: usize) -> bool {
        self.test_ranges.iter().any(|&(a, b)| a <= k && k <= b)
    }

    /// Lines outside `#[cfg(test)]` items.
    fn code_lines(&self) -> usize {
        let mut test_lines = BTreeSet::new();
        for &(a, b) in &self.test_ranges {
            test_lines.extend(self.toks[a].line..=self.toks[b].line);
        }
        self.lines - test_lines.len()
    }

    /// `(name, first line, lines)` of every function outside test items.
    fn functions(&self) -> Vec<(String, usize, usize)> {
        let t = &self.toks;
        let mut fns = Vec::new();
        for k in 0..t.len() {
            if t[k].text != "fn" || self.in_test(k) {
                continue;
            }
            let Some(name) = t.get(k + 1).filter(|n| is_ident(&n.text)) else {
                continue;
            };
            let Some(open) = item_head_end(t, k + 2).filter(|&o| t[o].text == "{") else {
                continue; // a declaration without a body
            };
            let close = matching(t, open);
            fns.push((name.text.clone(), t[k].line, t[close].line - t[k].line + 1));
        }
        fns
    }

    /// Paths starting with `crate`, `super` or `self` (use trees expanded), with their lines.
    fn paths(&self) -> Vec<(Vec<String>, usize)> {
        let t = &self.toks;
        let mut out = Vec::new();
        for k in 0..t.len() {
            let starts = matches!(t[k].text.as_str(), "crate" | "super" | "self")
                && t.get(k + 1).is_some_and(|n| n.text == "::")
                && (k == 0 || t[k - 1].text != "::");
            if starts && !self.in_test(k) {
                let mut found = Vec::new();
                use_tree(t, k, Vec::new(), &mut found);
                out.extend(found.into_iter().map(|p| (p, t[k].line)));
            }
        }
        out
    }
}

/// Parse a path or use tree at `j` below `prefix`; push every full path; return the index after.
fn use_tree(t: &[Tok], mut j: usize, mut segs: Vec<String>, out: &mut Vec<Vec<String>>) -> usize {
    loop {
        match t.get(j).map(|x| x.text.as_str()) {
            Some("{") => {
                j += 1;
                loop {
                    match t.get(j).map(|x| x.text.as_str()) {
                        Some("}") => return j + 1,
                        Some(",") => j += 1,
                        None => return j,
                        Some(_) => {
                            let before = j;
                            j = use_tree(t, j, segs.clone(), out);
                            if j == before {
                                j += 1;
                            }
                        }
                    }
                }
            }
            Some(s) if is_ident(s) || s == "*" => {
                segs.push(s.to_string());
                j += 1;
                if t.get(j).is_some_and(|x| x.text == "::") {
                    j += 1;
                    continue;
                }
                if t.get(j).is_some_and(|x| x.text == "as") {
                    j += 2;
                }
                out.push(segs);
                return j;
            }
            _ => {
                if !segs.is_empty() {
                    out.push(segs);
                }
                return j;
            }
        }
    }
}

/// The absolute module path (below the crate root) a path names, from module `module`.
fn resolve(module: &[String], segs: &[String]) -> Option<Vec<String>> {
    let mut base: Vec<String> = match segs.first()?.as_str() {
        "crate" => Vec::new(),
        "self" => module.to_vec(),
        "super" => module[..module.len().checked_sub(1)?].to_vec(),
        _ => return None,
    };
    for s in &segs[1..] {
        match s.as_str() {
            "super" => {
                base.pop()?;
            }
            "self" | "*" => {}
            _ => base.push(s.clone()),
        }
    }
    Some(base)
}

/// A file's module path: `log/reader.rs` → [log, reader], `log/mod.rs` → [log].
fn module_of(rel: &str) -> Vec<String> {
    let rel = rel.strip_suffix(".rs").unwrap_or(rel);
    let mut parts: Vec<String> = rel.split('/').map(str::to_string).collect();
    if parts
        .last()
        .is_some_and(|l| l == "mod" || l == "lib" || l == "main")
    {
        parts.pop();
    }
    parts
}

// ---------------------------------------------------------------------------------------------
// the tree

/// Every violation in `files` (`(path relative to src/, source)`), one line each.
fn check(files: &[(String, String)]) -> Vec<String> {
    let scanned: Vec<(String, Scanned)> = files
        .iter()
        .map(|(rel, src)| (rel.clone(), scan(src)))
        .collect();
    // test-only files
    let mut test_files: BTreeSet<String> = BTreeSet::new();
    for (rel, s) in &scanned {
        let dir = module_of(rel).join("/");
        for m in &s.test_mod_files {
            let d = if dir.is_empty() {
                String::new()
            } else {
                format!("{dir}/")
            };
            test_files.insert(format!("{d}{m}.rs"));
            test_files.insert(format!("{d}{m}/mod.rs"));
        }
    }
    let code: Vec<&(String, Scanned)> = scanned
        .iter()
        .filter(|(rel, _)| !rel.ends_with("tests.rs") && !test_files.contains(rel))
        .collect();
    let modules: BTreeSet<Vec<String>> = code
        .iter()
        .flat_map(|(rel, _)| {
            let m = module_of(rel);
            (1..=m.len()).map(move |n| m[..n].to_vec())
        })
        .collect();
    let mut v = Vec::new();
    // folder → (from, to) → first place
    let mut edges: BTreeMap<Vec<String>, BTreeMap<(String, String), String>> = BTreeMap::new();
    for (rel, s) in &code {
        let lines = s.code_lines();
        if lines > MAX_FILE_LINES {
            v.push(format!(
                "(a) src/{rel}: {lines} lines outside #[cfg(test)] (max {MAX_FILE_LINES})"
            ));
        }
        for (name, line, n) in s.functions() {
            if n > MAX_FN_LINES {
                v.push(format!(
                    "(b) src/{rel}:{line}: fn {name} has {n} lines (max {MAX_FN_LINES})"
                ));
            }
        }
        let module = module_of(rel);
        let mut reported = BTreeSet::new();
        for (segs, line) in s.paths() {
            let Some(target) = resolve(&module, &segs) else {
                continue;
            };
            let (Some(from), Some(to)) = (module.first(), target.first()) else {
                continue;
            };
            if from != to && modules.contains(&vec![to.clone()]) {
                match (layer(from), layer(to)) {
                    (Some(a), Some(b)) if a < b && reported.insert(to.clone()) => v.push(format!(
                        "(c) src/{rel}:{line}: {from} (layer {a}) imports {to} (layer {b}, higher)"
                    )),
                    (None, _) if reported.insert(from.clone()) => v.push(format!(
                        "(c) src/{rel}: module {from} is not in LAYERS (tests/house_rules.rs)"
                    )),
                    (_, None) if reported.insert(to.clone()) => v.push(format!(
                        "(c) src/{rel}:{line}: module {to} is not in LAYERS (tests/house_rules.rs)"
                    )),
                    _ => {}
                }
            }
            // sibling edge under the deepest common folder
            let common = module
                .iter()
                .zip(&target)
                .take_while(|(a, b)| a == b)
                .count();
            if common < module.len() && common < target.len() {
                let sibling = target[..=common].to_vec();
                if modules.contains(&sibling) {
                    edges
                        .entry(module[..common].to_vec())
                        .or_default()
                        .entry((module[common].clone(), target[common].clone()))
                        .or_insert_with(|| format!("src/{rel}:{line}"));
                }
            }
        }
    }
    v.extend(circles(&edges));
    v
}

/// (d) Circles among the modules of each folder: every strongly connected group of two or more.
fn circles(edges: &BTreeMap<Vec<String>, BTreeMap<(String, String), String>>) -> Vec<String> {
    let mut v = Vec::new();
    for (folder, es) in edges {
        let nodes: BTreeSet<&String> = es.keys().flat_map(|(a, b)| [a, b]).collect();
        let reach = |from: &String| -> BTreeSet<String> {
            let mut seen = BTreeSet::new();
            let mut stack = vec![from.clone()];
            while let Some(n) = stack.pop() {
                for (a, b) in es.keys() {
                    if *a == n && seen.insert(b.clone()) {
                        stack.push(b.clone());
                    }
                }
            }
            seen
        };
        let reaches: BTreeMap<&String, BTreeSet<String>> =
            nodes.iter().map(|n| (*n, reach(n))).collect();
        let mut done: BTreeSet<&String> = BTreeSet::new();
        for n in &nodes {
            if done.contains(n) || !reaches[n].contains(*n) {
                continue;
            }
            let group: Vec<&String> = nodes
                .iter()
                .copied()
                .filter(|m| reaches[n].contains(*m) && reaches[m].contains(*n))
                .collect();
            done.extend(group.iter().copied());
            let places: Vec<String> = es
                .iter()
                .filter(|((a, b), _)| group.contains(&a) && group.contains(&b))
                .map(|((a, b), at)| format!("{a} → {b} at {at}"))
                .collect();
            let names: Vec<&str> = group.iter().map(|s| s.as_str()).collect();
            v.push(format!(
                "(d) src/{}: import circle between {}: {}",
                if folder.is_empty() {
                    String::new()
                } else {
                    format!("{}/", folder.join("/"))
                },
                names.join(", "),
                places.join("; ")
            ));
        }
    }
    v
}

fn read_tree(root: &Path, dir: &Path, out: &mut Vec<(String, String)>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("readable folder")
        .map(|e| e.expect("entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            read_tree(root, &p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            let rel = p.strip_prefix(root).expect("below src");
            let rel = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect::<Vec<_>>()
                .join("/");
            out.push((rel, std::fs::read_to_string(&p).expect("utf-8 source")));
        }
    }
}

#[test]
fn the_source_tree_keeps_the_house_rules() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    read_tree(&src, &src, &mut files);
    assert!(files.len() > 50, "src/ was read");
    let v = check(&files);
    assert!(
        v.is_empty(),
        "{} house-rule violation(s):\n{}",
        v.len(),
        v.join("\n")
    );
}

// ---------------------------------------------------------------------------------------------
// the checker's own known answers

fn files(list: &[(&str, &str)]) -> Vec<(String, String)> {
    list.iter()
        .map(|(a, b)| ((*a).to_string(), (*b).to_string()))
        .collect()
}

#[test]
fn braces_in_strings_chars_and_comments_do_not_count() {
    let src = "fn a() {\n let s = \"}}\"; let c = '}'; let r = r#\"}\"#; // }\n /* { */ }\nfn b<'x>(v: &'x str) { }\n";
    let f = scan(src).functions();
    assert_eq!(
        f,
        [("a".to_string(), 1, 3), ("b".to_string(), 4, 1)],
        "{f:?}"
    );
}

#[test]
fn long_functions_are_found_and_test_items_are_not_counted() {
    let body = "    x += 1;\n".repeat(149);
    let ok = format!("fn ok() {{\n{body}}}\n"); // 1 + 149 + 1 = 151 lines: too long
    let short = format!("fn short() {{\n{}}}\n", "    x += 1;\n".repeat(148)); // 150: fine
    let test_mod = format!("#[cfg(test)]\nmod tests {{\n    fn long() {{\n{body}    }}\n}}\n");
    let v = check(&files(&[(
        "time.rs",
        &format!("{ok}{short}{test_mod}fn decl();\n"),
    )]));
    assert_eq!(
        v,
        ["(b) src/time.rs:1: fn ok has 151 lines (max 150)"],
        "{v:?}"
    );
}

#[test]
fn file_length_excludes_test_modules_and_test_files() {
    let code = "const X: u8 = 0;\n".repeat(800);
    let tests = format!("#[cfg(test)]\nmod tests {{\n{}}}\n", "// t\n".repeat(10));
    assert!(check(&files(&[("time.rs", &format!("{code}{tests}"))])).is_empty());
    let v = check(&files(&[("time.rs", &format!("{code}const Y: u8 = 0;\n"))]));
    assert_eq!(
        v,
        ["(a) src/time.rs: 801 lines outside #[cfg(test)] (max 800)"]
    );
    let big = "const X: u8 = 0;\n".repeat(900);
    let declared = "#[cfg(test)]\n#[path = \"x\"]\nmod checks;\n";
    assert!(
        check(&files(&[
            ("run/mod.rs", declared),
            ("run/checks.rs", &big),
            ("run/tests.rs", &big),
        ]))
        .is_empty()
    );
}

#[test]
fn imports_against_the_layers_are_found_in_every_form() {
    let v = check(&files(&[
        ("time.rs", ""),
        ("report/mod.rs", ""),
        ("run/mod.rs", ""),
        ("log/mod.rs", "pub mod reader;\nuse crate::time::Nanos;\n"),
        (
            "log/reader.rs",
            "use crate::{time::Nanos, report::{self, Table}};\nfn f() { super::super::run::go(); }\n// crate::run::x\nconst S: &str = \"crate::run\";\n",
        ),
        (
            "report/x.rs",
            "use crate::time::Nanos;\ncrate::table_row!(A);\nuse crate::Nanos;\n",
        ),
    ]));
    assert_eq!(
        v,
        [
            "(c) src/log/reader.rs:1: log (layer 2) imports report (layer 7, higher)",
            "(c) src/log/reader.rs:2: log (layer 2) imports run (layer 8, higher)",
        ],
        "{v:?}"
    );
    let v = check(&files(&[
        ("log/mod.rs", ""),
        ("gadgets/mod.rs", "use crate::log::X;\n"),
    ]));
    assert_eq!(
        v,
        ["(c) src/gadgets/mod.rs: module gadgets is not in LAYERS (tests/house_rules.rs)"]
    );
}

#[test]
fn circles_between_siblings_are_found() {
    let one_way = files(&[
        ("log/mod.rs", "mod a;\nmod b;\n"),
        ("log/a.rs", "use super::b::X;\n"),
        ("log/b.rs", "use super::Shared;\n"),
    ]);
    assert!(check(&one_way).is_empty());
    let v = check(&files(&[
        ("log/mod.rs", "mod a;\nmod b;\nmod c;\n"),
        ("log/a.rs", "use super::b::X;\n"),
        ("log/b.rs", "\nfn f() { crate::log::c::g() }\n"),
        (
            "log/c.rs",
            "use super::{a, b};\n#[cfg(test)]\nmod tests { use super::super::b; }\n",
        ),
    ]));
    assert_eq!(
        v,
        [
            "(d) src/log/: import circle between a, b, c: a → b at src/log/a.rs:1; b → c at src/log/b.rs:2; c → a at src/log/c.rs:1; c → b at src/log/c.rs:1"
        ],
        "{v:?}"
    );
}
