//! The report formats, all written from one [`GradeReport`]: [`Format`] names them and renders
//! one, [`write_reports`] writes them into a folder.

mod feedback;
pub mod gradescope;
pub mod json;
pub mod junit;
pub mod markdown;

use std::path::Path;

use super::{result::GradeError, result::GradeReport};

/// The report formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Format {
    /// `report.json`.
    Json,
    /// `results.json` for Gradescope.
    Gradescope,
    /// `junit.xml`.
    Junit,
    /// `feedback.md`.
    Markdown,
}

impl Format {
    /// Every format.
    pub const ALL: [Format; 4] = [
        Format::Json,
        Format::Gradescope,
        Format::Junit,
        Format::Markdown,
    ];

    /// Parses `all` or a comma-separated list.
    pub fn parse_list(text: &str) -> Result<Vec<Format>, GradeError> {
        let mut out = Vec::new();
        for part in text.split(',').map(str::trim) {
            match part {
                "all" => out.extend(Format::ALL),
                "json" => out.push(Format::Json),
                "gradescope" => out.push(Format::Gradescope),
                "junit" => out.push(Format::Junit),
                "markdown" | "md" => out.push(Format::Markdown),
                other => return Err(GradeError::Format(other.to_string())),
            }
        }
        out.sort();
        out.dedup();
        Ok(out)
    }

    /// Its name on the command line (`--format`) and in `batch.json`.
    pub fn name(self) -> &'static str {
        match self {
            Format::Json => "json",
            Format::Gradescope => "gradescope",
            Format::Junit => "junit",
            Format::Markdown => "markdown",
        }
    }

    /// The file it is written to.
    pub fn file_name(self) -> &'static str {
        match self {
            Format::Json => "report.json",
            Format::Gradescope => "results.json",
            Format::Junit => "junit.xml",
            Format::Markdown => "feedback.md",
        }
    }

    /// `report` in this format.
    pub fn render(self, report: &GradeReport) -> String {
        match self {
            Format::Json => json::render(report),
            Format::Gradescope => gradescope::render(report),
            Format::Junit => junit::render(report),
            Format::Markdown => markdown::render(report),
        }
    }
}

/// The exception a check's smallest failure raised, as the reports say it (`raised NameError:
/// name 'root' is not defined (RT_object.py, line 29)`: the submission's text, unescaped), for a
/// line of its own on the terminal: a code check's smallest failing vector that raised, a
/// function's smallest failing case that raised, a render that raised.
pub fn exception_of(check: &super::result::CheckResult) -> Option<crate::escape::Untrusted> {
    use crate::escape::Untrusted;
    if let Some(f) = &check.function {
        return f
            .failure
            .as_ref()
            .map(|c| Untrusted::from(c.problem.as_str()))
            .filter(|p| p.starts_with("raised "));
    }
    if let Some(image) = &check.image {
        let why = image.metrics.get("render")?.get("not_run")?.as_str()?;
        return Untrusted::from(why)
            .strip_prefix("the render ")
            .filter(|w| w.starts_with("raised "));
    }
    let f = super::result::smallest_failure(&check.failures)?;
    (f.kind == crate::candidate::judging::check::FailureKind::Error
        && f.message.starts_with("raised "))
    .then(|| f.message.clone())
}

/// Writes `report` in each of `formats` into the existing folder `out_dir` (each file whole or
/// not at all, readable by everyone: reports are read by other users, such as a web server or
/// Gradescope's harness).
pub fn write_reports(
    report: &GradeReport,
    out_dir: &Path,
    formats: &[Format],
) -> Result<(), GradeError> {
    for &f in formats {
        let path = out_dir.join(f.file_name());
        crate::output::write_file(&path, "", f.render(report).as_bytes())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_parse() {
        assert_eq!(Format::parse_list("all").unwrap(), Format::ALL);
        assert_eq!(
            Format::parse_list("markdown,json").unwrap(),
            [Format::Json, Format::Markdown]
        );
        assert_eq!(Format::parse_list(" md , md").unwrap(), [Format::Markdown]);
        let e = Format::parse_list("json,pdf").unwrap_err().to_string();
        assert!(e.starts_with("--format \"pdf\""), "{e}");
    }
}
