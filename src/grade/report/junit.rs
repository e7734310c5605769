//! `junit.xml`: a `<testsuite>` per rubric group and a `<testcase>` per check, with `<failure>`,
//! `<error>` or `<skipped>` as the check came out, written by a small escaping writer.

use std::fmt::Write;

use crate::escape::Untrusted;
use crate::grade::{result::CheckStatus, result::GradeReport};

/// Escapes text for XML content and attribute values ([`crate::escape::xml`]).
pub fn escape(text: &str) -> String {
    crate::escape::xml(text)
}

/// `junit.xml` text.
pub fn render(report: &GradeReport) -> String {
    let count = |s: CheckStatus| report.checks.iter().filter(|c| c.status == s).count();
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<testsuites name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\" skipped=\"{}\" time=\"{}\">",
        Untrusted::from("rtoracle grade ")
            .join("", &report.submission)
            .xml(),
        report.checks.len(),
        count(CheckStatus::Failed),
        count(CheckStatus::Error),
        count(CheckStatus::Skipped),
        report.execution_time
    );
    for (group, score, max) in report.group_scores() {
        let checks: Vec<_> = report.checks.iter().filter(|c| c.group == group).collect();
        let n = |s: CheckStatus| checks.iter().filter(|c| c.status == s).count();
        let _ = writeln!(
            x,
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"{}\" skipped=\"{}\">",
            escape(&group),
            checks.len(),
            n(CheckStatus::Failed),
            n(CheckStatus::Error),
            n(CheckStatus::Skipped)
        );
        let _ = writeln!(
            x,
            "    <properties>\n      <property name=\"score\" value=\"{score}\"/>\n      <property name=\"max_score\" value=\"{max}\"/>\n    </properties>"
        );
        for c in checks {
            let _ = write!(
                x,
                "    <testcase classname=\"{}\" name=\"{}\"",
                escape(&c.group),
                escape(&c.id)
            );
            let mut body = c.message.clone();
            // A function check's smallest failing case: what the code answered or raised.
            if let Some(failure) = c.function.as_ref().and_then(|f| f.failure.as_ref()) {
                body.push_str(&format!(
                    "\n\n{} ({}): {}\n{}",
                    failure.case, failure.input, failure.problem, failure.repro
                ));
            }
            for f in &c.failures {
                body.push_str(&format!("\n\n{} [{}]: ", f.id, f.kind.name()));
                body.push(&f.message);
                body.push_str(&format!("\n{}", f.repro));
            }
            let tag = match c.status {
                CheckStatus::Passed => None,
                CheckStatus::Failed => Some("failure"),
                CheckStatus::Error => Some("error"),
                CheckStatus::Skipped => Some("skipped"),
            };
            match tag {
                None => x.push_str("/>\n"),
                Some(tag) => {
                    let _ = writeln!(
                        x,
                        ">\n      <{tag} message=\"{}\" type=\"{}\">{}</{tag}>\n    </testcase>",
                        Untrusted::from(format!("{} / {}: ", c.score, c.max_score))
                            .join("", &c.message.first_line())
                            .xml(),
                        c.status.name(),
                        body.xml()
                    );
                }
            }
        }
        x.push_str("  </testsuite>\n");
    }
    x.push_str("</testsuites>\n");
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_covers_markup_quotes_and_control_characters() {
        assert_eq!(escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&apos;");
        assert_eq!(escape("x\u{1}y\nz"), "x\\x01y&#10;z");
    }
}
