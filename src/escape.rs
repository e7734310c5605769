//! Untrusted text stays text: escaping for every format that text a submission or candidate
//! controls can reach (exception messages, tracebacks, stderr, file and folder names).
//!
//! One function per format family, used by every writer (never escaping at the call sites):
//! - the terminal: [`terminal_line`], [`terminal_text`]: control characters (ANSI escapes
//!   included) are shown as `\x1b`, never sent;
//! - Markdown (`feedback.md`, `summary.md`, Gradescope's `output`): [`markdown_block`] puts text
//!   in a fenced block whose fence is longer than any backtick run inside, so nothing can close
//!   it; [`markdown_inline`] for a name inside a sentence (backslash-escapes every punctuation
//!   mark Markdown gives a meaning to, and `<` `>` `&` as HTML entities, so no link, emphasis,
//!   heading or tag survives);
//! - HTML: [`html`];
//! - CSV (`gradebook.csv`): [`csv_cell`] quotes per RFC 4180 and defuses formulas (a cell starting
//!   with `=`, `+`, `-`, `@`, tab or carriage return is prefixed with `'`, as OWASP advises);
//! - XML (JUnit) keeps its own writer in `grade::report::junit`, which already drops what XML
//!   forbids and escapes the rest.
//!
//! No function here bounds length: caps belong to the harness that keeps the text ([`truncate`]
//! helps it).

use std::fmt::Write;

/// Writes `c` as `\xHH` (or `\u{HHHH}` above U+00FF).
fn push_escaped(out: &mut String, c: char) {
    let n = c as u32;
    if n <= 0xff {
        let _ = write!(out, "\\x{n:02x}");
    } else {
        let _ = write!(out, "\\u{{{n:04x}}}");
    }
}

/// Whether `c` is a control character or one that changes how text is laid out or read
/// (C0, DEL, C1, bidirectional overrides and isolates, zero-width and line/paragraph separators).
fn is_control(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{200b}'..='\u{200f}' | '\u{2028}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{feff}'
        )
}

/// Text for one line of a terminal: every control character, newline and tab included, is
/// written as an escape (`\x1b`, `\x0a`), so nothing can move the cursor, change colours or
/// start a new line that looks like the tool's own.
pub fn terminal_line(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if is_control(c) {
            push_escaped(&mut out, c);
        } else {
            out.push(c);
        }
    }
    out
}

/// Text of several lines for a terminal (a traceback): newlines and tabs are kept, every other
/// control character is escaped as in [`terminal_line`]. A carriage return is escaped too (it
/// could overwrite the start of the line).
pub fn terminal_text(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if c == '\n' || c == '\t' || !is_control(c) {
            out.push(c);
        } else {
            push_escaped(&mut out, c);
        }
    }
    out
}

/// The longest run of `ch` in `s`.
fn longest_run(s: &str, ch: char) -> usize {
    let (mut best, mut run) = (0, 0);
    for c in s.chars() {
        if c == ch {
            run += 1;
            best = best.max(run);
        } else {
            run = 0;
        }
    }
    best
}

/// A fenced Markdown code block holding `s` verbatim (control characters escaped as in
/// [`terminal_text`]): the fence is made of backticks, one longer than the longest run of
/// backticks inside and at least three, so no line of `s` can
/// close it. `info` is the info string (a language name, or empty); it is reduced to ASCII
/// letters, digits and `-`. The result ends with a newline.
pub fn markdown_block(s: &str, info: &str) -> String {
    let body = terminal_text(s);
    let fence = "`".repeat((longest_run(&body, '`') + 1).max(3));
    let info: String = info
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || *c == '-')
        .collect();
    let mut out = String::with_capacity(body.len() + 2 * fence.len() + 8);
    out.push_str(&fence);
    out.push_str(&info);
    out.push('\n');
    out.push_str(&body);
    if !body.ends_with('\n') {
        out.push('\n');
    }
    out.push_str(&fence);
    out.push('\n');
    out
}

