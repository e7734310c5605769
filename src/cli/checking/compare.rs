use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use rtoracle::compare::noise_model::recorded_scene;
use rtoracle::compare::{
    CompareOptions, Comparison, candidate::CandidateImage, check_size, compare_image,
    encoding::Encoding, heatmap::write_heatmap, noise_model::Golden, report,
    report::write_report_to,
};
use rtoracle::golden::{GoldenRecord, GoldenScene, cache_dir};

/// `rtoracle compare CANDIDATE (--scene NAME|FILE.toml [--golden FILE.exr] | --golden FILE.exr) [--spp N] [--encoding E]
/// [--json] [--heatmap OUT.png] [--report DIR]`, or `rtoracle compare A B [--json] [--heatmap
/// OUT.png] [--report DIR]` (two renders, no golden)
#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("reference").required(false).multiple(true).args(["scene", "golden"])))]
pub struct Args {
    /// The image to judge: a PNG (8-bit RGB or RGBA), a PPM (P3 or P6, 8-bit) or an EXR. With
    /// OTHER: an EXR with a variance layer, or a folder of EXR renders with different seeds.
    candidate: PathBuf,
    /// A second render of the same scene to compare CANDIDATE with, with no golden (two-sample
    /// tests): an EXR with a variance layer (`rtoracle render --variance`) and an rtoracle.spp
    /// attribute, or a folder of EXR renders with different seeds.
    #[arg(value_name = "OTHER", conflicts_with_all = ["scene", "golden", "spp", "encoding"])]
    other: Option<PathBuf>,
    /// Compare with the golden of this built-in scene (see `rtoracle scenes`), or of this scene
    /// file (`.toml`; its golden rendered once and cached, as grading does).
    #[arg(long, value_name = "NAME|FILE.toml")]
    scene: Option<String>,
    /// Compare with this golden EXR (mean and a `variance` layer). With --scene, the golden must
    /// have been made from that scene (`rtoracle golden FILE.toml -o FILE.exr`), and the scene
    /// gives the candidate's default spp.
    #[arg(long, value_name = "FILE.exr")]
    golden: Option<PathBuf>,
    /// The candidate's samples per pixel (default: the scene's, 20 for the course scenes; with
    /// --golden alone, the scene's that the golden records, else 20).
    #[arg(long, value_name = "N", value_parser = crate::cli::args::spp)]
    spp: Option<u32>,
    /// How the candidate's 8-bit codes encode linear values.
    #[arg(long, value_name = "E", default_value = "course",
          value_parser = ["course", "rtiow", "srgb", "gamma22", "linear"])]
    encoding: String,
    /// Print the JSON report on stdout instead of the summary.
    #[arg(long)]
    json: bool,
    /// Write the signed z heatmap (a map per channel, failing regions outlined) to this PNG
    /// (inside the --report folder: named heat*.png).
    #[arg(long, value_name = "OUT.png")]
    heatmap: Option<PathBuf>,
    /// Write a report folder: report.json, the candidate, golden and difference images,
    /// heatmap.png, crops of the worst regions, index.html.
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
}

