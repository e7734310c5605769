//! The report folder: `report.json`, `heatmap.png`, side-by-side crops of the worst regions
//! (candidate, golden, difference) and an `index.html` that shows them.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::heatmap::heatmap_image;
use super::{CandidateImage, CompareError, Comparison, Encoding, Golden};
use crate::escape::html;
use crate::image_io::{ImageError, Rgb8Image, write_atomically, write_png};

/// How many regions get crops.
const CROPS: usize = 6;
const GAP: usize = 4;

/// The JSON report (pretty-printed).
pub fn to_json(comparison: &Comparison) -> String {
    serde_json::to_string_pretty(comparison).expect("a comparison always serialises")
}

/// The crop `(x, y, w, h)` shown for a region: the region with an 8-pixel margin, at least
/// 24 pixels on a side, inside the image.
fn crop_box(r: &super::Region, w: usize, h: usize) -> (usize, usize, usize, usize) {
    let grow = |start: usize, len: usize, total: usize| {
        let len2 = (len + 16).max(24).min(total);
        let centre = start + len / 2;
        let s = centre.saturating_sub(len2 / 2).min(total - len2);
        (s, len2)
    };
    let (x, cw) = grow(r.x, r.width, w);
    let (y, ch) = grow(r.y, r.height, h);
    (x, y, cw, ch)
}

/// Candidate, golden and |difference| (x4, in codes) side by side, scaled up to about 300 pixels.
fn side_by_side(
    cand: &[u8],
    gold: &[u8],
    width: usize,
    (x0, y0, cw, ch): (usize, usize, usize, usize),
) -> Rgb8Image {
    let scale = (300 / cw.max(ch)).clamp(1, 8);
    let pw = cw * scale;
    let out_w = 3 * pw + 2 * GAP;
    let out_h = ch * scale;
    let mut data = vec![255u8; out_w * out_h * 3];
    for y in 0..out_h {
        for x in 0..out_w {
            let panel = x / (pw + GAP);
            let px = x % (pw + GAP);
            if px >= pw {
                continue;
            }
            let src = 3 * ((y0 + y / scale) * width + x0 + px / scale);
            let rgb: [u8; 3] = match panel {
                0 => [cand[src], cand[src + 1], cand[src + 2]],
                1 => [gold[src], gold[src + 1], gold[src + 2]],
                _ => {
                    let d = (0..3)
                        .map(|c| (cand[src + c] as i32 - gold[src + c] as i32).abs())
                        .max()
                        .unwrap_or(0);
                    let v = 255 - (4 * d).min(255) as u8;
                    [v, v, v]
                }
            };
            data[3 * (y * out_w + x)..3 * (y * out_w + x) + 3].copy_from_slice(&rgb);
        }
    }
    Rgb8Image {
        width: out_w,
        height: out_h,
        data,
    }
}

fn index_html(c: &Comparison, crops: &[(String, super::Region)]) -> String {
    let mut h = String::new();
    let verdict = if c.passed() { "PASS" } else { "FAIL" };
    let _ = write!(
        h,
        "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>rtoracle compare: {verdict}</title>\
         <style>body{{font-family:sans-serif;margin:2em}}td,th{{padding:2px 10px;text-align:right}}\
         img{{image-rendering:pixelated;border:1px solid #ccc}}</style></head><body>\n\
         <h1>{verdict}</h1>\n<p>{w}x{hh}, candidate {n} spp against a golden of {m} spp{scene}, \
         encoding {enc}, false-failure rate {alpha}.</p>\n",
        w = c.width,
        hh = c.height,
        n = c.candidate_spp,
        m = c.golden_spp,
        scene = c
            .scene
            .as_ref()
            .map(|s| format!(" ({})", html(s)))
            .unwrap_or_default(),
        enc = html(&c.encoding),
        alpha = c.alpha
    );
    if let Some(d) = &c.diagnosis {
        let _ = writeln!(h, "<h2>Diagnosis</h2><p><b>{}</b></p>", html(&d.summary));
    }
    h.push_str("<h2>Scales</h2><table><tr><th>scale</th><th>tests</th><th>smallest adjusted p</th><th>threshold</th><th>largest |z|</th><th>failing</th></tr>\n");
    for s in &c.scales {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{:.3e}</td><td>{:.1e}</td><td>{:.2}</td><td>{}</td></tr>",
            s.scale, s.tests, s.smallest_adjusted_p, s.threshold, s.largest_abs_z, s.failing
        );
    }
    let _ = writeln!(
        h,
        "</table><p>Bias (linear, R G B): {:+.5} {:+.5} {:+.5}. Effective spp: {}.</p>",
        c.bias[0],
        c.bias[1],
        c.bias[2],
        c.effective_spp
            .map_or_else(|| "unknown".to_string(), |n| format!("{n:.1}"))
    );
    h.push_str("<h2>Signed z (red: brighter than the golden, blue: darker; failing regions in green)</h2>\n<img src=\"heatmap.png\" alt=\"heatmap\">\n");
    if !crops.is_empty() {
        h.push_str("<h2>Worst regions: candidate, golden, |difference| x4</h2>\n");
        for (file, r) in crops {
            let _ = writeln!(
                h,
                "<p>x {} y {} ({}x{}), {} scale, channel {}, adjusted p {:.2e}, z {:+.1}<br><img src=\"{file}\" alt=\"{file}\"></p>",
                r.x, r.y, r.width, r.height, r.scale, r.channel, r.adjusted_p, r.z
            );
        }
    }
    h.push_str("<p>Report: <a href=\"report.json\">report.json</a></p></body></html>\n");
    h
}

