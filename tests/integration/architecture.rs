//! The house rules, checked on the source so they hold as the code grows:
//!
//! - no import cycle between the files of `src/`, nor between its top-level modules;
//! - the top-level modules stand on floors ([`FLOORS`]), and a module imports only from lower
//!   floors; within a folder, a room (a file or a sub-folder) imports only the rooms its
//!   folder's `mod.rs` declares before it;
//! - no source file is over [`MAX_FILE_LINES`] lines before its `#[cfg(test)]`, and no
//!   function over [`MAX_FN_LINES`] lines, except the tables of [`TABLES`], each with its reason.
//!
//! What counts as an import: every `use` whose path starts with `crate`, `super`, `self` or a
//! child module's name, every `crate::`, `super::` and `self::` path in the code, and a child
//! module's name used as a path; `rtoracle::` in `main.rs`. Comments, doc comments, string
//! literals and `#[cfg(test)]` / `#[cfg(doc)]` items are not code. A name is followed through
//! `use` re-exports to the file that defines it, so `crate::geometry::Interval` is an arrow to
//! `geometry/interval.rs`.
//!
//! A module's own file (`a/mod.rs`, or `a.rs` beside `a/`) may use its children: it is the room
//! they are in, and it declares them, re-exports them and hands work to them. Every other arrow
//! counts: a child's use of its parent's items, of a sibling, of another module. So a child may
//! use what its parent defines, and siblings must not import each other around a loop.
//!
//! The scanner is a small lexer, not a Rust parser: it is exact for the code as written here
//! (no macros that generate `use` items or functions), and its unit tests below pin the cases
//! it must get right.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The top-level modules, bottom floor first. A module imports only modules on lower floors
/// (the floors are the layering the code has; a new arrow that needs another floor moves a
/// module up, here and in `docs/ARCHITECTURE.md`).
const FLOORS: &[&[&str]] = &[
    // Exact and interval arithmetic: imports nothing else of the crate.
    &["arithmetic"],
    // Untrusted text kept as text; Ctrl-C and SIGTERM.
    &["escape", "interrupt", "secret"],
    // Output files, written whole or not at all (escaping names, removed when interrupted).
    &["output"],
    &["geometry"],
    &["scene"],
    // The engines: the reference renderer, the intersection oracle, the sandbox.
    &["render", "oracle", "sandbox"],
    &["image_io"],
    &["candidate"],
    // The function checks of the course's weeks 5 to 10 (run through a candidate's session).
    &["weekly"],
    &["golden"],
    &["compare"],
    // Physics checks that need no golden (materials through a candidate's session); grading
    // stands beside them.
    &["grade", "physics"],
    // The benchmarks: figures over every part, against baselines measured in the same run.
    &["bench"],
    // The binary: one module per subcommand, and `main`.
    &["cli"],
    &["main"],
];

/// The longest a source file may be before its `#[cfg(test)]`.
const MAX_FILE_LINES: usize = 900;
/// The longest a function may be, from its `fn` line to its closing brace.
const MAX_FN_LINES: usize = 120;

/// Files and functions that are tables, allowed to be long: `(file, function or "" for the
/// file's length, reason)`. None is over the limits today; an entry must say why the table
/// reads best whole, and goes when it is no longer too long.
const TABLES: &[(&str, &str, &str)] = &[];

/// Being split (issue 22): the known offenders that other work of the issue is splitting right
/// now. The test fails when an entry is no longer needed (remove it with the split that mends
/// it), so the list can only shrink; it goes when the splits have landed. `(file, what)`:
/// `what` is a function's name, `""` for the file's length, or `"cycle FILE"` for an import
/// cycle with another file.
const BEING_SPLIT: &[(&str, &str)] = &[];

#[test]
fn no_import_cycle_between_files() {
    let house = House::read();
    let mut failures = house.file_cycles();
    failures.retain(|c| !house.allowed_cycle(c));
    assert!(
        failures.is_empty(),
        "import cycles between files of src/ (no two files may import each other, directly or \
         around a loop):\n{}",
        failures
            .iter()
            .map(|c| house.describe_file_cycle(c))
            .collect::<Vec<_>>()
            .join("\n")
    );
}