/// The summary printed without `--json`; `pictures` says whether `--heatmap` or `--report` was
/// given (a FAIL without them says how to see where it fails).
fn summary(c: &Comparison, candidate: &Path, pictures: bool, spp_note: Option<&str>) -> String {
    let mut s = format!(
        "{} {}: {}x{}, {} spp against a {} spp golden{}, {} encoding\n",
        if c.passed() { "PASS" } else { "FAIL" },
        rtoracle::escape::terminal_line(&candidate.display().to_string()),
        c.width,
        c.height,
        c.candidate_spp,
        c.golden_spp,
        c.scene
            .as_ref()
            .map(|n| format!(" of {n}"))
            .unwrap_or_default(),
        c.encoding
    );
    if let Some(note) = spp_note {
        s.push_str(&format!("  {note}\n"));
    }
    s.push_str("  scale      tests  smallest adjusted p  (threshold)  largest |z|  failing\n");
    for r in &c.scales {
        s.push_str(&format!(
            "  {:<7} {:>8}  {:>19.3e}  ({:.1e})  {:>11.2}  {:>7}\n",
            r.scale, r.tests, r.smallest_adjusted_p, r.threshold, r.largest_abs_z, r.failing
        ));
    }
    s.push_str(&format!(
        "  bias (linear R G B) {:+.5} {:+.5} {:+.5}; effective spp {}; relMSE {}; FLIP {}\n",
        c.bias[0],
        c.bias[1],
        c.bias[2],
        c.effective_spp
            .map_or_else(|| "unknown".to_string(), |n| format!("{n:.1}")),
        c.rel_mse
            .map_or_else(|| "unknown".to_string(), |r| format!("{r:.3e}")),
        flip_words(c.flip.as_ref())
    ));
    for r in c.regions.iter().take(5) {
        let change = r
            .change
            .as_deref()
            .map(|c| format!(" ({c})"))
            .unwrap_or_default();
        s.push_str(&format!(
            "  failing region x {} y {} {}x{}{change}: {} scale, channel {}, adjusted p {:.2e}, z {:+.1}\n",
            r.x, r.y, r.width, r.height, r.scale, r.channel, r.adjusted_p, r.z
        ));
    }
    let total = c.regions_total.max(c.regions.len());
    if total > 5 {
        s.push_str(&format!("  ... and {} more regions\n", total - 5));
    }
    if c.noise.as_ref().is_some_and(|n| !n.passed) {
        s.push_str(&format!("  {}\n", c.noise_sentence()));
    }
    if let Some(d) = &c.diagnosis {
        s.push_str(&format!("  diagnosis: {}\n", d.summary));
    }
    if !c.passed() && !pictures {
        s.push_str("  to see where: add --heatmap FILE.png (the signed z map) or --report DIR (crops and index.html)\n");
    }
    s
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if let Some(other) = &args.other {
        return two_sample(&args, other);
    }
    if args.scene.is_none() && args.golden.is_none() {
        anyhow::bail!(
            "give --scene NAME or --golden FILE.exr, or a second render OTHER to compare with"
        );
    }
    let encoding: Encoding = args
        .encoding
        .parse()
        .map_err(|e: String| anyhow::anyhow!(e))?;
    let heatmap_in_report = heatmap_in_report(&args)?;
    if let (Some(h), None) = (&args.heatmap, &heatmap_in_report) {
        rtoracle::output::check_output_file(h, "--heatmap")?;
        let png = h.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !png {
            anyhow::bail!(
                "--heatmap {}: the heatmap is a PNG; give a name ending in .png",
                h.display()
            );
        }
    }
    // The report's folder is checked and its staging folder made before any work (removed on
    // Ctrl-C and on an error, swapped in whole at the end).
    let report_out = args
        .report
        .as_deref()
        .map(|r| report::report_dir(r, "--report"))
        .transpose()?;
    // The candidate first: a bad candidate is reported before any golden work.
    let candidate = CandidateImage::load(&args.candidate)?;
    let (golden, default_spp, spp_note) = reference(&args, &candidate)?;
    let spp = args.spp.unwrap_or(default_spp);
    let golden = golden(spp)?;
    let spp_note = spp_note.filter(|_| args.spp.is_none());
    let options = CompareOptions {
        samples_per_pixel: spp,
        encoding,
        ..Default::default()
    };
    let mut comparison = compare_image(&candidate, &golden, &options)
        .with_context(|| args.candidate.display().to_string())?;
    comparison.candidate = Some(args.candidate.display().to_string());
    match (&args.heatmap, &heatmap_in_report) {
        (Some(h), None) => write_heatmap(h, &comparison)?,
        (_, Some(name)) if name != "heatmap.png" => {
            if let Some(out) = &report_out {
                out.write(name, &rtoracle::compare::heatmap::heatmap_png(&comparison)?)?;
            }
        }
        _ => {}
    }
    if let Some(out) = report_out {
        write_report_to(out, &comparison, &candidate, &golden, encoding)?;
    }
    if args.json {
        outln!("{}", report::to_json(&comparison))?;
    } else {
        let pictures = args.heatmap.is_some() || args.report.is_some();
        out!(
            "{}",
            summary(&comparison, &args.candidate, pictures, spp_note.as_deref())
        )?;
    }
    Ok(ExitCode::from(if comparison.passed() { 0 } else { 1 }))
}

