//! What an instructor reads: the diagnosis, the failing regions and the HTML report on the
//! cases met in practice: one quad's colour changed (blue to red), a render flipped upside down,
//! a render 10% darker everywhere, a field of view of 80 degrees for 90.
//!
//! Each case knows which pixels it changed (independently of the comparison: from renders with
//! the same seed, or from the golden and the change's closed form), so every region the report
//! boxes can be checked against it.

use std::sync::OnceLock;

use rtoracle::compare::{
    CompareOptions, Comparison, Region, candidate::CandidateImage, compare_image,
    noise_model::Golden,
};
use rtoracle::image_io::Rgb8Image;
use rtoracle::render::{RenderOptions, encode_course_png, render};
use rtoracle::scene::SceneDescription;

const SCENE: &str = "week04-quad";
const SEED: u64 = 31;
const SPP: u32 = 20;

/// The quad scene's embedded golden (4096 spp, seed 0), decoded once.
fn golden() -> &'static Golden {
    static GOLDEN: OnceLock<Golden> = OnceLock::new();
    GOLDEN.get_or_init(|| {
        let scene = rtoracle::golden::GoldenScene::builtin(SCENE).unwrap();
        let found = rtoracle::golden::golden_of(&scene, 4096, None, false).unwrap();
        let g = Golden::from_exr_image(found.image, &found.source).unwrap();
        assert_eq!(g.vfov, Some(90.0));
        g
    })
}

/// `d` rendered at [`SPP`] with [`SEED`]: the linear means.
fn render_means(d: &SceneDescription) -> Vec<[f64; 3]> {
    let film = render(
        &d.scene(),
        &d.camera(None),
        &RenderOptions {
            samples_per_pixel: SPP,
            seed: SEED,
            ..Default::default()
        },
    )
    .unwrap();
    film.mean.iter().map(|m| m.to_array()).collect()
}

/// Linear means times `scale` as a course PNG's codes, `w` wide.
fn codes(means: &[[f64; 3]], scale: f64, w: usize) -> Rgb8Image {
    Rgb8Image {
        width: w,
        height: means.len() / w,
        data: means
            .iter()
            .flat_map(|m| m.map(|x| encode_course_png(scale * x)))
            .collect(),
    }
}

/// One wrong render and the pixels it changed.
pub struct Case {
    /// A file-name-friendly name.
    pub name: &'static str,
    /// The candidate.
    pub image: Rgb8Image,
    /// Per pixel: whether the change touched it.
    pub changed: Vec<bool>,
}

/// The four cases and the pixels each changed, exactly: those whose mean (linear, before the
/// codes) the change alters. Colour and field of view: renders with the same seed (the same
/// rays; only those that meet the recoloured quad, or see the scene from another angle, change).
/// Flip and darker: the golden's means flipped, or times 0.9.
pub fn cases() -> &'static [Case] {
    static CASES: OnceLock<Vec<Case>> = OnceLock::new();
    CASES.get_or_init(|| {
        let d = rtoracle::scene::builtin(SCENE).unwrap();
        let honest = render_means(&d);
        let (w, h) = (golden().width, golden().height);
        let mut recoloured = d.clone();
        let blue = recoloured
            .materials
            .iter_mut()
            .find(|m| m.name == "right_blue")
            .unwrap();
        blue.albedo = [1.0, 0.2, 0.2];
        let colour = render_means(&recoloured);
        let mut narrow = d.clone();
        assert_eq!(narrow.camera.vfov, 90.0);
        narrow.camera.vfov = 80.0;
        let fov = render_means(&narrow);
        let flip = |k: usize| (h - 1 - k / w) * w + k % w;
        let flipped: Vec<[f64; 3]> = (0..w * h).map(|k| honest[flip(k)]).collect();
        let g = &golden().mean;
        let differ = |a: &[[f64; 3]], b: &[[f64; 3]]| -> Vec<bool> {
            a.iter().zip(b).map(|(p, q)| p != q).collect()
        };
        vec![
            Case {
                name: "colour",
                image: codes(&colour, 1.0, w),
                changed: differ(&honest, &colour),
            },
            Case {
                name: "flip",
                image: codes(&flipped, 1.0, w),
                changed: (0..w * h).map(|k| g[k] != g[flip(k)]).collect(),
            },
            Case {
                name: "darker",
                image: codes(&honest, 0.9, w),
                changed: g.iter().map(|m| m.iter().any(|&x| x != 0.0)).collect(),
            },
            Case {
                name: "fov80",
                image: codes(&fov, 1.0, w),
                changed: differ(&honest, &fov),
            },
        ]
    })
}

