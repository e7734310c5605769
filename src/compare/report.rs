//! The report folder: `report.json`; `candidate.png`, `golden.png` and `difference.png` (the
//! whole images, shown at the same scale, the worst regions boxed on the candidate);
//! `heatmap.png` (each channel's signed z); side-by-side crops of the worst regions (candidate,
//! golden, difference); and an `index.html` that shows them with their legends, the candidate's
//! name, the diagnosis and the noise check in words. It is an
//! [`OutputDir`]: checked before any work (an existing folder must hold only a compare report's
//! files, [`REPORT_FOLDER`]), built beside its place and swapped in whole (see
//! [`crate::output`]).

use std::fmt::Write as _;
use std::path::Path;

use super::heatmap::heatmap_image;
use super::{
    CompareError, Comparison, candidate::CandidateImage, encoding::Encoding, noise_model::Golden,
};
use crate::escape::html;
use crate::image_io::{Rgb8Image, encode_png};
use crate::output::{OutputDir, OutputError, Replaceable};

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
                    let v = difference_shade(&cand[src..src + 3], &gold[src..src + 3]);
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

/// Pixels a thumbnail is shown wide: the image's width up to 320, small images enlarged by a
/// whole factor to at least 160.
fn thumb_width(w: usize) -> usize {
    if w >= 160 {
        w.min(320)
    } else {
        w * 160usize.div_ceil(w)
    }
}

/// Scales an image coordinate to the thumbnail's, in CSS pixels.
fn scaled(v: usize, w: usize) -> String {
    format!("{:.1}", v as f64 * thumb_width(w) as f64 / w as f64)
}

const STYLE: &str = "body{font-family:sans-serif;margin:1.5em;max-width:1150px}\
td,th{padding:2px 10px;text-align:right}\
img{image-rendering:pixelated;border:1px solid #ccc}\
.row{display:flex;gap:12px;flex-wrap:wrap;align-items:flex-start}\
figure{margin:0}figcaption{font-size:90%;text-align:center}\
.thumb{position:relative}.thumb img{display:block}\
.box{position:absolute;border:2px solid #0a0;box-sizing:border-box}\
.box span{position:absolute;top:-1.3em;left:0;color:#0a0;font-weight:bold;font-size:80%}\
.legend{display:flex;align-items:center;gap:8px;font-size:90%;margin:6px 0}\
.bar{display:inline-block;width:220px;height:14px;border:1px solid #999}";

/// The three thumbnails (candidate with the listed regions boxed, golden, |difference|) at the
/// same scale, and the difference's legend.
fn thumbnails(h: &mut String, c: &Comparison, boxed: &[(String, super::Region)]) {
    let (w, tw) = (c.width, thumb_width(c.width));
    let th = scaled(c.height, w);
    let _ = write!(
        h,
        "<h2>The images</h2>\n<div class=\"row\">\n<figure><div class=\"thumb\" style=\"width:{tw}px;height:{th}px\">\
         <img src=\"candidate.png\" alt=\"the candidate\" width=\"{tw}\">"
    );
    for (k, (_, r)) in boxed.iter().enumerate() {
        let _ = write!(
            h,
            "<div class=\"box\" data-region=\"{},{},{},{}\" style=\"left:{}px;top:{}px;width:{}px;height:{}px\"><span>{}</span></div>",
            r.x,
            r.y,
            r.width,
            r.height,
            scaled(r.x, w),
            scaled(r.y, w),
            scaled(r.width, w),
            scaled(r.height, w),
            k + 1
        );
    }
    let _ = write!(
        h,
        "</div><figcaption>candidate{}</figcaption></figure>\n\
         <figure><img src=\"golden.png\" alt=\"the golden\" width=\"{tw}\"><figcaption>golden ({} spp)</figcaption></figure>\n\
         <figure><img src=\"difference.png\" alt=\"the difference\" width=\"{tw}\"><figcaption>|difference| x4</figcaption></figure>\n</div>\n",
        if boxed.is_empty() {
            String::new()
        } else {
            " (the worst regions boxed, numbered as below)".to_string()
        },
        c.golden_spp
    );
    h.push_str(DIFFERENCE_LEGEND);
}

/// The legend of every |difference| picture.
const DIFFERENCE_LEGEND: &str = "<div class=\"legend\" id=\"difference-legend\">|difference| x4: the largest of the three channels' differences in 8-bit codes, times 4. \
<span>white: equal</span><span class=\"bar\" style=\"background:linear-gradient(to right,#fff,#000)\"></span><span>black: 64 codes or more apart (of 255)</span></div>\n";

