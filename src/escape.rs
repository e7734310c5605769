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
//! - XML (JUnit): [`xml`], for element content and quoted attribute values;
//! - JSON: serde's writer (every candidate text is a JSON string value).
//!
//! **One door.** Text that comes from a candidate is kept as [`Untrusted`]: it has no `Display`,
//! no `Deref` and no way to be read as a `&str` for output; it can only be written out through
//! one of its methods, each escaping it for one format (or serialised, which escapes it for
//! JSON). A new report path that forgets to escape does not compile. The result model keeps as
//! `Untrusted` what a submission names or says, whole: its folder's name, each check's message
//! (a render's exception, a copy finding, the code's error), each failing vector's message,
//! why its code could not run and what it wrote to stderr
//! (`tests/integration/attacks/hostile.rs` sends a hostile payload through every path into every
//! format).
//!
//! No function here bounds length: caps belong to the harness that keeps the text ([`truncate`]
//! helps it).

use std::fmt::Write;

use serde::{Deserialize, Serialize};

/// Text a candidate controls (a submission's folder name, an exception's message, a message
/// quoting what the code answered): it can only be written out escaped for a format, through
/// its methods, or serialised (a JSON string, escaped by the JSON writer). Made from any string
/// (`From`); compared, searched and measured without being written out.
#[derive(Clone, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Untrusted(String);

impl From<String> for Untrusted {
    fn from(s: String) -> Self {
        Untrusted(s)
    }
}

impl From<&str> for Untrusted {
    fn from(s: &str) -> Self {
        Untrusted(s.to_string())
    }
}

impl Untrusted {
    /// The text for one line of a terminal ([`terminal_line`]).
    pub fn terminal_line(&self) -> String {
        terminal_line(&self.0)
    }

    /// The text for a terminal, lines kept ([`terminal_text`]).
    pub fn terminal_text(&self) -> String {
        terminal_text(&self.0)
    }

    /// The text inside a Markdown sentence ([`markdown_inline`]).
    pub fn markdown_inline(&self) -> String {
        markdown_inline(&self.0)
    }

    /// The text as a fenced Markdown block ([`markdown_block`]).
    pub fn markdown_block(&self, info: &str) -> String {
        markdown_block(&self.0, info)
    }

    /// The text for HTML ([`html`]).
    pub fn html(&self) -> String {
        html(&self.0)
    }

    /// The text as one CSV cell ([`csv_cell`]).
    pub fn csv_cell(&self) -> String {
        csv_cell(&self.0)
    }

    /// The text for XML ([`xml`]).
    pub fn xml(&self) -> String {
        xml(&self.0)
    }

    /// The text as a file or folder name, for the file system only (never for a report): a
    /// batch's submission folders are named by it.
    pub fn as_file_name(&self) -> &str {
        &self.0
    }

    /// Whether it is `s`.
    pub fn is(&self, s: &str) -> bool {
        self.0 == s
    }

    /// Whether it holds `s`.
    pub fn contains(&self, s: &str) -> bool {
        self.0.contains(s)
    }

    /// Whether it starts with `s`.
    pub fn starts_with(&self, s: &str) -> bool {
        self.0.starts_with(s)
    }

    /// Whether it ends with `s`.
    pub fn ends_with(&self, s: &str) -> bool {
        self.0.ends_with(s)
    }

    /// Whether it is empty.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Its length in bytes.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// The text without the prefix `s`, when it starts with it.
    pub fn strip_prefix(&self, s: &str) -> Option<Untrusted> {
        self.0.strip_prefix(s).map(Untrusted::from)
    }

    /// Appends `s` (the harness's words): the whole stays untrusted.
    pub fn push_str(&mut self, s: &str) {
        self.0.push_str(s);
    }

    /// Appends `more`.
    pub fn push(&mut self, more: &Untrusted) {
        self.0.push_str(&more.0);
    }

    /// Its lines (without their newlines), each still untrusted.
    pub fn lines(&self) -> Vec<Untrusted> {
        self.0.lines().map(Untrusted::from).collect()
    }

    /// The text without whitespace at its end.
    pub fn trim_end(&self) -> Untrusted {
        Untrusted::from(self.0.trim_end())
    }

    /// The text without the untrusted suffix `s`, when it ends with it.
    pub fn strip_suffix_of(&self, s: &Untrusted) -> Option<Untrusted> {
        self.strip_suffix(&s.0)
    }

    /// The text without the suffix `s`, when it ends with it.
    pub fn strip_suffix(&self, s: &str) -> Option<Untrusted> {
        self.0.strip_suffix(s).map(Untrusted::from)
    }

    /// Its first line (without the newline), still untrusted.
    pub fn first_line(&self) -> Untrusted {
        Untrusted::from(self.0.lines().next().unwrap_or(""))
    }

    /// The text cut to at most `max_bytes` ([`truncate`]).
    pub fn truncated(&self, max_bytes: usize) -> Untrusted {
        Untrusted(truncate(&self.0, max_bytes))
    }

    /// This text, then `more` (the harness's words or the candidate's), all of it untrusted.
    pub fn join(&self, sep: &str, more: &Untrusted) -> Untrusted {
        Untrusted(format!("{}{sep}{}", self.0, more.0))
    }
}

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

/// Text for XML element content or a quoted attribute value (JUnit): `& < > " '` as entities,
/// newline, tab and carriage return as character references, and every other control
/// character (C0, DEL, C1, bidirectional and zero-width controls) shown as `\x1b` or
/// `\u{202e}` (as [`terminal_text`] does), so nothing XML forbids is written and no viewer
/// reorders or hides text.
pub fn xml(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' | '\t' | '\r' => {
                let _ = write!(out, "&#{};", c as u32);
            }
            '\u{fffe}' | '\u{ffff}' => push_escaped(&mut out, c),
            c if is_control(c) => push_escaped(&mut out, c),
            c => out.push(c),
        }
    }
    out
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
    fn xml_escapes_markup_and_shows_controls() {
        assert_eq!(xml("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&apos;");
        assert_eq!(
            xml("x\u{1}y\nz\u{1b}[2J\u{202e}\u{0}"),
            "x\\x01y&#10;z\\x1b[2J\\u{202e}\\x00"
        );
    }

    #[test]
    fn untrusted_text_is_written_only_escaped() {
        let t = Untrusted::from("# Score: 100 / 100\n<img onerror=x>\u{1b}[31m");
        assert_eq!(
            t.terminal_line(),
            "# Score: 100 / 100\\x0a<img onerror=x>\\x1b[31m"
        );
        assert!(!t.markdown_inline().contains('<') && t.markdown_inline().starts_with("\\#"));
        assert!(!t.html().contains('<'));
        assert!(!t.xml().contains('<'));
        assert_eq!(Untrusted::from("=1").csv_cell(), "\"'=1\"");
        // JSON: a string, escaped by the JSON writer.
        assert_eq!(
            serde_json::to_string(&t).unwrap(),
            "\"# Score: 100 / 100\\n<img onerror=x>\\u001b[31m\""
        );
        assert!(t.starts_with("# Score") && t.contains("onerror") && !t.is("x"));
    }

    #[test]
    fn truncate_cuts_on_a_character_boundary() {
        assert_eq!(truncate("abc", 3), "abc");
        assert_eq!(truncate("ééé", 3), "é... [4 more bytes]");
    }
}