#[test]
fn no_import_cycle_between_modules_and_no_arrow_up() {
    let house = House::read();
    let mut problems = vec![];
    for cycle in house.module_cycles() {
        problems.push(format!(
            "import cycle between modules: {}",
            house.describe_module_cycle(&cycle)
        ));
    }
    for (from, to, evidence) in house.module_arrows() {
        if let (Some(a), Some(b)) = (floor_of(&from), floor_of(&to)) {
            if a <= b {
                let which = if a == b { "its own" } else { "a higher" };
                problems.push(format!(
                    "{from} (floor {a}) imports {to} (floor {b}), {which} floor: {evidence}"
                ));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn no_long_files_and_no_long_functions() {
    let house = House::read();
    let mut problems = vec![];
    for file in &house.files {
        let long_file = file.production_lines > MAX_FILE_LINES;
        if long_file && !excused(&file.path, "") {
            problems.push(format!(
                "{} is {} lines before its #[cfg(test)] (at most {MAX_FILE_LINES}): split it \
                 where it does two things",
                file.path, file.production_lines
            ));
        }
        for f in &file.functions {
            if f.lines > MAX_FN_LINES && !excused(&file.path, &f.name) {
                problems.push(format!(
                    "{}:{}: fn {} is {} lines (at most {MAX_FN_LINES}): split it into steps \
                     you can name",
                    file.path, f.line, f.name, f.lines
                ));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_exceptions_are_still_needed() {
    let house = House::read();
    let cycles = house.file_cycles();
    let mut stale = vec![];
    for &(path, what) in BEING_SPLIT {
        let needed = if let Some(other) = what.strip_prefix("cycle ") {
            cycles
                .iter()
                .any(|c| c.contains(&path.to_string()) && c.contains(&other.to_string()))
        } else {
            house.too_long(path, what)
        };
        if !needed {
            stale.push(format!(
                "BEING_SPLIT lists ({path:?}, {what:?}), which is no longer needed: remove it \
                 from tests/integration/architecture.rs"
            ));
        }
    }
    for &(path, what, _reason) in TABLES {
        if !house.too_long(path, what) {
            stale.push(format!(
                "TABLES lists ({path:?}, {what:?}), which is no longer too long: remove it"
            ));
        }
    }
    assert!(stale.is_empty(), "{}", stale.join("\n"));
}

/// Within a folder, the rooms (its files and sub-folders) stand on floors too: the folder's own
/// file (`mod.rs`) declares them bottom floor first, and a room uses only rooms declared before
/// it. So a folder reads top to bottom, no two rooms import each other around a loop, and a new
/// arrow up fails here with the import that makes it and an order that would hold.
#[test]
fn within_a_folder_a_room_uses_only_rooms_declared_before_it() {
    let house = House::read();
    let problems = house.arrows_up_within_folders();
    assert!(
        problems.is_empty(),
        "within a folder, a room uses only the rooms its mod.rs declares before it (bottom floor \
         first):\n{}",
        problems.join("\n")
    );
}

/// The most `.rs` files a folder of `src/` holds directly (its sub-folders count as one each):
/// past about a dozen, a folder is split into rooms along the groups its `mod.rs` names.
const MAX_FOLDER_ENTRIES: usize = 13;

#[test]
fn no_folder_holds_more_than_about_a_dozen_files() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut crowded = BTreeMap::new();
    let mut dirs = vec![root.join("src")];
    while let Some(dir) = dirs.pop() {
        let mut entries = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
                entries += 1;
            } else if path.extension().is_some_and(|e| e == "rs") {
                entries += 1;
            }
        }
        let name = dir
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        crowded.insert(name, entries);
    }
    // `src` itself holds the top-level modules, which FLOORS orders.
    crowded.remove("src");
    let mut too_many = Vec::new();
    for (name, entries) in &crowded {
        if *entries > MAX_FOLDER_ENTRIES {
            too_many.push(format!("{name} ({entries})"));
        }
    }
    assert!(
        too_many.is_empty(),
        "these folders hold more than {MAX_FOLDER_ENTRIES} files and folders: {}; split each \
         into rooms along the groups its mod.rs names",
        too_many.join(", ")
    );
}

/// One surface per module: a module's own file either re-exports its children's items (a facade
/// over private files) or declares public files, not both.
#[test]
fn a_module_shows_one_surface() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    collect_rs(&root.join("src"), &mut files);
    let mut both = BTreeSet::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        let code = blank_test_items(&blank_literals(&text));
        let public_file = code.lines().any(|l| l.starts_with("pub mod "));
        let reexport = code.lines().any(|l| l.starts_with("pub use "));
        if public_file && reexport {
            let name = file
                .strip_prefix(&root)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            both.insert(name);
        }
    }
    assert!(
        both.is_empty(),
        "{both:?} both declare public files and re-export items: keep one surface (re-exports \
         over private files, or public files imported where they are defined)"
    );
}

/// docs/ARCHITECTURE.md's "Where to find things" names files and folders a newcomer opens
/// first: each must exist.
#[test]
fn the_files_the_architecture_page_points_to_exist() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let page = std::fs::read_to_string(root.join("docs/ARCHITECTURE.md")).unwrap();
    let start = page.find("## Where to find things").expect("the section");
    let end = page[start + 3..]
        .find("\n## ")
        .map_or(page.len(), |e| start + 3 + e);
    let section = &page[start..end];
    let mut named = 0;
    for word in section.split(|c: char| c.is_whitespace() || c == '`' || c == '(' || c == ',') {
        if let Some(path) = word.strip_prefix("src/") {
            let path = root
                .join("src")
                .join(path.trim_end_matches(['.', ')', ';', ':']));
            assert!(
                path.exists(),
                "docs/ARCHITECTURE.md names {} which is not there",
                path.display()
            );
            named += 1;
        }
    }
    assert!(
        named >= 20,
        "only {named} paths found in the section: the parser lost them"
    );
}

/// Every source path the docs name (`src/...` in README.md and docs/*.md) is there: a move
/// that leaves a page pointing at nothing fails here.
#[test]
fn every_source_path_the_docs_name_exists() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut pages = vec![root.join("README.md")];
    for entry in std::fs::read_dir(root.join("docs")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "md") {
            pages.push(path);
        }
    }
    let mut missing = vec![];
    let mut named = 0;
    for page in &pages {
        let text = std::fs::read_to_string(page).unwrap();
        let bytes = text.as_bytes();
        let mut from = 0;
        while let Some(i) = text[from..].find("src/").map(|i| from + i) {
            from = i + 4;
            let starts_a_path = i == 0
                || !(bytes[i - 1].is_ascii_alphanumeric() || b"_/.-".contains(&bytes[i - 1]));
            if !starts_a_path {
                continue;
            }
            let end = text[i..]
                .find(|c: char| !(c.is_ascii_alphanumeric() || "_/.".contains(c)))
                .map_or(text.len(), |e| i + e);
            let path = text[i..end].trim_end_matches(['.', '/']);
            named += 1;
            if !root.join(path).exists() {
                missing.push(format!("{} names {path}", page.display()));
            }
        }
    }
    assert!(
        named >= 40,
        "only {named} paths found: the scanner lost them"
    );
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

#[test]
fn the_floors_name_every_module_once() {
    let mut seen = BTreeSet::new();
    for floor in FLOORS {
        for m in *floor {
            assert!(seen.insert(*m), "{m} is on two floors");
        }
    }
    let house = House::read();
    for m in house.modules() {
        assert!(
            seen.contains(m.as_str()),
            "module {m} is on no floor: add it to FLOORS in this test and to docs/ARCHITECTURE.md"
        );
    }
}

fn floor_of(module: &str) -> Option<usize> {
    FLOORS.iter().position(|f| f.contains(&module))
}

fn excused(path: &str, what: &str) -> bool {
    BEING_SPLIT.iter().any(|&(p, w)| p == path && w == what)
        || TABLES.iter().any(|&(p, w, _)| p == path && w == what)
}

// ---------------------------------------------------------------------------------------------
// The house: every production source file, its imports and its functions.

/// One function: its name, the line of its `fn` and its length in lines.
#[derive(Debug)]
struct Function {
    name: String,
    line: usize,
    lines: usize,
}

/// One import arrow out of a file: the file it reaches, the line, and the path as written.
#[derive(Clone, Debug)]
struct Arrow {
    to: String,
    line: usize,
    path: String,
}

#[derive(Debug)]
struct SourceFile {
    /// `src/...`, with `/`.
    path: String,
    /// The module the file defines (`["oracle", "band"]`; `[]` for `lib.rs`, `["main"]` for
    /// `main.rs`).
    module: Vec<String>,
    /// The code with comments, literals and test items blanked (same byte offsets and lines).
    code: String,
    production_lines: usize,
    functions: Vec<Function>,
    arrows: Vec<Arrow>,
}

/// One `use` item: where it is, the module it is written in, and the paths it names with the
/// names they bind (`None` for a glob or `as _`).
#[derive(Debug)]
struct UseItem {
    offset: usize,
    module: Vec<String>,
    paths: Vec<UsePath>,
}

struct House {
    files: Vec<SourceFile>,
    /// Every module (file-backed or inline), mapped to the file that holds it.
    module_files: BTreeMap<Vec<String>, String>,
    /// Per module, the names its `use` items bind and the path each stands for.
    aliases: BTreeMap<Vec<String>, BTreeMap<String, Vec<String>>>,
}

impl House {
    /// The crate's `src/`, read once for all the tests.
    fn read() -> &'static House {
        static HOUSE: std::sync::OnceLock<House> = std::sync::OnceLock::new();
        HOUSE.get_or_init(House::read_now)
    }

    fn read_now() -> House {
        let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
        let mut paths = vec![];
        collect_rs(&root.join("src"), &mut paths);
        paths.sort();
        let mut raw = vec![];
        for p in paths {
            let text = std::fs::read_to_string(&p).expect("a readable source file");
            let rel = p
                .strip_prefix(&root)
                .expect("under the crate")
                .to_string_lossy()
                .replace('\\', "/");
            raw.push((rel, text));
        }
        House::of(raw)
    }

    /// The house of the given `(src/... path, text)` files.
    fn of(raw: Vec<(String, String)>) -> House {
        let mut files = vec![];
        for (path, text) in &raw {
            let module = module_of(path);
            let code = blank_test_items(&blank_literals(text));
            files.push(SourceFile {
                path: path.clone(),
                module,
                production_lines: production_lines(text),
                functions: functions(&code),
                code,
                arrows: vec![],
            });
        }
        // A file its parent declares only in test code (`#[cfg(test)] mod tests;`) is a test.
        // The binary's root `main.rs` declares its modules (`cli`) at the root, as the library
        // declares its own.
        let declared: BTreeSet<Vec<String>> = files
            .iter()
            .flat_map(|f| {
                let parent = if f.path == "src/main.rs" {
                    vec![]
                } else {
                    f.module.clone()
                };
                declared_modules(&f.code)
                    .into_iter()
                    .map(move |m| join(&parent, &m))
            })
            .collect();
        files.retain(|f| {
            f.module.is_empty() || f.path == "src/main.rs" || declared.contains(&f.module)
        });

        let mut module_files = BTreeMap::new();
        let mut inline = vec![];
        for f in &files {
            module_files.insert(f.module.clone(), f.path.clone());
            for (name, start, end) in inline_modules(&f.code) {
                inline.push((f.path.clone(), f.module.clone(), name, start, end));
            }
        }
        for (path, module, name, _, _) in &inline {
            module_files.insert(join(module, name), path.clone());
        }
        let module_at = |path: &str, base: &[String], offset: usize| -> Vec<String> {
            let mut m = base.to_vec();
            let mut spans: Vec<_> = inline
                .iter()
                .filter(|(p, _, _, s, e)| p == path && *s <= offset && offset < *e)
                .collect();
            spans.sort_by_key(|(_, _, _, s, _)| *s);
            for (_, _, name, _, _) in spans {
                m.push(name.clone());
            }
            m
        };

        let mut uses: BTreeMap<String, Vec<UseItem>> = BTreeMap::new();
        for f in &files {
            let items = use_items(&f.code)
                .into_iter()
                .map(|(offset, paths)| UseItem {
                    offset,
                    module: module_at(&f.path, &f.module, offset),
                    paths,
                })
                .collect();
            uses.insert(f.path.clone(), items);
        }
        let mut house = House {
            files: vec![],
            module_files,
            aliases: BTreeMap::new(),
        };
        // Aliases first (names bound by `use`, resolved lazily through each other).
        for items in uses.values() {
            for u in items {
                for (path, bound) in &u.paths {
                    if let Some(name) = bound {
                        house
                            .aliases
                            .entry(u.module.clone())
                            .or_default()
                            .insert(name.clone(), path.clone());
                    }
                }
            }
        }
        for mut f in files {
            let mut arrows = vec![];
            for u in &uses[&f.path] {
                let line = line_of(&f.code, u.offset);
                for (path, _) in &u.paths {
                    let Some(target) = house.resolve(&u.module, path) else {
                        continue;
                    };
                    arrows.push((target, line, path.join("::")));
                }
            }
            for (offset, path) in code_paths(&f.code, &house.child_names(&f.module)) {
                let module = module_at(&f.path, &f.module, offset);
                if let Some(target) = house.resolve(&module, &path) {
                    arrows.push((target, line_of(&f.code, offset), path.join("::")));
                }
            }
            for (target, line, path) in arrows {
                // A module's own file may use its children (see the module docs).
                if target.starts_with(&f.module) {
                    continue;
                }
                let to = house.file_of(&target);
                if to != f.path {
                    f.arrows.push(Arrow { to, line, path });
                }
            }
            house.files.push(f);
        }
        house
    }

    /// The names of the modules directly inside `module`.
    fn child_names(&self, module: &[String]) -> BTreeSet<String> {
        self.module_files
            .keys()
            .filter(|m| m.len() == module.len() + 1 && m.starts_with(module))
            .map(|m| m[module.len()].clone())
            .collect()
    }

    /// The module that defines what `path`, written in `module`, names; `None` for paths
    /// outside the crate.
    fn resolve(&self, module: &[String], path: &[String]) -> Option<Vec<String>> {
        self.resolve_depth(module, path, 0)
    }

    fn resolve_depth(
        &self,
        module: &[String],
        path: &[String],
        depth: usize,
    ) -> Option<Vec<String>> {
        if depth > 16 || path.is_empty() {
            return None;
        }
        let mut base: Vec<String>;
        let mut rest = path;
        match path[0].as_str() {
            "crate" | "rtoracle" => {
                base = vec![];
                rest = &path[1..];
            }
            "self" | "super" => {
                base = module.to_vec();
                while let Some(first) = rest.first() {
                    match first.as_str() {
                        "self" => {}
                        "super" => {
                            base.pop();
                        }
                        _ => break,
                    }
                    rest = &rest[1..];
                }
            }
            first => {
                if self.module_files.contains_key(&join(module, first)) {
                    base = module.to_vec();
                } else if let Some(target) = self.aliases.get(module).and_then(|a| a.get(first)) {
                    // A name bound by a `use` of this module (`use super::exact; exact::f()`).
                    let mut full = target.clone();
                    full.extend_from_slice(&path[1..]);
                    return self.resolve_depth(module, &full, depth + 1);
                } else {
                    return None;
                }
            }
        }
        // The longest prefix that is a module, then the name after it through that module's
        // aliases.
        let mut m = base;
        let mut i = 0;
        while i < rest.len() && self.module_files.contains_key(&join(&m, &rest[i])) {
            m.push(rest[i].clone());
            i += 1;
        }
        if i < rest.len() {
            if let Some(target) = self.aliases.get(&m).and_then(|a| a.get(&rest[i])) {
                let mut full = target.clone();
                full.extend_from_slice(&rest[i + 1..]);
                if let Some(r) = self.resolve_depth(&m, &full, depth + 1) {
                    return Some(r);
                }
            }
        }
        Some(m)
    }

    fn file_of(&self, module: &[String]) -> String {
        let mut m = module.to_vec();
        loop {
            if let Some(f) = self.module_files.get(&m) {
                return f.clone();
            }
            if m.pop().is_none() {
                return "src/lib.rs".into();
            }
        }
    }

    /// The top-level module of a file (`"main"` for the binary, `""` for `lib.rs`).
    fn top_of(path: &str) -> String {
        module_of(path).first().cloned().unwrap_or_default()
    }

    fn modules(&self) -> BTreeSet<String> {
        self.files
            .iter()
            .map(|f| House::top_of(&f.path))
            .filter(|m| !m.is_empty())
            .collect()
    }

    /// The arrows between top-level modules, with one import as evidence each.
    fn module_arrows(&self) -> Vec<(String, String, String)> {
        let mut out: BTreeMap<(String, String), String> = BTreeMap::new();
        for f in &self.files {
            let from = House::top_of(&f.path);
            for a in &f.arrows {
                let to = House::top_of(&a.to);
                if from.is_empty() || to.is_empty() || from == to {
                    continue;
                }
                out.entry((from.clone(), to))
                    .or_insert_with(|| format!("{}:{} uses {}", f.path, a.line, a.path));
            }
        }
        out.into_iter().map(|((a, b), e)| (a, b, e)).collect()
    }

    /// Every strongly connected group of more than one file, each as a list of files.
    fn file_cycles(&self) -> Vec<Vec<String>> {
        let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for f in &self.files {
            let e = graph.entry(f.path.clone()).or_default();
            for a in &f.arrows {
                e.insert(a.to.clone());
            }
        }
        strongly_connected(&graph)
    }

    fn module_cycles(&self) -> Vec<Vec<String>> {
        let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (from, to, _) in self.module_arrows() {
            graph.entry(from).or_default().insert(to);
        }
        strongly_connected(&graph)
    }

    fn allowed_cycle(&self, cycle: &[String]) -> bool {
        BEING_SPLIT.iter().any(|&(p, w)| {
            w.strip_prefix("cycle ")
                .is_some_and(|other| cycle.iter().all(|f| f == p || f == other) && cycle.len() == 2)
        })
    }

    /// A loop through the group, each step with the import that makes it.
    fn describe_file_cycle(&self, group: &[String]) -> String {
        let set: BTreeSet<&String> = group.iter().collect();
        let step = |from: &str| -> Vec<(String, String)> {
            let f = self.files.iter().find(|f| f.path == from).expect("a file");
            f.arrows
                .iter()
                .filter(|a| set.contains(&a.to))
                .map(|a| {
                    (
                        a.to.clone(),
                        format!("{}:{} uses {}", f.path, a.line, a.path),
                    )
                })
                .collect()
        };
        let lp = find_loop(&group[0], &|n| step(n));
        let mut s = String::from("  ");
        for (i, (node, why)) in lp.iter().enumerate() {
            let _ = write!(s, "{}{node}", if i == 0 { "" } else { " -> " });
            let _ = write!(s, " [{why}]");
        }
        let _ = write!(s, " -> {}", group[0]);
        s
    }

    fn describe_module_cycle(&self, group: &[String]) -> String {
        let arrows = self.module_arrows();
        let set: BTreeSet<&String> = group.iter().collect();
        let step = |from: &str| -> Vec<(String, String)> {
            arrows
                .iter()
                .filter(|(a, b, _)| a == from && set.contains(b))
                .map(|(_, b, e)| (b.clone(), e.clone()))
                .collect()
        };
        let lp = find_loop(&group[0], &|n| step(n));
        let mut s = String::new();
        for (i, (node, why)) in lp.iter().enumerate() {
            let _ = write!(s, "{}{node} [{why}]", if i == 0 { "" } else { " -> " });
        }
        let _ = write!(s, " -> {}", group[0]);
        s
    }

    /// For every folder, each import from one of its rooms to a room its own file declares at
    /// or after it, with the evidence, and a declaration order that would hold (rooms declared
    /// only in test code are not rooms: the scanner blanks test items).
    fn arrows_up_within_folders(&self) -> Vec<String> {
        let mut problems = vec![];
        for owner in &self.files {
            // The crate's root and the binary's: FLOORS orders the top-level modules.
            if owner.module.is_empty() || owner.path == "src/main.rs" {
                continue;
            }
            let folder = &owner.module;
            let room_of = |module: &[String]| -> Option<String> {
                (module.len() > folder.len() && module.starts_with(folder))
                    .then(|| module[folder.len()].clone())
            };
            let rooms: BTreeSet<String> = self
                .files
                .iter()
                .filter_map(|f| room_of(&f.module))
                .collect();
            if rooms.len() < 2 {
                continue;
            }
            let mut order: Vec<String> = vec![];
            for name in declared_modules(&owner.code) {
                if rooms.contains(&name) && !order.contains(&name) {
                    order.push(name);
                }
            }
            let mut arrows: BTreeMap<(String, String), String> = BTreeMap::new();
            for f in &self.files {
                let Some(from) = room_of(&f.module) else {
                    continue;
                };
                for a in &f.arrows {
                    if let Some(to) = room_of(&module_of(&a.to)) {
                        if to != from {
                            arrows.entry((from.clone(), to)).or_insert_with(|| {
                                format!("{}:{} uses {}", f.path, a.line, a.path)
                            });
                        }
                    }
                }
            }
            let position = |room: &str| order.iter().position(|r| r == room);
            let mut up = vec![];
            for ((from, to), evidence) in &arrows {
                let (Some(a), Some(b)) = (position(from), position(to)) else {
                    continue;
                };
                if b >= a {
                    up.push(format!("  {from} uses {to}, declared after it: {evidence}"));
                }
            }
            if !up.is_empty() {
                problems.push(format!(
                    "{}: {}\n{}",
                    owner.path,
                    suggested_order(&order, &arrows),
                    up.join("\n")
                ));
            }
        }
        problems
    }

    /// Whether `path` is too long (`what == ""`) or has a function `what` that is.
    fn too_long(&self, path: &str, what: &str) -> bool {
        let Some(f) = self.files.iter().find(|f| f.path == path) else {
            return false;
        };
        if what.is_empty() {
            f.production_lines > MAX_FILE_LINES
        } else {
            f.functions
                .iter()
                .any(|g| g.name == what && g.lines > MAX_FN_LINES)
        }
    }
}