/// Whether `name` is a file of a compare report folder.
fn is_report_file(name: &str) -> bool {
    matches!(name, "report.json" | "heatmap.png" | "index.html")
        || name
            .strip_prefix("region-")
            .and_then(|n| n.strip_suffix(".png"))
            .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
}

/// Checks, before any work, that `dir` may be replaced by a fresh report folder: missing, or a
/// folder holding only a compare report's files (so no file of the user's is removed).
pub fn check_report_dir(dir: &Path) -> Result<(), CompareError> {
    let dir = &resolve_link(dir);
    let bad = |message: String| CompareError::Input {
        path: dir.to_path_buf(),
        message,
    };
    match std::fs::symlink_metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(bad(format!("cannot be read ({})", e.kind()))),
        Ok(m) if !m.is_dir() => Err(bad("exists and is not a folder".into())),
        Ok(_) => {
            let entries = std::fs::read_dir(dir)
                .map_err(|e| bad(format!("cannot be read ({})", e.kind())))?;
            for e in entries.flatten() {
                let name = e.file_name().to_string_lossy().to_string();
                let file = e.file_type().map(|t| t.is_file()).unwrap_or(false);
                if !(file && is_report_file(&name)) {
                    return Err(bad(format!(
                        "holds {}, which is not part of a compare report; the folder is replaced whole, so choose an empty or new one",
                        crate::escape::terminal_line(&name)
                    )));
                }
            }
            Ok(())
        }
    }
}

/// Puts the finished folder `tmp` where `dest` is, whole: a missing `dest` is a rename; an
/// existing one is exchanged atomically with `renameat2`'s `RENAME_EXCHANGE` and the old one
/// removed (with `tmp`), so no file of an earlier run survives. Where the exchange is not
/// available, the old folder is renamed aside first and removed after.
pub fn swap_in(tmp: tempfile::TempDir, dest: &Path) -> std::io::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    if std::fs::symlink_metadata(dest).is_err() {
        let path = tmp.keep();
        return std::fs::rename(&path, dest).inspect_err(|_| {
            let _ = std::fs::remove_dir_all(&path);
        });
    }
    let c =
        |p: &Path| std::ffi::CString::new(p.as_os_str().as_bytes()).map_err(std::io::Error::other);
    let (a, b) = (c(tmp.path())?, c(dest)?);
    // SAFETY: two valid NUL-terminated paths; renameat2 only reads them.
    let rc = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            a.as_ptr(),
            libc::AT_FDCWD,
            b.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if rc == 0 {
        // `tmp` now holds the old folder: dropping it removes it.
        return Ok(());
    }
    let old = tmp.path().with_extension("old");
    if std::fs::rename(dest, &old).is_err() {
        // `dest` cannot be renamed (a mount point, say): empty it and copy the new folder in.
        return copy_into(tmp.path(), dest);
    }
    let path = tmp.keep();
    match std::fs::rename(&path, dest) {
        Ok(()) => {
            let _ = std::fs::remove_dir_all(&old);
            Ok(())
        }
        Err(e) => {
            let _ = std::fs::rename(&old, dest);
            let _ = std::fs::remove_dir_all(&path);
            Err(e)
        }
    }
}

/// Empties `dest` (already checked to hold only reports) and copies the files of `src`, and of
/// its folders one level down, into it.
fn copy_into(src: &Path, dest: &Path) -> std::io::Result<()> {
    for e in std::fs::read_dir(dest)?.flatten() {
        if e.file_type()?.is_dir() {
            std::fs::remove_dir_all(e.path())?;
        } else {
            std::fs::remove_file(e.path())?;
        }
    }
    for e in std::fs::read_dir(src)?.flatten() {
        let to = dest.join(e.file_name());
        if e.file_type()?.is_dir() {
            std::fs::create_dir(&to)?;
            for f in std::fs::read_dir(e.path())?.flatten() {
                std::fs::copy(f.path(), to.join(f.file_name()))?;
            }
        } else {
            std::fs::copy(e.path(), &to)?;
        }
    }
    Ok(())
}