/// The name `--heatmap` gives inside the `--report` folder, when it names a file there (written
/// into the report, which the folder does not hold yet): `heat*.png`, or bad input.
fn heatmap_in_report(args: &Args) -> anyhow::Result<Option<String>> {
    let (Some(h), Some(dir)) = (&args.heatmap, &args.report) else {
        return Ok(None);
    };
    let parent = h
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let same = match (std::path::absolute(parent), std::path::absolute(dir)) {
        (Ok(a), Ok(b)) => a.components().eq(b.components()),
        _ => false,
    };
    if !same {
        return Ok(None);
    }
    let name = h
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    if !report::is_heatmap_name(&name) {
        anyhow::bail!(
            "--heatmap {}: inside the --report folder the heatmap must be named heat*.png (the report holds heatmap.png already)",
            h.display()
        );
    }
    Ok(Some(name))
}

/// The golden, made once the candidate's samples per pixel are known.
type GoldenFor = Box<dyn FnOnce(u32) -> anyhow::Result<Golden>>;

/// The scene `--scene` names: a scene file (`.toml`, or an existing file) or a built-in.
fn golden_scene(name: &str) -> anyhow::Result<GoldenScene> {
    let path = Path::new(name);
    Ok(if name.ends_with(".toml") || path.is_file() {
        GoldenScene::from_file(path)?
    } else {
        GoldenScene::builtin(name)?
    })
}

/// Reads `--golden`, naming it in errors as the option.
fn read_golden_file(path: &Path) -> anyhow::Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| {
        let why = match e.kind() {
            std::io::ErrorKind::NotFound => "no such file".to_string(),
            std::io::ErrorKind::IsADirectory => "is a folder".to_string(),
            _ => e.to_string(),
        };
        anyhow::anyhow!("--golden {}: {why}", path.display())
    })
}

/// What the candidate is compared with: the golden (given the candidate's spp), the default spp,
/// and, with `--golden` alone, where that default came from.
fn reference(
    args: &Args,
    candidate: &CandidateImage,
) -> anyhow::Result<(GoldenFor, u32, Option<String>)> {
    match (&args.scene, &args.golden) {
        (Some(name), Some(path)) => {
            // The golden given, checked against the scene (as a rubric's `golden` is).
            let scene = golden_scene(name)?;
            let bytes = read_golden_file(path)?;
            let image = scene.fits(&bytes, path).map_err(|why| {
                anyhow::anyhow!(
                    "--golden {}: {why}; make it with `rtoracle golden {name} -o {}`",
                    path.display(),
                    path.display()
                )
            })?;
            let mut g = Golden::from_exr_image(image, path)?;
            g.scene = Some(scene.name.clone());
            check_size(&args.candidate, candidate, g.width, g.height)?;
            let spp = scene.description.image.samples_per_pixel;
            Ok((Box::new(move |_| Ok(g)), spp, None))
        }
        (Some(name), None) => {
            let scene = golden_scene(name)?;
            let camera = scene.description.camera(None);
            check_size(&args.candidate, candidate, camera.width, camera.height)?;
            let spp = scene.description.image.samples_per_pixel;
            let golden: GoldenFor = Box::new(move |spp| {
                Ok(Golden::of_scene(&scene, spp, cache_dir().as_deref(), true)?)
            });
            Ok((golden, spp, None))
        }
        (None, Some(path)) => {
            let bytes = read_golden_file(path)?;
            let image = rtoracle::image_io::decode_exr(&bytes, path)?;
            let (spp, note) = recorded_spp(&GoldenRecord::of(&image));
            let g = Golden::from_exr_image(image, path)?;
            check_size(&args.candidate, candidate, g.width, g.height)?;
            Ok((Box::new(move |_| Ok(g)), spp, Some(note)))
        }
        (None, None) => anyhow::bail!("give --scene NAME or --golden FILE.exr"),
    }
}

/// The candidate's samples per pixel a golden's attributes imply, and a line saying so: the
/// scene's own, when the golden records its scene ([`recorded_scene`]: the TOML a scene file's
/// golden holds, or the built-in scene it names, hashes agreeing); else 20, the course's.
fn recorded_spp(record: &GoldenRecord) -> (u32, String) {
    let Some(d) = recorded_scene(record) else {
        return (
            20,
            "judged as a render of 20 spp: this golden does not say its scene's samples per pixel (--spp N to change)".to_string(),
        );
    };
    let n = d.image.samples_per_pixel;
    let name = rtoracle::escape::terminal_line(record.scene.as_deref().unwrap_or("its scene"));
    let which = if record.scene_toml.is_some() {
        format!("{name}, the scene this golden holds")
    } else {
        format!("the built-in scene {name}, which this golden is of")
    };
    (
        n,
        format!(
            "judged as a render of {n} spp, the samples_per_pixel of {which} (--spp N to change)"
        ),
    )
}