/// A declaration order of the rooms in which each uses only rooms before it, as close to
/// `order` as it can be (the earliest-declared room that is ready goes next); or the rooms that
/// import each other around a loop when there is none.
fn suggested_order(order: &[String], arrows: &BTreeMap<(String, String), String>) -> String {
    let mut placed: Vec<String> = vec![];
    let mut left: Vec<String> = order.to_vec();
    while !left.is_empty() {
        let ready = left.iter().position(|room| {
            arrows
                .keys()
                .all(|(from, to)| from != room || placed.contains(to) || !left.contains(to))
        });
        match ready {
            Some(i) => placed.push(left.remove(i)),
            None => {
                let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
                for (from, to) in arrows.keys() {
                    if left.contains(from) && left.contains(to) {
                        graph.entry(from.clone()).or_default().insert(to.clone());
                    }
                }
                let loops: Vec<String> = strongly_connected(&graph)
                    .iter()
                    .map(|group| group.join(", "))
                    .collect();
                return format!(
                    "no order holds, these rooms import each other around a loop: {}",
                    loops.join("; ")
                );
            }
        }
    }
    format!("an order that holds: {}", placed.join(", "))
}

fn collect_rs(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("a readable folder") {
        let p = entry.expect("an entry").path();
        if p.is_dir() {
            collect_rs(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

fn join(m: &[String], name: &str) -> Vec<String> {
    let mut v = m.to_vec();
    v.push(name.to_string());
    v
}

/// `src/a/b.rs` and `src/a/b/mod.rs` define `a::b`; `src/lib.rs` the crate; `src/main.rs` the
/// binary, called `main`.
fn module_of(path: &str) -> Vec<String> {
    let rel = path.strip_prefix("src/").unwrap_or(path);
    let rel = rel.strip_suffix(".rs").unwrap_or(rel);
    if rel == "lib" {
        return vec![];
    }
    let mut parts: Vec<String> = rel.split('/').map(str::to_string).collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
}

fn line_of(text: &str, offset: usize) -> usize {
    text[..offset].bytes().filter(|&b| b == b'\n').count() + 1
}

/// Lines before the first `#[cfg(test)]` at the start of a line (all of them without one).
fn production_lines(text: &str) -> usize {
    text.lines()
        .position(|l| l.starts_with("#[cfg(test)]"))
        .unwrap_or_else(|| text.lines().count())
}

// ---------------------------------------------------------------------------------------------
// The lexer.

/// The text with comments and the contents of string and character literals replaced by
/// spaces (newlines kept), so offsets and lines stay those of the file.
fn blank_literals(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let blank = |out: &mut Vec<u8>, from: usize, to: usize| {
        for c in &mut out[from..to] {
            if *c != b'\n' {
                *c = b' ';
            }
        }
    };
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c == b'/' && b.get(i + 1) == Some(&b'/') {
            let end = b[i..]
                .iter()
                .position(|&x| x == b'\n')
                .map_or(b.len(), |p| i + p);
            blank(&mut out, i, end);
            i = end;
        } else if c == b'/' && b.get(i + 1) == Some(&b'*') {
            let mut depth = 0;
            let mut j = i;
            while j < b.len() {
                if b[j] == b'/' && b.get(j + 1) == Some(&b'*') {
                    depth += 1;
                    j += 2;
                } else if b[j] == b'*' && b.get(j + 1) == Some(&b'/') {
                    depth -= 1;
                    j += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    j += 1;
                }
            }
            blank(&mut out, i, j);
            i = j;
        } else if (c == b'r' || c == b'b')
            && !prev_is_ident(b, i)
            && raw_string_start(b, i).is_some()
        {
            let (hashes, open) = raw_string_start(b, i).expect("checked");
            let close: Vec<u8> = std::iter::once(b'"')
                .chain(std::iter::repeat_n(b'#', hashes))
                .collect();
            let end = b[open + 1..]
                .windows(close.len())
                .position(|w| w == close.as_slice())
                .map_or(b.len(), |p| open + 1 + p + close.len());
            blank(
                &mut out,
                open + 1,
                end.saturating_sub(close.len()).max(open + 1),
            );
            i = end;
        } else if c == b'"' {
            let mut j = i + 1;
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            blank(&mut out, i + 1, j.min(b.len()));
            i = j + 1;
        } else if c == b'\'' {
            // A character literal, or a lifetime / label (`'a`), which is left alone.
            if let Some(end) = char_literal_end(b, i) {
                blank(&mut out, i + 1, end);
                i = end + 1;
            } else {
                i += 1;
            }
        } else {
            i += 1;
        }
    }
    String::from_utf8(out).unwrap_or_default()
}

fn prev_is_ident(b: &[u8], i: usize) -> bool {
    i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_')
}

/// At `r"`, `r#"`, `br"`, `br#"`: the number of `#` and the offset of the opening quote.
fn raw_string_start(b: &[u8], i: usize) -> Option<(usize, usize)> {
    let mut j = i;
    if b[j] == b'b' {
        j += 1;
    }
    if b.get(j) != Some(&b'r') {
        return None;
    }
    j += 1;
    let mut hashes = 0;
    while b.get(j) == Some(&b'#') {
        hashes += 1;
        j += 1;
    }
    (b.get(j) == Some(&b'"')).then_some((hashes, j))
}

/// The offset of the closing `'` of a character literal starting at `i`, or `None` for a
/// lifetime or a label.
fn char_literal_end(b: &[u8], i: usize) -> Option<usize> {
    if b.get(i + 1) == Some(&b'\\') {
        let end = b[i + 2..].iter().position(|&x| x == b'\'')?;
        return Some(i + 2 + end);
    }
    // One character (one to four bytes) and a closing quote.
    let len = (1..=4).find(|&k| {
        b.get(i + 1..i + 1 + k)
            .is_some_and(|s| std::str::from_utf8(s).is_ok())
    })?;
    let after = i + 1 + len;
    (b.get(after) == Some(&b'\'')).then_some(after)
}

/// The offset just past the `}` matching the `{` at `open`.
fn matching_brace(b: &[u8], open: usize) -> usize {
    let mut depth = 0usize;
    for (k, &c) in b.iter().enumerate().skip(open) {
        if c == b'{' {
            depth += 1;
        } else if c == b'}' {
            depth -= 1;
            if depth == 0 {
                return k + 1;
            }
        }
    }
    b.len()
}

/// The end of the item starting at `from`: past its `;` or its matching `}`, whichever comes
/// first outside brackets and parentheses.
fn item_end(b: &[u8], from: usize) -> usize {
    let mut depth = 0i32;
    for (k, &c) in b.iter().enumerate().skip(from) {
        match c {
            b'(' | b'[' => depth += 1,
            b')' | b']' => depth -= 1,
            b';' if depth == 0 => return k + 1,
            b'{' if depth == 0 => return matching_brace(b, k),
            _ => {}
        }
    }
    b.len()
}

/// The code with every item under `#[cfg(test)]` or `#[cfg(doc)]` blanked.
fn blank_test_items(code: &str) -> String {
    let mut out = code.as_bytes().to_vec();
    for marker in ["#[cfg(test)]", "#[cfg(doc)]"] {
        let mut from = 0;
        while let Some(p) = find_from(&out, marker.as_bytes(), from) {
            let mut k = p + marker.len();
            // Further attributes of the same item.
            loop {
                while k < out.len() && out[k].is_ascii_whitespace() {
                    k += 1;
                }
                if out.get(k) == Some(&b'#') && out.get(k + 1) == Some(&b'[') {
                    k = bracket_end(&out, k + 1);
                } else {
                    break;
                }
            }
            let end = item_end(&out, k);
            for c in &mut out[p..end] {
                if *c != b'\n' {
                    *c = b' ';
                }
            }
            from = end;
        }
    }
    String::from_utf8(out).unwrap_or_default()
}

fn bracket_end(b: &[u8], open: usize) -> usize {
    let mut depth = 0usize;
    for (k, &c) in b.iter().enumerate().skip(open) {
        if c == b'[' {
            depth += 1;
        } else if c == b']' {
            depth -= 1;
            if depth == 0 {
                return k + 1;
            }
        }
    }
    b.len()
}

fn find_from(hay: &[u8], needle: &[u8], from: usize) -> Option<usize> {
    hay.get(from..)?
        .windows(needle.len())
        .position(|w| w == needle)
        .map(|p| from + p)
}

/// The identifier starting at `i`, if one starts there (and not in the middle of another).
fn ident_at(b: &[u8], i: usize) -> Option<&str> {
    if prev_is_ident(b, i) || !(b[i].is_ascii_alphabetic() || b[i] == b'_') {
        return None;
    }
    let end = b[i..]
        .iter()
        .position(|c| !(c.is_ascii_alphanumeric() || *c == b'_'))
        .map_or(b.len(), |p| i + p);
    std::str::from_utf8(&b[i..end]).ok()
}

fn skip_ws(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && b[i].is_ascii_whitespace() {
        i += 1;
    }
    i
}

/// Every `fn NAME ... { ... }` of the code with its length in lines.
fn functions(code: &str) -> Vec<Function> {
    let b = code.as_bytes();
    let mut out = vec![];
    let mut i = 0;
    while i < b.len() {
        if ident_at(b, i) == Some("fn") {
            let j = skip_ws(b, i + 2);
            if let Some(name) = ident_at(b, j) {
                // The body: the first `{` outside brackets, unless a `;` ends a declaration.
                let mut depth = 0i32;
                let mut k = j;
                let mut body = None;
                while k < b.len() {
                    match b[k] {
                        b'(' | b'[' => depth += 1,
                        b')' | b']' => depth -= 1,
                        b';' if depth == 0 => break,
                        b'{' if depth == 0 => {
                            body = Some(k);
                            break;
                        }
                        _ => {}
                    }
                    k += 1;
                }
                if let Some(open) = body {
                    let end = matching_brace(b, open);
                    let first = line_of(code, i);
                    let last = line_of(code, end.saturating_sub(1));
                    out.push(Function {
                        name: name.to_string(),
                        line: first,
                        lines: last - first + 1,
                    });
                }
            }
            i += 2;
        } else {
            i += 1;
        }
    }
    out
}

/// The names of `mod NAME;` and `mod NAME { ... }` declarations.
fn declared_modules(code: &str) -> Vec<String> {
    let b = code.as_bytes();
    let mut out = vec![];
    for i in 0..b.len() {
        if ident_at(b, i) == Some("mod") {
            let j = skip_ws(b, i + 3);
            if let Some(name) = ident_at(b, j) {
                out.push(name.to_string());
            }
        }
    }
    out
}

/// Inline modules `mod NAME { ... }`: name, and the byte range of the braces.
fn inline_modules(code: &str) -> Vec<(String, usize, usize)> {
    let b = code.as_bytes();
    let mut out = vec![];
    for i in 0..b.len() {
        if ident_at(b, i) == Some("mod") {
            let j = skip_ws(b, i + 3);
            if let Some(name) = ident_at(b, j) {
                let k = skip_ws(b, j + name.len());
                if b.get(k) == Some(&b'{') {
                    out.push((name.to_string(), k, matching_brace(b, k)));
                }
            }
        }
    }
    out
}

/// A path of a `use` item and the name it binds (`None` for `*` and `as _`).
type UsePath = (Vec<String>, Option<String>);

/// Every `use` item: its offset and its paths.
fn use_items(code: &str) -> Vec<(usize, Vec<UsePath>)> {
    let b = code.as_bytes();
    let mut out = vec![];
    let mut i = 0;
    while i < b.len() {
        if ident_at(b, i) == Some("use") {
            let end = b[i..]
                .iter()
                .position(|&c| c == b';')
                .map_or(b.len(), |p| i + p);
            let tokens = tokenize(&code[i + 3..end]);
            let mut paths = vec![];
            parse_tree(&tokens, &mut 0, &[], &mut paths);
            out.push((i, paths));
            i = end;
        } else {
            i += 1;
        }
    }
    out
}

fn tokenize(s: &str) -> Vec<String> {
    let b = s.as_bytes();
    let mut out = vec![];
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c == b':' && b.get(i + 1) == Some(&b':') {
            out.push("::".into());
            i += 2;
        } else if c.is_ascii_alphanumeric() || c == b'_' {
            let end = b[i..]
                .iter()
                .position(|c| !(c.is_ascii_alphanumeric() || *c == b'_'))
                .map_or(b.len(), |p| i + p);
            out.push(s[i..end].to_string());
            i = end;
        } else {
            out.push((c as char).to_string());
            i += 1;
        }
    }
    out
}

/// Parses a use tree into full paths and the names they bind.
fn parse_tree(t: &[String], i: &mut usize, prefix: &[String], out: &mut Vec<UsePath>) {
    let mut path = prefix.to_vec();
    while *i < t.len() {
        match t[*i].as_str() {
            "{" => {
                *i += 1;
                loop {
                    if *i >= t.len() {
                        return;
                    }
                    if t[*i] == "}" {
                        *i += 1;
                        return;
                    }
                    parse_tree(t, i, &path, out);
                    if *i < t.len() && t[*i] == "," {
                        *i += 1;
                    }
                }
            }
            "*" => {
                *i += 1;
                out.push((path, None));
                return;
            }
            "::" => *i += 1,
            "," | "}" => {
                bind(path, None, out);
                return;
            }
            "as" => {
                *i += 1;
                let alias = t.get(*i).cloned();
                *i += 1;
                bind(path, alias, out);
                return;
            }
            seg => {
                path.push(seg.to_string());
                *i += 1;
            }
        }
    }
    if !path.is_empty() && path.len() > prefix.len() {
        bind(path, None, out);
    }
}

/// `a::b::self` binds `b` to `a::b`; `a::b` binds `b`; `as _` binds nothing.
fn bind(mut path: Vec<String>, alias: Option<String>, out: &mut Vec<UsePath>) {
    if path.last().is_some_and(|s| s == "self") {
        path.pop();
    }
    let Some(last) = path.last().cloned() else {
        return;
    };
    // `use x as _` imports without binding a name.
    let name = match alias {
        Some(a) if a == "_" => None,
        Some(a) => Some(a),
        None => Some(last),
    };
    out.push((path, name));
}

/// Paths in code (outside `use` items) that start with `crate::`, `super::`, `self::`,
/// `rtoracle::` or the name of a child module followed by `::`.
fn code_paths(code: &str, children: &BTreeSet<String>) -> Vec<(usize, Vec<String>)> {
    let b = code.as_bytes();
    let uses: Vec<(usize, usize)> = {
        let mut v = vec![];
        let mut i = 0;
        while i < b.len() {
            if ident_at(b, i) == Some("use") {
                let end = b[i..]
                    .iter()
                    .position(|&c| c == b';')
                    .map_or(b.len(), |p| i + p);
                v.push((i, end));
                i = end;
            } else {
                i += 1;
            }
        }
        v
    };
    let in_use = |k: usize| uses.iter().any(|&(s, e)| s <= k && k < e);
    let mut out = vec![];
    let mut i = 0;
    while i < b.len() {
        let Some(first) = ident_at(b, i) else {
            i += 1;
            continue;
        };
        let len = first.len();
        let starts =
            matches!(first, "crate" | "super" | "self" | "rtoracle") || children.contains(first);
        let after = skip_ws(b, i + len);
        let preceded_by_path = i >= 2 && &b[i - 2..i] == b"::";
        if starts && !preceded_by_path && b.get(after..after + 2) == Some(b"::") && !in_use(i) {
            let mut path = vec![first.to_string()];
            let mut k = after + 2;
            loop {
                let k2 = skip_ws(b, k);
                let Some(seg) = ident_at(b, k2) else { break };
                path.push(seg.to_string());
                let next = skip_ws(b, k2 + seg.len());
                if b.get(next..next + 2) == Some(b"::") {
                    k = next + 2;
                } else {
                    k = next;
                    break;
                }
            }
            out.push((i, path));
            i = k.max(i + len);
        } else {
            i += len;
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Graphs.

/// The strongly connected groups of more than one node (Tarjan), each sorted, in order.
fn strongly_connected(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'g> {
        graph: &'g BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'g str, usize>,
        low: BTreeMap<&'g str, usize>,
        stack: Vec<&'g str>,
        on_stack: BTreeSet<&'g str>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    fn visit<'g>(s: &mut State<'g>, v: &'g str) {
        s.index.insert(v, s.next);
        s.low.insert(v, s.next);
        s.next += 1;
        s.stack.push(v);
        s.on_stack.insert(v);
        if let Some(edges) = s.graph.get(v) {
            for w in edges {
                if !s.index.contains_key(w.as_str()) {
                    visit(s, w);
                    let lw = s.low[w.as_str()];
                    let lv = s.low[v];
                    s.low.insert(v, lv.min(lw));
                } else if s.on_stack.contains(w.as_str()) {
                    let iw = s.index[w.as_str()];
                    let lv = s.low[v];
                    s.low.insert(v, lv.min(iw));
                }
            }
        }
        if s.low[v] == s.index[v] {
            let mut group = vec![];
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                group.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if group.len() > 1 {
                group.sort();
                s.out.push(group);
            }
        }
    }
    let mut s = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: vec![],
        on_stack: BTreeSet::new(),
        next: 0,
        out: vec![],
    };
    for v in graph.keys() {
        if !s.index.contains_key(v.as_str()) {
            visit(&mut s, v);
        }
    }
    s.out.sort();
    s.out
}

/// A shortest loop from `start` back to itself, as `(node, why it steps to the next)`.
fn find_loop(start: &str, step: &dyn Fn(&str) -> Vec<(String, String)>) -> Vec<(String, String)> {
    // Breadth-first from start's successors back to start.
    let mut prev: BTreeMap<String, (String, String)> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::new();
    queue.push_back(start.to_string());
    while let Some(n) = queue.pop_front() {
        for (m, why) in step(&n) {
            if prev.contains_key(&m) {
                continue;
            }
            prev.insert(m.clone(), (n.clone(), why));
            if m == start {
                let mut path = vec![];
                let mut cur = start.to_string();
                loop {
                    let (p, why) = prev[&cur].clone();
                    path.push((p.clone(), why));
                    cur = p;
                    if cur == start {
                        break;
                    }
                }
                path.reverse();
                return path;
            }
            queue.push_back(m);
        }
    }
    vec![(start.to_string(), "?".into())]
}

// ---------------------------------------------------------------------------------------------
// The scanner's own tests: each names a case it must get right.

fn house(files: &[(&str, &str)]) -> House {
    House::of(
        files
            .iter()
            .map(|(p, t)| (p.to_string(), t.to_string()))
            .collect(),
    )
}

fn arrows(h: &House, path: &str) -> Vec<String> {
    let f = h.files.iter().find(|f| f.path == path).expect("the file");
    let mut v: Vec<String> = f.arrows.iter().map(|a| a.to.clone()).collect();
    v.sort();
    v.dedup();
    v
}

#[test]
fn scanner_follows_reexports_and_ignores_comments_strings_and_tests() {
    let h = house(&[
        ("src/lib.rs", "pub mod a;\npub mod b;\n"),
        (
            "src/a/mod.rs",
            "mod x;\nmod y;\npub use x::X;\npub use y::Y;\npub fn shared() {}\n",
        ),
        ("src/a/x.rs", "use super::shared;\npub struct X;\n"),
        ("src/a/y.rs", "pub struct Y;\n"),
        (
            "src/b.rs",
            "//! see crate::a::Y\nuse crate::a::X;\nfn f() { let s = \"crate::a::Y\"; }\n\
             #[cfg(test)]\nmod tests { use crate::a::Y; }\n",
        ),
    ]);
    // The parent's `pub use x::X` is no arrow; x's use of `shared` is one to mod.rs.
    assert_eq!(arrows(&h, "src/a/mod.rs"), Vec::<String>::new());
    assert_eq!(arrows(&h, "src/a/x.rs"), vec!["src/a/mod.rs"]);
    // b reaches X through the re-export; the doc comment, the string and the test are not code.
    assert_eq!(arrows(&h, "src/b.rs"), vec!["src/a/x.rs"]);
    assert!(h.file_cycles().is_empty());
}

#[test]
fn scanner_finds_a_cycle_through_code_paths_and_child_names() {
    let h = house(&[
        ("src/lib.rs", "pub mod a;\npub mod b;\n"),
        (
            "src/a/mod.rs",
            "mod p;\nmod q;\nfn f() { q::g(); crate::b::h(); }\n",
        ),
        ("src/a/p.rs", "pub fn h() { super::q::g() }\n"),
        ("src/a/q.rs", "pub fn g() { crate::a::p::h(); }\n"),
        ("src/b.rs", "pub fn h() {}\n"),
    ]);
    // The parent's use of its child is no arrow; its use of another module is one.
    assert_eq!(arrows(&h, "src/a/mod.rs"), vec!["src/b.rs"]);
    assert_eq!(
        h.file_cycles(),
        vec![vec!["src/a/p.rs".to_string(), "src/a/q.rs".to_string()]]
    );
    let words = h.describe_file_cycle(&h.file_cycles()[0]);
    assert!(words.contains("src/a/p.rs:1 uses super::q::g"), "{words}");
    // Module level: a -> b only.
    assert_eq!(
        h.module_arrows()
            .into_iter()
            .map(|(a, b, _)| (a, b))
            .collect::<Vec<_>>(),
        vec![("a".to_string(), "b".to_string())]
    );
}

#[test]
fn scanner_measures_functions_and_skips_fn_types_and_declarations() {
    let code = blank_test_items(&blank_literals(
        "trait T { fn decl(&self); }\nfn pointer(f: fn(u8) -> u8) -> u8 {\n    let c = '{';\n    \
         let s = r#\"}\"#;\n    f(1)\n}\nfn life<'a>(x: &'a str) -> &'a str { x }\n",
    ));
    let f = functions(&code);
    let names: Vec<(&str, usize)> = f.iter().map(|f| (f.name.as_str(), f.lines)).collect();
    assert_eq!(names, vec![("pointer", 5), ("life", 1)]);
    assert_eq!(production_lines("a\nb\n#[cfg(test)]\nmod tests {}\n"), 2);
}

#[test]
fn scanner_reads_use_trees() {
    let items = use_items("pub(crate) use super::{a::{self, B as C}, d::*, e};");
    assert_eq!(items.len(), 1);
    let (_, paths) = &items[0];
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    assert_eq!(
        paths,
        &vec![
            (s(&["super", "a"]), Some("a".to_string())),
            (s(&["super", "a", "B"]), Some("C".to_string())),
            (s(&["super", "d"]), None),
            (s(&["super", "e"]), Some("e".to_string())),
        ]
    );
}

#[test]
fn scanner_finds_an_arrow_up_within_a_folder_and_an_order_that_holds() {
    // In a/, `low` is declared first and `high` second; `sub/` (a room of a sub-folder) is
    // declared last. `low` uses `high` (an arrow up), `sub`'s file uses `low` (fine), and `high`
    // uses what the folder's own file defines (fine: not a room).
    let h = house(&[
        ("src/lib.rs", "pub mod a;\n"),
        (
            "src/a/mod.rs",
            "pub mod low;\npub mod high;\npub mod sub;\npub fn shared() {}\n",
        ),
        ("src/a/low.rs", "use super::high::H;\npub struct L;\n"),
        ("src/a/high.rs", "use super::shared;\npub struct H;\n"),
        ("src/a/sub/mod.rs", "mod deep;\n"),
        ("src/a/sub/deep.rs", "use crate::a::low::L;\n"),
    ]);
    let problems = h.arrows_up_within_folders();
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(
        problems[0].starts_with("src/a/mod.rs: an order that holds: high, low, sub"),
        "{}",
        problems[0]
    );
    assert!(
        problems[0]
            .contains("low uses high, declared after it: src/a/low.rs:1 uses super::high::H"),
        "{}",
        problems[0]
    );

    // Two rooms that import each other through files that do not (no file cycle): no order.
    let h = house(&[
        ("src/lib.rs", "pub mod a;\n"),
        ("src/a/mod.rs", "pub mod p;\npub mod q;\n"),
        ("src/a/p/mod.rs", "pub mod one;\npub mod two;\n"),
        ("src/a/p/one.rs", "pub struct One;\n"),
        ("src/a/p/two.rs", "use crate::a::q::Q;\n"),
        ("src/a/q.rs", "use crate::a::p::one::One;\npub struct Q;\n"),
    ]);
    assert!(h.file_cycles().is_empty());
    let problems = h.arrows_up_within_folders();
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(
        problems[0].contains("import each other around a loop: p, q"),
        "{}",
        problems[0]
    );
}