/// `path`, or the folder it links to when it is a symbolic link (so swapping a folder in
/// replaces the folder, not the link).
pub fn resolve_link(path: &Path) -> PathBuf {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => path.canonicalize().unwrap_or_else(|_| path.into()),
        _ => path.to_path_buf(),
    }
}

/// Writes the report folder: built beside `dir` under a temporary name (removed on Ctrl-C or
/// SIGTERM) and swapped in whole, so it appears whole or not at all and nothing of an earlier
/// report (say a stale `region-7.png`) survives. An existing `dir` must pass
/// [`check_report_dir`].
pub fn write_report(
    dir: &Path,
    comparison: &Comparison,
    candidate: &CandidateImage,
    golden: &Golden,
    encoding: Encoding,
) -> Result<(), CompareError> {
    let io = |e: std::io::Error| {
        CompareError::Image(ImageError::Io {
            path: dir.to_path_buf(),
            message: e.to_string(),
        })
    };
    let dir = &resolve_link(dir);
    check_report_dir(dir)?;
    let parent = match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let tmp = tempfile::Builder::new()
        .prefix(".rtoracle-report-")
        .tempdir_in(parent)
        .map_err(io)?;
    let _cleanup = crate::interrupt::remove_on_interrupt(tmp.path());
    let target: PathBuf = tmp.path().to_path_buf();
    write_atomically(&target.join("report.json"), to_json(comparison).as_bytes())?;
    write_png(&target.join("heatmap.png"), &heatmap_image(comparison))?;
    let cand = candidate.to_rgb8(encoding);
    let gold: Vec<u8> = golden
        .mean
        .iter()
        .flat_map(|p| p.map(|x| encoding.encode(x)))
        .collect();
    let mut crops = Vec::new();
    for (k, r) in comparison.regions.iter().take(CROPS).enumerate() {
        let name = format!("region-{}.png", k + 1);
        let img = side_by_side(
            &cand,
            &gold,
            comparison.width,
            crop_box(r, comparison.width, comparison.height),
        );
        write_png(&target.join(&name), &img)?;
        crops.push((name, r.clone()));
    }
    write_atomically(
        &target.join("index.html"),
        index_html(comparison, &crops).as_bytes(),
    )?;
    {
        use std::os::unix::fs::PermissionsExt;
        let _ = std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o755));
    }
    swap_in(tmp, dir).map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder_with(parent: &Path, files: &[&str]) -> tempfile::TempDir {
        let t = tempfile::Builder::new().tempdir_in(parent).unwrap();
        for f in files {
            std::fs::write(t.path().join(f), f.as_bytes()).unwrap();
        }
        t
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().to_string())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn swapping_in_replaces_the_old_folder_whole_through_a_link_too() {
        let root = tempfile::tempdir().unwrap();
        let dest = root.path().join("rep");
        std::fs::create_dir(&dest).unwrap();
        std::fs::write(dest.join("region-7.png"), b"stale").unwrap();
        swap_in(folder_with(root.path(), &["report.json"]), &dest).unwrap();
        assert_eq!(names(&dest), ["report.json"]);
        // Only the new folder is left beside it.
        assert_eq!(names(root.path()), ["rep"]);
        // Through a symbolic link, the folder it points to is replaced and the link stays.
        let link = root.path().join("link");
        std::os::unix::fs::symlink(&dest, &link).unwrap();
        let target = resolve_link(&link);
        swap_in(folder_with(root.path(), &["index.html"]), &target).unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(names(&link), ["index.html"]);
    }

    #[test]
    fn copying_into_a_folder_that_cannot_be_renamed_leaves_only_the_new_files() {
        let root = tempfile::tempdir().unwrap();
        let dest = folder_with(root.path(), &["heatmap.png", "region-3.png"]);
        let src = folder_with(root.path(), &["report.json"]);
        std::fs::create_dir(src.path().join("sub")).unwrap();
        std::fs::write(src.path().join("sub/feedback.md"), b"x").unwrap();
        copy_into(src.path(), dest.path()).unwrap();
        assert_eq!(names(dest.path()), ["report.json", "sub"]);
        assert_eq!(names(&dest.path().join("sub")), ["feedback.md"]);
    }

    #[test]
    fn only_a_compare_report_may_be_replaced() {
        let root = tempfile::tempdir().unwrap();
        let ok = folder_with(
            root.path(),
            &["report.json", "heatmap.png", "region-12.png"],
        );
        assert!(check_report_dir(ok.path()).is_ok());
        assert!(check_report_dir(&root.path().join("new")).is_ok());
        let mine = folder_with(root.path(), &["report.json", "region-x.png"]);
        let e = check_report_dir(mine.path()).unwrap_err().to_string();
        assert!(e.contains("holds region-x.png"), "{e}");
    }
}
