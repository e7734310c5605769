//! The sandbox's own paths in what its code says, told in the user's terms: [`replace_path`].

use std::path::Path;

/// `text` with the path `from` replaced by `to` where it starts a path (not inside a longer
/// one: `/sandbox/x.py` is replaced, `/work/sandbox/x.py` and `/sandboxes` are not).
pub fn replace_path(text: &str, from: &Path, to: &str) -> String {
    let from = from.display().to_string();
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find(&from) {
        let before = rest[..i].chars().next_back();
        let after = rest[i + from.len()..].chars().next();
        let path_char = |c: char| c.is_alphanumeric() || "._-/~".contains(c);
        let starts = before.is_none_or(|c| !path_char(c));
        let ends = after.is_none_or(|c| c == '/' || !path_char(c));
        out.push_str(&rest[..i]);
        out.push_str(if starts && ends { to } else { &from });
        rest = &rest[i + from.len()..];
    }
    out.push_str(rest);
    out
}
