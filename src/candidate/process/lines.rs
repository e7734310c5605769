//! The strict protocol, line by line: what one stdout line means for the case the session is
//! waiting for (`meaning`), and how stray lines are kept, bounded (`push_junk`).
//!
//! Every line is judged against the case waited for:
//! - its valid answer settles it; stray lines before it make it a `protocol` error;
//! - a malformed answer carrying its id (or no id), an answer with an id that is not in the
//!   run, or an oversize line settle it at once as a `protocol` error;
//! - an answer for a case already settled (late, or a duplicate) is stray output of the case
//!   waited for, which keeps waiting for its own answer;
//! - an answer for a later case settles the waited case as a `protocol` error (answers come in
//!   request order) and is kept for that later case.

use std::collections::HashMap;

use crate::candidate::process::protocol::{Answer, ParsedLine, quote_line};
use crate::oracle::vectors::Case;

/// Bytes of stray output quoted over one session; past it stray lines are counted, not kept.
pub const RUN_JUNK_BYTES: usize = 64 * 1024;

/// Most stray lines quoted for one case; the rest are counted.
pub(crate) const MAX_JUNK_LINES: usize = 8;

/// Records a stray line (already quoted and capped), keeping memory bounded however much a
/// candidate prints: at most [`MAX_JUNK_LINES`] per case and [`RUN_JUNK_BYTES`] per session
/// (`budget` holds what is left of it).
pub(crate) fn push_junk(junk: &mut Vec<String>, line: String, budget: &mut usize) {
    if junk.len() < MAX_JUNK_LINES && line.len() <= *budget {
        *budget -= line.len();
        junk.push(line);
    } else if junk.last().map(String::as_str) != Some(MORE_JUNK) {
        junk.push(MORE_JUNK.into());
    }
}

/// A line that is stray output where it came, in words.
pub(crate) fn describe_line(line: ParsedLine) -> String {
    match line {
        ParsedLine::Junk(text) => text,
        ParsedLine::Hello(_) => "another hello".into(),
        ParsedLine::BadHello(problem) => format!("a line like a hello ({problem})"),
        ParsedLine::Answer { id, .. } => format!("an answer for {}", quote_line(&id)),
        ParsedLine::Malformed { quoted, .. } => quoted,
        ParsedLine::Result { id, .. } => format!("a function's answer for {}", quote_line(&id)),
    }
}

/// The note that ends a case's stray lines when some were not kept.
pub(crate) const MORE_JUNK: &str = "(more lines not shown)";

/// What a line means for the case waited for.
#[derive(Debug)]
pub(crate) enum Meaning {
    /// Its answer, with the quoted text that preceded it on the line (empty when clean).
    Own {
        /// The answer.
        answer: Answer,
        /// Junk before it on the same line.
        prefix: String,
    },
    /// A protocol error that settles the case at once.
    Protocol(String),
    /// The answer to the later case at `later`: the waited case is a protocol error
    /// (`message`), and the answer is kept for that case.
    Early {
        /// The later case's index.
        later: usize,
        /// Its answer.
        answer: Answer,
        /// Junk before it on the same line.
        prefix: String,
        /// The waited case's protocol error.
        message: String,
    },
    /// Stray output, in words: the case keeps waiting.
    Stray(String),
}

/// What `line` means for `case`, the `i`-th of the run. `index` maps each id to its first case,
/// and `settled(k)` says whether case `k` has its outcome already.
pub(crate) fn meaning(
    line: ParsedLine,
    case: &Case,
    i: usize,
    index: &HashMap<&str, usize>,
    settled: impl Fn(usize) -> bool,
) -> Meaning {
    match line {
        ParsedLine::Answer { id, answer, junk } if id == case.id => Meaning::Own {
            answer,
            prefix: junk,
        },
        ParsedLine::Result { id, .. } if id == case.id => {
            Meaning::Protocol("a function's answer (\"result\") to an intersection request".into())
        }
        ParsedLine::Malformed {
            id,
            problem,
            quoted,
        } if id.is_none() || id.as_deref() == Some(case.id.as_str()) => Meaning::Protocol(format!(
            "a malformed answer ({problem}): the line was {quoted}"
        )),
        ParsedLine::Answer { id, .. } | ParsedLine::Malformed { id: Some(id), .. }
            if index.get(id.as_str()).is_some_and(|&k| settled(k)) =>
        {
            Meaning::Stray(format!("a second answer for {}", quote_line(&id)))
        }
        ParsedLine::Answer { id, answer, junk }
            if index.get(id.as_str()).is_some_and(|&k| k > i) =>
        {
            Meaning::Early {
                later: index[id.as_str()],
                answer,
                prefix: junk,
                message: format!(
                    "no answer to this request before the answer for the later request {} \
                     (answers come in request order)",
                    quote_line(&id)
                ),
            }
        }
        ParsedLine::Answer { id, answer, .. } => {
            let line = serde_json::to_string(&answer).unwrap_or_default();
            Meaning::Protocol(format!(
                "an answer with id {} instead of {}: {}",
                quote_line(&id),
                quote_line(&case.id),
                quote_line(&line)
            ))
        }
        ParsedLine::Malformed {
            id: Some(id),
            problem,
            quoted,
        } => Meaning::Protocol(format!(
            "a malformed answer with id {} instead of {} ({problem}): the line was {quoted}",
            quote_line(&id),
            quote_line(&case.id)
        )),
        other => Meaning::Stray(describe_line(other)),
    }
}

/// The protocol error of a line over `max_bytes` that began with `head` (quoted).
pub(crate) fn oversize_message(head: &str, max_bytes: usize) -> String {
    format!(
        "a line longer than {} MiB (answer lines are at most that): it began {head}",
        max_bytes >> 20
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::candidate::process::protocol::MAX_QUOTE_CHARS;

    #[test]
    fn stray_output_is_quoted_briefly_and_bounded() {
        let mut junk = Vec::new();
        let mut left = RUN_JUNK_BYTES;
        for _ in 0..1000 {
            push_junk(&mut junk, quote_line(&"x".repeat(10_000)), &mut left);
        }
        assert_eq!(junk.len(), MAX_JUNK_LINES + 1);
        assert_eq!(junk[0].len(), MAX_QUOTE_CHARS + 5);
        assert_eq!(junk[MAX_JUNK_LINES], MORE_JUNK);
        // Over a session: once the total is used up, lines are only counted.
        let mut left = 3 * (MAX_QUOTE_CHARS + 5);
        let mut kept = 0;
        for _ in 0..100 {
            let mut junk = Vec::new();
            push_junk(&mut junk, quote_line(&"y".repeat(500)), &mut left);
            kept += (junk[0] != MORE_JUNK) as usize;
        }
        assert_eq!(kept, 3);
    }
}