/// The heatmap and its legend.
fn heatmap_section(h: &mut String, c: &Comparison) {
    use super::heatmap::{HIGHER, LOWER, SATURATE};
    let rgb = |c: [u8; 3]| format!("rgb({},{},{})", c[0], c[1], c[2]);
    let tw = 3 * thumb_width(c.width);
    let _ = write!(
        h,
        "<h2>Where and how each channel differs</h2>\n<p>Each map is one channel's signed z: the candidate minus the golden, over the noise that \
         {n} samples and the golden's allow. White is within noise; failing regions are outlined in green.</p>\n\
         <figure><img src=\"heatmap.png\" alt=\"the signed z of the red, green and blue channels\" width=\"{tw}\">\
         <figcaption style=\"display:flex;justify-content:space-around\"><span>red channel</span><span>green channel</span><span>blue channel</span></figcaption></figure>\n\
         <div class=\"legend\" id=\"z-legend\"><span>z &le; -{s}: the candidate lower</span>\
         <span class=\"bar\" style=\"background:linear-gradient(to right,{lo},#fff,{hi})\"></span>\
         <span>z &ge; +{s}: the candidate higher</span></div>\n",
        n = c.candidate_spp,
        s = SATURATE,
        lo = rgb(LOWER),
        hi = rgb(HIGHER),
    );
}

fn index_html(c: &Comparison, crops: &[(String, super::Region)]) -> String {
    let mut h = String::new();
    let verdict = if c.passed() { "PASS" } else { "FAIL" };
    let name = c
        .candidate
        .as_deref()
        .map(|n| format!(": {}", html(n)))
        .unwrap_or_default();
    let _ = write!(
        h,
        "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>rtoracle compare: {verdict}{name}</title>\
         <style>{STYLE}</style></head><body>\n\
         <h1>{verdict}{name}</h1>\n<p>{w}x{hh}, candidate {n} spp against a golden of {m} spp{scene}, \
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
        let _ = writeln!(
            h,
            "<p id=\"diagnosis\">Diagnosis: <b>{}</b></p>",
            html(&d.summary)
        );
    }
    let _ = writeln!(h, "<p id=\"noise\">{}</p>", html(&c.noise_sentence()));
    thumbnails(&mut h, c, crops);
    heatmap_section(&mut h, c);
    if !crops.is_empty() {
        let _ = writeln!(
            h,
            "<h2>The worst regions: candidate, golden, |difference| x4</h2>\n<p>{} failing regions in all, ranked by how much they show (evidence over their area, distinct places first).</p>",
            c.regions_total.max(c.regions.len())
        );
        for (k, (file, r)) in crops.iter().enumerate() {
            let _ = writeln!(
                h,
                "<p>{}. x {} y {} ({}x{}): <b>{}</b>; {} scale, channel {}, adjusted p {:.2e}, z {:+.1}<br><img src=\"{file}\" alt=\"region {}\"></p>",
                k + 1,
                r.x,
                r.y,
                r.width,
                r.height,
                html(r.change.as_deref().unwrap_or("")),
                r.scale,
                r.channel,
                r.adjusted_p,
                r.z,
                k + 1
            );
        }
        h.push_str(DIFFERENCE_LEGEND);
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
        "</table><p>Bias (linear, R G B): {:+.5} {:+.5} {:+.5}. Effective spp: {}. relMSE (how \
         far, not whether): {}.</p>{}",
        c.bias[0],
        c.bias[1],
        c.bias[2],
        c.effective_spp
            .map_or_else(|| "unknown".to_string(), |n| format!("{n:.1}")),
        c.rel_mse
            .map_or_else(|| "unknown".to_string(), |r| format!("{r:.3e}")),
        flip_paragraph(c)
    );
    h.push_str("<p>Report: <a href=\"report.json\">report.json</a></p></body></html>\n");
    h
}

/// FLIP's figures and map, when there is one: how far as people see it, never the verdict.
fn flip_paragraph(c: &Comparison) -> String {
    match &c.flip {
        Some(f) if !c.flip_map.is_empty() => format!(
            "<h2>FLIP (how far as people see it, not whether)</h2><p>Mean {:.4}, median {:.4}, \
             worst 1% from {:.4}, largest {:.4} (0 equal, 1 as different as FLIP can say; both \
             images as an sRGB display shows them).</p><img src=\"flip.png\" alt=\"FLIP error \
             map\">\n",
            f.mean, f.median, f.p99, f.max
        ),
        _ => String::new(),
    }
}

/// The |difference| x4 image of two images' codes: per pixel the largest channel's difference
/// times 4, white where they are equal.
fn difference_image(cand: &[u8], gold: &[u8], width: usize, height: usize) -> Rgb8Image {
    let data = cand
        .chunks_exact(3)
        .zip(gold.chunks_exact(3))
        .flat_map(|(a, b)| {
            let v = difference_shade(a, b);
            [v, v, v]
        })
        .collect();
    Rgb8Image {
        width,
        height,
        data,
    }
}

/// The grey of one pixel of a |difference| x4 picture.
fn difference_shade(a: &[u8], b: &[u8]) -> u8 {
    let d = (0..3)
        .map(|c| (i32::from(a[c]) - i32::from(b[c])).abs())
        .max()
        .unwrap_or(0);
    255 - (4 * d).min(255) as u8
}