pub fn candidate(img: &Rgb8Image) -> CandidateImage {
    CandidateImage::Rgb8 {
        width: img.width,
        height: img.height,
        data: img.data.clone(),
    }
}

fn compared(case: &Case) -> Comparison {
    compare_image(
        &candidate(&case.image),
        golden(),
        &CompareOptions::default(),
    )
    .unwrap()
}

/// Whether `r` holds a pixel `changed` marks in an image `w` wide.
pub fn holds_a_change(r: &Region, changed: &[bool], w: usize) -> bool {
    (r.y..r.y + r.height).any(|y| (r.x..r.x + r.width).any(|x| changed[y * w + x]))
}

fn case(name: &str) -> &'static Case {
    cases().iter().find(|c| c.name == name).unwrap()
}

/// FLIP says where the change is: with the quad recoloured, its mean error over the pixels the
/// change touched is several times that over the rest (which differ from the golden by noise and
/// quantisation only); every case has a map of one error per pixel in `[0, 1]`, and a summary
/// whose figures are in order.
#[test]
fn flip_s_error_is_where_the_change_is() {
    for case in cases() {
        let name = case.name;
        let c = compared(case);
        let f = c.flip.expect("a FLIP summary");
        assert_eq!(c.flip_map.len(), c.width * c.height, "{name}");
        assert!(c.flip_map.iter().all(|e| (0.0..=1.0).contains(e)), "{name}");
        assert!(
            f.median <= f.p99 && f.p99 <= f.max && f.mean <= f.max,
            "{name}: {f:?}"
        );
        let mean_where = |touched: bool| {
            let errors: Vec<f64> = c
                .flip_map
                .iter()
                .zip(&case.changed)
                .filter(|(_, t)| **t == touched)
                .map(|(e, _)| *e as f64)
                .collect();
            errors.iter().sum::<f64>() / errors.len() as f64
        };
        if name == "colour" {
            let (changed, rest) = (mean_where(true), mean_where(false));
            assert!(
                changed > 3.0 * rest,
                "{name}: {changed} where changed, {rest} elsewhere"
            );
        }
    }
}

/// Every failing region of every case, listed or only outlined, holds a pixel the case changed.
#[test]
fn every_failing_region_holds_a_changed_pixel() {
    for case in cases() {
        let c = compared(case);
        assert!(!c.passed(), "{}", case.name);
        assert!(!c.outline.is_empty(), "{}", case.name);
        for r in &c.outline {
            assert!(
                holds_a_change(r, &case.changed, c.width),
                "{}: {r:?} holds no changed pixel",
                case.name
            );
        }
    }
}

/// The quad turned from blue to red is said to be a different colour, not a brighter one.
#[test]
fn a_colour_change_is_told_per_channel() {
    let c = compared(case("colour"));
    let first = &c.regions[0];
    let change = first.change.as_deref().unwrap();
    assert_eq!(
        change, "red up, blue down: a different colour, not a brighter one",
        "{first:?}"
    );
    // The quad spans x 266-319, y 120-279: the first region lies on it.
    assert!(
        first.x + first.width > 266
            && first.x < 320
            && first.y + first.height > 120
            && first.y < 280,
        "{first:?}"
    );
}