/// Text for use inside a Markdown sentence, a heading or a table cell (a file name, a one-line
/// message): one line (control characters and newlines escaped as in [`terminal_line`]) that
/// renders as the same characters in CommonMark and GitHub's Markdown, and reads as they are in
/// a renderer that shows backslashes (Python-Markdown's plain fallback, Gradescope's text): only
/// what would change the rendering is escaped, nothing else.
///
/// - `<`, `>`, `&` become HTML entities (no tag, autolink or entity);
/// - a backslash before a backslash; `` ` ``, `*`, `~`, `[`, `]`, `|` and `$` after one (no
///   code span, emphasis, strikethrough, link or image, table cell, math), and `_` unless it
///   sits between two letters or digits (`RT_object.py` stays as it is);
/// - `#` after one at the start or after a space (no heading, nor a heading's closing `#`s);
///   `-`, `+`, `=` and an ordered list's `1.` / `1)` after one at the start (no list or setext
///   line when the text begins a line);
/// - the `:` of `://` and the `.` of `www.` after one, so a URL in the text does not become an
///   extended autolink.
///
/// Everything else (`.`, `-` or `+` inside a word, `(`, `)`, `=`, `:`, quotes, `!`) stays as it
/// is: with `[` and `]` escaped nothing else can make a link.
pub fn markdown_inline(s: &str) -> String {
    let line = terminal_line(s);
    let chars: Vec<char> = line.chars().collect();
    let mut out = String::with_capacity(line.len() + 8);
    // Where the text starts (after leading spaces): list markers and headings matter there.
    let start = chars.iter().position(|c| *c != ' ').unwrap_or(chars.len());
    let ordered_marker = {
        let digits = chars[start..]
            .iter()
            .take_while(|c| c.is_ascii_digit())
            .count();
        (digits > 0 && matches!(chars.get(start + digits), Some('.' | ')')))
            .then_some(start + digits)
    };
    for (i, &c) in chars.iter().enumerate() {
        let escape = match c {
            '<' => {
                out.push_str("&lt;");
                continue;
            }
            '>' => {
                out.push_str("&gt;");
                continue;
            }
            '&' => {
                out.push_str("&amp;");
                continue;
            }
            // Between two letters or digits `_` is text (no emphasis starts or ends there).
            '_' => {
                !(i > 0
                    && chars[i - 1].is_alphanumeric()
                    && chars.get(i + 1).is_some_and(|n| n.is_alphanumeric()))
            }
            '\\' | '`' | '*' | '~' | '[' | ']' | '|' | '$' => true,
            '#' => i == start || chars[i - 1] == ' ',
            '-' | '+' | '=' => i == start,
            '.' | ')' if Some(i) == ordered_marker => true,
            ':' => chars.get(i + 1) == Some(&'/') && chars.get(i + 2) == Some(&'/'),
            '.' => {
                i >= 3
                    && chars[i - 3..i]
                        .iter()
                        .zip("www".chars())
                        .all(|(a, b)| a.to_ascii_lowercase() == b)
            }
            _ => false,
        };
        if escape {
            out.push('\\');
        }
        out.push(c);
    }
    out
}

