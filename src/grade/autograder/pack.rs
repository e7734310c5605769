//! Packing a rubric with its scene files and goldens, for the Gradescope autograder.
//!
//! [`pack_rubric`] promises: every image group on a scene file gets its scene file (the
//! original bytes, so its SHA-256 in `report.json` is the instructor's file's) and a golden
//! (the rubric's own, else [`crate::golden::golden_of`]'s, rendered into the cache now if
//! missing) under
//! [`PACKED_SCENES`]`/`, and the packed rubric names them there, so grading from the package
//! never renders. Built-in scenes need nothing: their goldens are in the binary.

use std::collections::BTreeSet;
use std::path::Path;

use crate::golden::{cache_dir, golden_of, golden_spp};
use crate::grade::rubric::{GroupKind, Rubric};

/// The folder of the package (beside `rubric.toml`) holding the scene files and goldens.
pub const PACKED_SCENES: &str = "rtoracle-scenes";

/// A rubric ready to pack.
#[derive(Clone, Debug, PartialEq)]
pub struct PackedRubric {
    /// The rubric's TOML with scene-file paths rewritten to [`PACKED_SCENES`].
    pub rubric_toml: String,
    /// The files to put beside it: (path in the package, bytes).
    pub files: Vec<(String, Vec<u8>)>,
    /// How many goldens were rendered to pack them.
    pub rendered: usize,
}

/// Why a rubric cannot be packed (one line).
#[derive(Debug, thiserror::Error)]
pub enum PackError {
    /// The rubric's text is not the TOML it was loaded from.
    #[error("{0}: the rubric's text cannot be rewritten: {1}")]
    Rewrite(String, String),
    /// A golden could not be rendered.
    #[error("{0}: cannot render the golden of {1}: {2}")]
    Golden(String, String, String),
}

/// Packs `rubric` (loaded from `rubric_text`): see the module docs. Missing goldens are rendered
/// (as the image checker would: for candidates of the scene's own samples per pixel), with a
/// progress bar when stderr is a terminal.
pub fn pack_rubric(rubric: &Rubric, rubric_text: &str) -> Result<PackedRubric, PackError> {
    let rewrite = |e: String| PackError::Rewrite(rubric.source.clone(), e);
    let mut table: toml::Table = toml::from_str(rubric_text).map_err(|e| rewrite(e.to_string()))?;
    let groups = table
        .get_mut("group")
        .and_then(|g| g.as_array_mut())
        .ok_or_else(|| rewrite("no [[group]] array".into()))?;
    if groups.len() != rubric.groups.len() {
        return Err(rewrite("its groups differ from the loaded rubric's".into()));
    }
    let mut files = Vec::new();
    let mut used = BTreeSet::new();
    let mut rendered = 0;
    for (value, group) in groups.iter_mut().zip(&rubric.groups) {
        let (GroupKind::Image, Some(scene)) = (group.kind, &group.scene_file) else {
            continue;
        };
        let entry = value
            .as_table_mut()
            .ok_or_else(|| rewrite("a [[group]] is not a table".into()))?;
        let stem: String = Path::new(&scene.label)
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default()
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let mut name = stem.clone();
        let mut n = 1;
        while !used.insert(name.clone()) {
            n += 1;
            name = format!("{stem}-{n}");
        }
        let scene_path = format!("{PACKED_SCENES}/{name}.toml");
        let golden_path = format!("{PACKED_SCENES}/{name}.exr");
        let golden = match &scene.golden {
            Some(g) => g.bytes.clone(),
            None => {
                let spp = golden_spp(scene.description.image.samples_per_pixel);
                let fail = |e: crate::golden::GoldenError| {
                    PackError::Golden(rubric.source.clone(), scene.label.clone(), e.to_string())
                };
                let made = crate::grade::checkers::images::golden_scene_of(scene)
                    .and_then(|g| golden_of(&g, spp, cache_dir().as_deref(), true))
                    .map_err(fail)?;
                rendered += usize::from(made.rendered());
                made.bytes
            }
        };
        let scene_bytes = std::fs::read(&scene.path).map_err(|e| {
            rewrite(format!(
                "{}: cannot read the scene file again: {e}",
                scene.path.display()
            ))
        })?;
        entry.insert("scene".into(), scene_path.clone().into());
        entry.insert("golden".into(), golden_path.clone().into());
        // Keep the image name the students were told, even when it was the default.
        if let Some(file) = &group.file {
            entry.insert("file".into(), file.clone().into());
        }
        files.push((scene_path, scene_bytes));
        files.push((golden_path, golden));
    }
    let body = toml::to_string(&table).map_err(|e| rewrite(e.to_string()))?;
    Ok(PackedRubric {
        rubric_toml: format!(
            "# Packed by rtoracle autograder from {}: scene files and goldens are in {PACKED_SCENES}/.\n{body}",
            rubric.source.replace('\n', " ")
        ),
        files,
        rendered,
    })
}