/// Flipped and darker images fail all over: the regions listed first are distinct places over
/// the image, not a row of crops of the top-left sky.
#[test]
fn the_first_regions_are_distinct_places() {
    for name in ["flip", "darker"] {
        let c = compared(case(name));
        let first: Vec<&Region> = c.regions.iter().take(6).collect();
        assert_eq!(first.len(), 6, "{name}");
        let centre = |r: &Region| {
            (
                r.x as f64 + r.width as f64 / 2.0,
                r.y as f64 + r.height as f64 / 2.0,
            )
        };
        let spread = first
            .iter()
            .flat_map(|a| first.iter().map(move |b| (centre(a), centre(b))))
            .map(|((ax, ay), (bx, by))| ((ax - bx).powi(2) + (ay - by).powi(2)).sqrt())
            .fold(0.0, f64::max);
        assert!(spread > c.width as f64 / 2.0, "{name}: {first:?}");
        assert!(
            first.iter().any(|r| r.y >= c.height / 2),
            "{name}: all in the top half: {first:?}"
        );
    }
}

/// A render 10% darker in linear light everywhere is named a uniform scale of 0.90, said in the
/// PNG's codes (the square root of 0.90: 0.95) with the linear factor beside it.
#[test]
fn a_darker_render_is_a_uniform_scale() {
    let c = compared(case("darker"));
    let d = c.diagnosis.as_ref().unwrap();
    assert_eq!(d.best.as_deref(), Some("scale:0.90"), "{}", d.summary);
    assert!(d.hypotheses[0].passes, "{}", d.summary);
    assert!(
        d.summary.contains("every code times 0.95 (linear x0.90)"),
        "{}",
        d.summary
    );
    assert!(
        d.summary.contains("5% darker in the picture"),
        "{}",
        d.summary
    );
}

/// A field of view of 80 degrees where the scene says 90 is named a zoom, with the field of view
/// it implies (80, to a degree).
#[test]
fn a_narrower_field_of_view_is_named() {
    let c = compared(case("fov80"));
    let d = c.diagnosis.as_ref().unwrap();
    let best = d.best.as_deref().unwrap_or_default();
    assert!(best.starts_with("zoom:"), "{}", d.summary);
    let about = d
        .summary
        .split("field of view of about ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse::<f64>().ok())
        .unwrap_or_else(|| panic!("{}", d.summary));
    assert!((about - 80.0).abs() <= 1.0, "{}", d.summary);
    assert!(
        d.summary.contains("where the scene's is 90"),
        "{}",
        d.summary
    );
}

// ---- The HTML report, as headless Chromium shows it ----

/// Headless Chromium (`RTORACLE_CHROMIUM`, else `/usr/bin/chromium`), or `None` after saying the
/// test is skipped; with `RTORACLE_REQUIRE_CHROMIUM=1` (as CI sets it) its absence fails.
fn chromium(test: &str) -> Option<std::path::PathBuf> {
    let path = std::env::var_os("RTORACLE_CHROMIUM")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| "/usr/bin/chromium".into());
    if path.is_file() {
        return Some(path);
    }
    assert!(
        std::env::var("RTORACLE_REQUIRE_CHROMIUM").as_deref() != Ok("1"),
        "{test}: RTORACLE_REQUIRE_CHROMIUM=1 but there is no Chromium at {}",
        path.display()
    );
    eprintln!("skipped {test}: no Chromium at {}", path.display());
    None
}

/// Runs headless Chromium on `page` with `args` (its profile in `profile`), killed after two
/// minutes; its stdout.
fn headless(chromium: &Path, profile: &Path, page: &Path, args: &[&str]) -> Vec<u8> {
    let mut child = std::process::Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(args)
        .arg(format!("file://{}", page.display()))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut out = Vec::new();
        std::io::Read::read_to_end(&mut stdout, &mut out).unwrap();
        out
    });
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > std::time::Duration::from_secs(120) {
            child.kill().unwrap();
            panic!(
                "Chromium did not finish with {} in two minutes",
                page.display()
            );
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    reader.join().unwrap()
}

