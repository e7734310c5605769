//! A batch's submissions compared with each other: the pairs whose images of one group share
//! their Monte Carlo noise ([`copies::shared_noise`](crate::grade::checkers::copies::shared_noise)) are flagged for
//! review in both reports and in the batch's summary.

use std::collections::BTreeMap;
use std::sync::Arc;

use crate::grade::checkers::copies::{CopyFinding, Fingerprint, NoiseMatch, shared_noise};
use crate::grade::result::GradeReport;

/// Two submissions of a batch whose images of one group share their noise.
#[derive(Clone, Debug, PartialEq)]
pub struct SharedPair {
    /// The image group's id.
    pub group: String,
    /// The two submissions, by name, in batch order.
    pub submissions: [crate::escape::Untrusted; 2],
    /// How their noise compares.
    pub noise: NoiseMatch,
}

/// Compares the images of every two `reports` (named), group by group, and records in both
/// reports each pair that shares its noise (a [`CopyFinding::SharedWith`] on the image check,
/// and a sentence in its message). Returns the pairs, in batch order.
pub fn flag_shared_noise(reports: &mut [(&str, &mut GradeReport)]) -> Vec<SharedPair> {
    let mut groups: BTreeMap<String, Vec<(usize, Arc<Fingerprint>)>> = BTreeMap::new();
    for (i, (_, r)) in reports.iter().enumerate() {
        for (g, fp) in &r.fingerprints {
            groups.entry(g.clone()).or_default().push((i, fp.clone()));
        }
    }
    let mut pairs = Vec::new();
    for (group, prints) in &groups {
        for (x, (i, a)) in prints.iter().enumerate() {
            for (j, b) in &prints[x + 1..] {
                let noise = shared_noise(a, b);
                if noise.shared {
                    pairs.push((group.clone(), *i, *j, noise));
                }
            }
        }
    }
    let mut out = Vec::new();
    for (group, i, j, noise) in pairs {
        let names = [
            crate::escape::Untrusted::from(reports[i].0),
            crate::escape::Untrusted::from(reports[j].0),
        ];
        for (me, other) in [(i, &names[1]), (j, &names[0])] {
            let finding = CopyFinding::SharedWith {
                submission: other.clone(),
                noise,
            };
            add_finding(reports[me].1, &group, finding);
        }
        out.push(SharedPair {
            group,
            submissions: names,
            noise,
        });
    }
    out
}

/// Adds `finding` to the image check of `group` in `report` (the sentence once per check).
fn add_finding(report: &mut GradeReport, group: &str, finding: CopyFinding) {
    let Some(check) = report.checks.iter_mut().find(|c| c.group == group) else {
        return;
    };
    let Some(image) = check.image.as_mut() else {
        return;
    };
    if !image.copies.iter().any(|c| !c.zeroes()) {
        let sentence = finding.sentence(&image.file);
        check.message.push_str(&format!(" {sentence}"));
    }
    image.copies.push(finding);
}