/// The EXRs of one side of `compare A B`: the file, or every `.exr` of the folder (name order).
fn side_files(path: &Path) -> anyhow::Result<Vec<(PathBuf, rtoracle::image_io::ExrImage)>> {
    let files: Vec<PathBuf> = if path.is_dir() {
        let mut files: Vec<PathBuf> = std::fs::read_dir(path)
            .with_context(|| format!("{}: cannot read the folder", path.display()))?
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")))
            .collect();
        files.sort();
        if files.is_empty() {
            anyhow::bail!("{}: the folder holds no .exr render", path.display());
        }
        files
    } else if path.exists() {
        vec![path.to_path_buf()]
    } else {
        anyhow::bail!("{}: no such file or folder", path.display());
    };
    files
        .into_iter()
        .map(|f| {
            let image = rtoracle::image_io::read_exr(&f)?;
            Ok((f, image))
        })
        .collect()
}

/// `rtoracle compare A B`: two renders with no golden.
fn two_sample(args: &Args, other: &Path) -> anyhow::Result<ExitCode> {
    use rtoracle::compare::twosample::{Side, compare_two};
    if let Some(h) = &args.heatmap {
        rtoracle::output::check_output_file(h, "--heatmap")?;
    }
    let report_out = args
        .report
        .as_deref()
        .map(|r| report::report_dir(r, "--report"))
        .transpose()?;
    let shown = |p: &Path| p.display().to_string();
    let a = Side::from_exrs(&side_files(&args.candidate)?, &shown(&args.candidate))?;
    let b = Side::from_exrs(&side_files(other)?, &shown(other))?;
    let comparison = compare_two(&a, &b, CompareOptions::default().alpha)?;
    if let Some(h) = &args.heatmap {
        write_heatmap(h, &comparison)?;
    }
    if let Some(out) = report_out {
        let candidate = CandidateImage::Linear {
            width: a.width,
            height: a.height,
            data: a.mean.iter().map(|p| p.map(|x| x as f32)).collect(),
        };
        let golden = Golden::new(
            b.width,
            b.height,
            b.spp.max(1),
            b.mean.clone(),
            b.variance.clone(),
            None,
        )?;
        write_report_to(out, &comparison, &candidate, &golden, Encoding::Srgb)?;
    }
    if args.json {
        outln!("{}", report::to_json(&comparison))?;
    } else {
        let sides = format!(
            "{} ({}) against {} ({})",
            rtoracle::escape::terminal_line(&a.label),
            side_words(&a),
            rtoracle::escape::terminal_line(&b.label),
            side_words(&b)
        );
        let text = summary(
            &comparison,
            &args.candidate,
            args.heatmap.is_some() || args.report.is_some(),
            None,
        );
        // The first line names both sides instead of a golden.
        let rest = text.split_once('\n').map_or("", |(_, r)| r);
        out!(
            "{} {sides}: {}x{}, two-sample tests (no golden)\n{rest}",
            if comparison.passed() { "PASS" } else { "FAIL" },
            comparison.width,
            comparison.height
        )?;
    }
    Ok(ExitCode::from(if comparison.passed() { 0 } else { 1 }))
}

/// FLIP's summary in words: `mean 0.021, worst 1% from 0.150`.
fn flip_words(flip: Option<&rtoracle::compare::flip::FlipSummary>) -> String {
    flip.map_or_else(
        || "unknown".to_string(),
        |f| format!("mean {:.3}, worst 1% from {:.3}", f.mean, f.p99),
    )
}

/// A side in words: its renders or its samples.
fn side_words(side: &rtoracle::compare::twosample::Side) -> String {
    match side.renders {
        0 => "exact".to_string(),
        1 => format!("{} spp, its variance layer", side.spp),
        n => format!("{n} renders"),
    }
}