/// The values of attribute `attr` in a serialised DOM.
fn attributes<'a>(dom: &'a str, attr: &str) -> Vec<&'a str> {
    let key = format!("{attr}=\"");
    dom.match_indices(&key)
        .map(|(at, _)| {
            let rest = &dom[at + key.len()..];
            &rest[..rest.find('"').unwrap()]
        })
        .collect()
}

/// The `<img>` tags of a serialised DOM, as (src, width).
fn images(dom: &str) -> Vec<(String, String)> {
    dom.split("<img ")
        .skip(1)
        .map(|tag| {
            let tag = &tag[..tag.find('>').unwrap()];
            let get = |a: &str| {
                attributes(tag, a)
                    .first()
                    .map(|s| s.to_string())
                    .unwrap_or_default()
            };
            (get("src"), get("width"))
        })
        .collect()
}

use std::path::Path;

/// Each case's report, as Chromium builds the page: the candidate, the golden and the
/// difference at the same scale, the heatmap, both legends, the candidate's name, the noise
/// sentence, the diagnosis, and boxes that each hold a pixel the case changed. `--heatmap` inside
/// the `--report` folder is written there. The colour case's page is screenshot: the heatmap's
/// colours and outlines are on screen (the images loaded), and the picture is the README's
/// (written again with `RTORACLE_UPDATE_SCREENSHOT=1`).
#[test]
fn the_html_report_shows_what_an_instructor_reads_at_a_glance() {
    let Some(chromium) = chromium("the_html_report_shows_what_an_instructor_reads_at_a_glance")
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let profile = tempfile::tempdir().unwrap();
    let expected_diagnosis = [
        (
            "colour",
            "red up, blue down: a different colour, not a brighter one",
        ),
        ("flip", "upside down"),
        ("darker", "every code times 0.95 (linear x0.90)"),
        ("fov80", "field of view of about"),
    ];
    for case in cases() {
        let file = format!("{}.png", case.name);
        rtoracle::image_io::write_png(&dir.path().join(&file), &case.image).unwrap();
        let report = format!("report-{}", case.name);
        let out = crate::common::rtoracle()
            .current_dir(dir.path())
            .env("RTORACLE_CACHE_DIR", dir.path().join("cache"))
            .args(["compare", &file, "--scene", SCENE, "--report", &report])
            .args(["--heatmap", &format!("{report}/heat.png")])
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(1),
            "{}: {}",
            case.name,
            String::from_utf8_lossy(&out.stderr)
        );
        let folder = dir.path().join(&report);
        assert!(folder.join("heat.png").is_file(), "{}", case.name);
        let page = folder.join("index.html");
        let dom =
            String::from_utf8(headless(&chromium, profile.path(), &page, &["--dump-dom"])).unwrap();
        let name = case.name;
        assert!(
            dom.contains(&format!("<h1>FAIL: {file}</h1>")),
            "{name}: {dom}"
        );
        // The three thumbnails at the same scale, and the heatmap three times as wide.
        let imgs = images(&dom);
        let width_of = |src: &str| {
            imgs.iter()
                .find(|(s, _)| s == src)
                .unwrap_or_else(|| panic!("{name}: no <img src={src}>: {dom}"))
                .1
                .parse::<usize>()
                .unwrap()
        };
        let w = width_of("candidate.png");
        assert!(w >= 160, "{name}: {w}");
        assert_eq!(width_of("golden.png"), w, "{name}");
        assert_eq!(width_of("difference.png"), w, "{name}");
        assert_eq!(width_of("heatmap.png"), 3 * w, "{name}");
        for (src, _) in &imgs {
            assert!(folder.join(src).is_file(), "{name}: {src} is missing");
        }
        // FLIP's map and figures, beside the verdict.
        assert!(
            imgs.iter().any(|(s, _)| s == "flip.png"),
            "{name}: no FLIP map: {dom}"
        );
        assert!(dom.contains("FLIP (how far as people see it"), "{name}");
        // Legends: the heatmap's colour scale and the difference's, with what white means.
        for legend in ["id=\"z-legend\"", "id=\"difference-legend\""] {
            assert!(dom.contains(legend), "{name}: no {legend}");
        }
        assert!(dom.contains("z ≥ +8: the candidate higher"), "{name}");
        assert!(dom.contains("white: equal"), "{name}");
        // The noise sentence, as the command line words it.
        let json: Comparison =
            serde_json::from_slice(&std::fs::read(folder.join("report.json")).unwrap()).unwrap();
        let noise = json.noise_sentence();
        let noise = noise
            .replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;");
        assert!(dom.contains(&noise), "{name}: {noise}");
        let (_, words) = expected_diagnosis.iter().find(|(n, _)| *n == name).unwrap();
        assert!(dom.contains(words), "{name}: {words}");
        // Every box holds a changed pixel.
        let boxes = attributes(&dom, "data-region");
        assert_eq!(boxes.len(), json.regions.len().min(6), "{name}");
        for b in boxes {
            let v: Vec<usize> = b.split(',').map(|s| s.parse().unwrap()).collect();
            let r = Region {
                x: v[0],
                y: v[1],
                width: v[2],
                height: v[3],
                scale: String::new(),
                channel: String::new(),
                adjusted_p: 0.0,
                z: 0.0,
                change: None,
            };
            assert!(
                holds_a_change(&r, &case.changed, json.width),
                "{name}: the box {b} holds no changed pixel"
            );
        }
    }
    screenshot(
        &chromium,
        profile.path(),
        &dir.path().join("report-colour/index.html"),
    );
}

