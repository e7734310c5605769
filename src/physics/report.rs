//! The materials report in words: one line per material, then each law that failed or is a
//! finding about the model, with what was measured; every text the candidate controls (its
//! name, its error messages) escaped for the terminal.

use std::fmt::Write as _;

use super::laws::Status;
use super::materials::{MaterialResult, MaterialsReport};
use crate::escape::terminal_line;

fn status_word(s: Status) -> &'static str {
    match s {
        Status::Passed => "passed",
        Status::Failed => "FAILED",
        Status::Finding => "finding",
        Status::NotRun => "not run",
    }
}

impl MaterialsReport {
    /// The report in words.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "materials of {}", terminal_line(&self.candidate));
        if let Some(why) = &self.not_run {
            let _ = writeln!(s, "  not run: {why}");
            return s;
        }
        let _ = writeln!(
            s,
            "  {} samples per outgoing direction, seed {}; false-alarm rate {:.0e} per run ({:.2e} per statistical test); answers: {}",
            self.options.samples,
            self.options.seed,
            self.options.alpha,
            self.alpha_per_test,
            self.ops.join(", ")
        );
        for m in &self.materials {
            material_text(&mut s, m);
        }
        let findings = self
            .materials
            .iter()
            .flat_map(MaterialResult::laws)
            .filter(|l| l.status == Status::Finding)
            .count();
        let verdict = if self.passed() {
            "PASS"
        } else if self.ran() {
            "FAIL"
        } else {
            "NOTHING RUN"
        };
        let _ = write!(s, "materials verdict: {verdict}");
        if findings > 0 {
            let whose = self.reference.as_deref().unwrap_or("the reference");
            let _ = write!(
                s,
                " ({findings} findings about the model: laws that {} break too, so not the \
                 candidate's failures)",
                terminal_line(whose)
            );
        }
        s.push('\n');
        s
    }
}

fn material_text(s: &mut String, m: &MaterialResult) {
    let counts = |st: Status| m.laws().filter(|l| l.status == st).count();
    let _ = write!(
        s,
        "  {:<14} {:<8}",
        terminal_line(&m.name),
        status_word(m.status)
    );
    match &m.problem {
        Some(p) => {
            let _ = writeln!(s, " {}", terminal_line(p));
            return;
        }
        None => {
            let _ = writeln!(
                s,
                " {} laws passed, {} failed, {} findings, {} not run ({} directions)",
                counts(Status::Passed),
                counts(Status::Failed),
                counts(Status::Finding),
                counts(Status::NotRun),
                m.directions.len()
            );
        }
    }
    for d in &m.directions {
        for l in d
            .laws
            .iter()
            .filter(|l| matches!(l.status, Status::Failed | Status::Finding))
        {
            let tag = if l.status == Status::Finding {
                "finding about the model"
            } else {
                "failed"
            };
            let p = l
                .p_value
                .map(|p| format!(" (p {p:.2e})"))
                .unwrap_or_default();
            let _ = writeln!(
                s,
                "    {tag}: {} at cos theta_o {:+.2}: {}{p}",
                l.law.name(),
                d.cos_theta,
                terminal_line(&l.detail)
            );
        }
    }
    let r = &m.reciprocity;
    if matches!(r.status, Status::Failed | Status::Finding) {
        let tag = if r.status == Status::Finding {
            "finding about the model"
        } else {
            "failed"
        };
        let _ = writeln!(s, "    {tag}: reciprocity: {}", terminal_line(&r.detail));
    }
}
