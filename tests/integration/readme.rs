//! README.md is assembled from `docs/sections/` by `docs/assemble-readme.sh`; an edit to one that
//! is not carried to the other fails here.

/// The sections in the order the script concatenates them.
const SECTIONS: [&str; 9] = [
    "intro",
    "subcommands",
    "render",
    "golden",
    "oracle",
    "check",
    "compare",
    "grade",
    "development",
];

#[test]
fn readme_is_the_sections_assembled() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let script = std::fs::read_to_string(root.join("docs/assemble-readme.sh")).unwrap();
    assert!(
        script.contains(&format!("for s in {}; do", SECTIONS.join(" "))),
        "docs/assemble-readme.sh lists other sections than this test"
    );
    let sections: Vec<String> = SECTIONS
        .iter()
        .map(|s| std::fs::read_to_string(root.join(format!("docs/sections/{s}.md"))).unwrap())
        .collect();
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    assert!(
        readme == sections.join("\n"),
        "README.md differs from docs/sections/: run docs/assemble-readme.sh"
    );
}