/// Where the README's screenshot of a report lives.
const SCREENSHOT: &str = "docs/compare-report.png";

/// Screenshots the colour case's report: the heatmap's orange, purple and green outline are on
/// screen; the README's copy is written again with `RTORACLE_UPDATE_SCREENSHOT=1`, and is a PNG
/// under 150 KB.
fn screenshot(chromium: &Path, profile: &Path, page: &Path) {
    use rtoracle::compare::heatmap::{HIGHER, LOWER, OUTLINE};
    let shot = page.with_file_name("screenshot.png");
    headless(
        chromium,
        profile,
        page,
        &[
            &format!("--screenshot={}", shot.display()),
            "--window-size=1100,1100",
        ],
    );
    let img = rtoracle::image_io::read_png(&shot).unwrap();
    let count = |want: [u8; 3]| {
        img.data
            .chunks_exact(3)
            .filter(|p| p.iter().zip(want).all(|(a, b)| a.abs_diff(b) <= 3))
            .count()
    };
    for (what, colour) in [("orange", HIGHER), ("purple", LOWER), ("green", OUTLINE)] {
        assert!(
            count(colour) > 50,
            "the screenshot shows no {what}: {}",
            shot.display()
        );
    }
    let readme_copy = Path::new(env!("CARGO_MANIFEST_DIR")).join(SCREENSHOT);
    if std::env::var("RTORACLE_UPDATE_SCREENSHOT").as_deref() == Ok("1") {
        std::fs::copy(&shot, &readme_copy).unwrap();
    }
    let size = std::fs::metadata(&readme_copy)
        .map(|m| m.len())
        .unwrap_or(0);
    assert!(
        size > 0 && size < 150_000,
        "{SCREENSHOT}: {size} bytes (RTORACLE_UPDATE_SCREENSHOT=1 writes it)"
    );
    rtoracle::image_io::read_png(&readme_copy).unwrap();
}