/// Whether `name` may be given to `--heatmap` inside the `--report` folder: `heat*.png` (letters,
/// digits, `-`, `_` and `.`), so that a report folder holding it can be replaced again.
pub fn is_heatmap_name(name: &str) -> bool {
    name.strip_prefix("heat")
        .and_then(|n| n.strip_suffix(".png"))
        .is_some()
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'-' | b'_' | b'.'))
}

/// Whether `name` is a file of a compare report folder.
fn is_report_file(name: &str) -> bool {
    matches!(
        name,
        "report.json"
            | "heatmap.png"
            | "index.html"
            | "candidate.png"
            | "golden.png"
            | "difference.png"
            | "flip.png"
    ) || is_heatmap_name(name)
        || name
            .strip_prefix("region-")
            .and_then(|n| n.strip_suffix(".png"))
            .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
}

/// What a folder may hold to be replaced by a compare report: a compare report's files.
pub const REPORT_FOLDER: Replaceable = Replaceable {
    what: "a compare report",
    is_output_file: is_report_file,
    folders: false,
};

/// Checks `dir` and creates the staging folder of its report (see [`OutputDir::create`]), before
/// any work; `option` names the option that gave it, for messages (`"--report"`).
pub fn report_dir(dir: &Path, option: &str) -> Result<OutputDir, OutputError> {
    OutputDir::create(dir, option, &REPORT_FOLDER)
}

/// Writes the report folder `dir` (see [`write_report_to`]). An existing `dir` must hold only a
/// compare report's files.
pub fn write_report(
    dir: &Path,
    comparison: &Comparison,
    candidate: &CandidateImage,
    golden: &Golden,
    encoding: Encoding,
) -> Result<(), CompareError> {
    let out = report_dir(dir, "")?;
    write_report_to(out, comparison, candidate, golden, encoding)
}

/// Fills the staging folder `out` (from [`report_dir`]) and swaps it in whole, so the report
/// appears whole or not at all, nothing of an earlier report (say a stale `region-7.png`)
/// survives, and Ctrl-C or SIGTERM leaves no temporary folder.
pub fn write_report_to(
    out: OutputDir,
    comparison: &Comparison,
    candidate: &CandidateImage,
    golden: &Golden,
    encoding: Encoding,
) -> Result<(), CompareError> {
    let png = |name: &str, img: &Rgb8Image| -> Result<(), CompareError> {
        let bytes = encode_png(img).map_err(|message| CompareError::Input {
            path: out.shown(name),
            message,
        })?;
        Ok(out.write(name, &bytes)?)
    };
    out.write("report.json", to_json(comparison).as_bytes())?;
    png("heatmap.png", &heatmap_image(comparison))?;
    let cand = candidate.to_rgb8(encoding);
    let gold: Vec<u8> = golden
        .mean
        .iter()
        .flat_map(|p| p.map(|x| encoding.encode(x)))
        .collect();
    png(
        "candidate.png",
        &Rgb8Image {
            width: comparison.width,
            height: comparison.height,
            data: cand.clone(),
        },
    )?;
    png(
        "golden.png",
        &Rgb8Image {
            width: comparison.width,
            height: comparison.height,
            data: gold.clone(),
        },
    )?;
    png(
        "difference.png",
        &difference_image(&cand, &gold, comparison.width, comparison.height),
    )?;
    if let Some(data) =
        super::flip::magma_picture(&comparison.flip_map, comparison.width, comparison.height)
    {
        png(
            "flip.png",
            &Rgb8Image {
                width: comparison.width,
                height: comparison.height,
                data,
            },
        )?;
    }
    let mut crops = Vec::new();
    for (k, r) in comparison.regions.iter().take(CROPS).enumerate() {
        let name = format!("region-{}.png", k + 1);
        let img = side_by_side(
            &cand,
            &gold,
            comparison.width,
            crop_box(r, comparison.width, comparison.height),
        );
        png(&name, &img)?;
        crops.push((name, r.clone()));
    }
    out.write("index.html", index_html(comparison, &crops).as_bytes())?;
    Ok(out.commit()?)
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

    #[test]
    fn only_a_compare_report_may_be_replaced() {
        let root = tempfile::tempdir().unwrap();
        let ok = folder_with(
            root.path(),
            &["report.json", "heatmap.png", "region-12.png"],
        );
        let check = |p: &Path| crate::output::check_replaceable(p, "--report", &REPORT_FOLDER);
        assert!(check(ok.path()).is_ok());
        assert!(check(&root.path().join("new")).is_ok());
        let mine = folder_with(root.path(), &["report.json", "region-x.png"]);
        let e = check(mine.path()).unwrap_err().to_string();
        assert!(e.starts_with("--report "), "{e}");
        assert!(
            e.contains("holds region-x.png, which is not part of a compare report"),
            "{e}"
        );
        // Nor a folder inside it: a compare report has none.
        let nested = folder_with(root.path(), &["report.json"]);
        std::fs::create_dir(nested.path().join("old")).unwrap();
        let e = check(nested.path()).unwrap_err().to_string();
        assert!(e.contains("holds old,"), "{e}");
    }
}
