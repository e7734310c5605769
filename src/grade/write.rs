//! Grading into a report folder: what `rtoracle grade DIR --out OUT` does. The folder is an
//! [`OutputDir`]: checked before any work (an existing one may hold only rtoracle's reports,
//! [`REPORT_FOLDER`]), filled beside its place and swapped in whole (see [`crate::output`]).

use std::path::Path;

use super::checkers::{CodeChecker, ImageChecker};
use super::report::Format;
use super::result::{GradeError, GradeReport};
use super::rubric::Rubric;
use super::run::grade;
use crate::output::{OutputDir, Replaceable};

/// Whether `name` is a file rtoracle's reports consist of (so an old report folder may be
/// replaced whole): a report, a heatmap, a batch's gradebook, summary or `batch.json`, a
/// batch submission's `batch-entry.json`.
fn is_report_file(name: &str) -> bool {
    matches!(
        name,
        "report.json"
            | "results.json"
            | "junit.xml"
            | "feedback.md"
            | "gradebook.csv"
            | "summary.md"
            | "batch.json"
            | "batch-entry.json"
    ) || (name.starts_with("heatmap-") && name.ends_with(".png"))
}

/// What a folder may hold to be replaced by grading's reports: only rtoracle's reports (and,
/// for a batch, folders of them), so no file of the user's is ever removed.
pub const REPORT_FOLDER: Replaceable = Replaceable {
    what: "an rtoracle grade report",
    is_output_file: is_report_file,
    folders: true,
};

/// Grades into a fresh staging folder and swaps it in whole as `out_dir` (see [`OutputDir`]):
/// what `rtoracle grade DIR --out OUT` does. An existing `out_dir` must hold only rtoracle's
/// reports ([`REPORT_FOLDER`], checked before any work); an interruption leaves no temporary
/// folder behind and a previous report as it was.
pub fn grade_to_dir(
    submission: &Path,
    rubric: &Rubric,
    code: &dyn CodeChecker,
    images: &dyn ImageChecker,
    out_dir: &Path,
    formats: &[Format],
) -> Result<GradeReport, GradeError> {
    if !submission.is_dir() {
        return Err(GradeError::NoSubmission(submission.to_path_buf()));
    }
    let out = OutputDir::create(out_dir, "", &REPORT_FOLDER)?;
    let report = grade_into(
        submission,
        rubric,
        code,
        images,
        &out,
        Path::new(""),
        formats,
    )?;
    out.commit()?;
    Ok(report)
}

/// Grades and writes the reports into the existing, empty folder `rel` of the staging folder
/// `out` (`""` for its top).
pub(crate) fn grade_into(
    submission: &Path,
    rubric: &Rubric,
    code: &dyn CodeChecker,
    images: &dyn ImageChecker,
    out: &OutputDir,
    rel: &Path,
    formats: &[Format],
) -> Result<GradeReport, GradeError> {
    let report = grade(submission, rubric, code, images, &out.path().join(rel))?;
    for &f in formats {
        out.write(rel.join(f.file_name()), f.render(&report).as_bytes())?;
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grade::checkers::fakes::*;
    use crate::output::tests::names;

    #[test]
    fn a_report_folder_is_replaced_whole_through_a_link_and_a_users_file_stops_it_first() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        fake_images(&sub);
        // A previous batch's folder behind a link: replaced whole, the link stays.
        let real = dir.path().join("real");
        std::fs::create_dir_all(real.join("old-sub")).unwrap();
        std::fs::write(real.join("gradebook.csv"), b"old").unwrap();
        std::fs::write(real.join("old-sub/heatmap-x.png"), b"old").unwrap();
        let link = dir.path().join("link");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        let grade_to_link = |code: &FakeCode| {
            grade_to_dir(
                &sub,
                &Rubric::week04(),
                code,
                &all_pass(),
                &link,
                &[Format::Json],
            )
        };
        let code = FakeCode::new(counts(2, 1), counts(2, 2));
        assert_eq!(grade_to_link(&code).unwrap().score, 85.0);
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(names(&real), ["report.json"]);
        assert_eq!(names(dir.path()), ["link", "real", "sub"]);
        // A file of the user's: refused before grading (which would panic here), and kept.
        std::fs::write(real.join("notes.txt"), b"mine").unwrap();
        let mut code = FakeCode::new(counts(2, 1), counts(2, 2));
        code.panic_on = Some("sub".into());
        let e = grade_to_link(&code).unwrap_err().to_string();
        assert!(e.contains("holds notes.txt"), "{e}");
        assert_eq!(names(&real), ["notes.txt", "report.json"]);
        assert_eq!(names(dir.path()), ["link", "real", "sub"]);
    }
}