/// Text for HTML element content or a quoted attribute value: `& < > " '` as entities and
/// control characters escaped as in [`terminal_text`] (newlines kept).
pub fn html(s: &str) -> String {
    let text = terminal_text(s);
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// One CSV cell (RFC 4180): a cell that a spreadsheet would read as a formula (it starts with
/// `=`, `+`, `-`, `@`, a tab or a carriage return) gets a leading `'`; control characters other
/// than newline are escaped; a cell holding a comma, a quote or a newline, or that was defused,
/// is quoted with quotes doubled.
pub fn csv_cell(s: &str) -> String {
    let mut text = String::with_capacity(s.len() + 2);
    if s.starts_with(['=', '+', '-', '@', '\t', '\r']) {
        text.push('\'');
    }
    for c in s.chars() {
        if c == '\n' || !is_control(c) {
            text.push(c);
        } else {
            push_escaped(&mut text, c);
        }
    }
    if text.contains([',', '"', '\n']) || text.starts_with('\'') {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text
    }
}

/// `s` cut to at most `max_bytes` bytes on a character boundary, with a note of how much was
/// left out (`... [12345 more bytes]`) when it was cut.
pub fn truncate(s: &str, max_bytes: usize) -> String {
    if s.len() <= max_bytes {
        return s.to_string();
    }
    let mut end = max_bytes;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}... [{} more bytes]", &s[..end], s.len() - end)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terminal_line_shows_escapes_instead_of_sending_them() {
        assert_eq!(
            terminal_line("a\x1b[31mred\nb\r"),
            "a\\x1b[31mred\\x0ab\\x0d"
        );
        assert_eq!(terminal_line("\u{202e}evil"), "\\u{202e}evil");
        assert_eq!(terminal_line("plain é"), "plain é");
    }

    #[test]
    fn terminal_text_keeps_lines() {
        assert_eq!(terminal_text("a\n\tb\x07"), "a\n\tb\\x07");
    }

    #[test]
    fn markdown_block_cannot_be_closed_from_inside() {
        let evil = "boom\n```\n# Score: 100 / 100\n````more";
        let block = markdown_block(evil, "text");
        let fence = block.lines().next().unwrap().trim_end_matches("text");
        assert_eq!(fence, "`````");
        // No line inside starts with a run of backticks as long as the fence.
        let inner: Vec<&str> = block.lines().collect();
        let inner = &inner[1..inner.len() - 1];
        assert!(inner.iter().all(|l| !l.starts_with(fence)));
        assert!(block.ends_with("`````\n"));
    }

    #[test]
    fn markdown_inline_defuses_links_headings_and_html() {
        let s = markdown_inline("# [x](http://e) <b>&");
        assert_eq!(s, "\\# \\[x\\](http\\://e) &lt;b&gt;&amp;");
        assert!(!markdown_inline("a\nb").contains('\n'));
        assert_eq!(markdown_inline("- a"), "\\- a");
        assert_eq!(markdown_inline("12. a"), "12\\. a");
        assert_eq!(markdown_inline("see www.e.org"), "see www\\.e.org");
        assert_eq!(markdown_inline("a # b #"), "a \\# b \\#");
        assert_eq!(markdown_inline("RT_object.py _x_"), "RT_object.py \\_x\\_");
        assert_eq!(
            markdown_inline("*x* _y_ `z` ~w~ a|b $m$ \\"),
            "\\*x\\* \\_y\\_ \\`z\\` \\~w\\~ a\\|b \\$m\\$ \\\\"
        );
    }

    #[test]
    fn html_escapes_markup() {
        assert_eq!(
            html("<a href='x'>&\"</a>"),
            "&lt;a href=&#39;x&#39;&gt;&amp;&quot;&lt;/a&gt;"
        );
    }

    #[test]
    fn csv_cells_are_quoted_and_formulas_defused() {
        assert_eq!(csv_cell("plain"), "plain");
        assert_eq!(csv_cell("a,b"), "\"a,b\"");
        assert_eq!(csv_cell("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(
            csv_cell("=HYPERLINK(\"http://e\",\"x\")"),
            "\"'=HYPERLINK(\"\"http://e\"\",\"\"x\"\")\""
        );
        assert_eq!(csv_cell("-1"), "\"'-1\"");
        assert_eq!(csv_cell("@x"), "\"'@x\"");
        assert_eq!(csv_cell("a\x1bb"), "a\\x1bb");
    }

    #[test]
    fn truncate_cuts_on_a_character_boundary() {
        assert_eq!(truncate("abc", 3), "abc");
        assert_eq!(truncate("ééé", 3), "é... [4 more bytes]");
    }
}
