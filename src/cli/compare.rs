use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use rtoracle::compare::{
    CandidateImage, CompareOptions, Comparison, Encoding, Golden, check_size, compare_image,
    golden_for_scene, golden_spp, report, write_heatmap, write_report_to,
};
use rtoracle::image_io::decode_exr;

/// `rtoracle compare CANDIDATE (--scene NAME|FILE.toml [--golden FILE.exr] | --golden FILE.exr) [--spp N] [--encoding E]
/// [--json] [--heatmap OUT.png] [--report DIR]`
#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("reference").required(true).multiple(true).args(["scene", "golden"])))]
pub struct Args {
    /// The image to judge: a PNG (8-bit RGB or RGBA) or an EXR.
    candidate: PathBuf,
    /// Compare with the golden of this built-in scene (see `rtoracle scenes`), or of this scene
    /// file (`.toml`; its golden rendered once and cached, as grading does).
    #[arg(long, value_name = "NAME|FILE.toml")]
    scene: Option<String>,
    /// Compare with this golden EXR (mean and a `variance` layer). With --scene, the golden must
    /// have been made from that scene (`rtoracle golden FILE.toml -o FILE.exr`), and the scene
    /// gives the candidate's default spp.
    #[arg(long, value_name = "FILE.exr")]
    golden: Option<PathBuf>,
    /// The candidate's samples per pixel (default: the scene's, 20 for the course scenes; 20 with
    /// --golden alone, which does not say the scene's).
    #[arg(long, value_name = "N", value_parser = super::num::spp)]
    spp: Option<u32>,
    /// How the candidate's 8-bit codes encode linear values.
    #[arg(long, value_name = "E", default_value = "course",
          value_parser = ["course", "rtiow", "srgb", "gamma22", "linear"])]
    encoding: String,
    /// Print the JSON report on stdout instead of the summary.
    #[arg(long)]
    json: bool,
    /// Write the signed z heatmap (failing regions outlined) to this PNG.
    #[arg(long, value_name = "OUT.png")]
    heatmap: Option<PathBuf>,
    /// Write a report folder: report.json, heatmap.png, crops of the worst regions, index.html.
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
}

/// The summary printed without `--json`; `pictures` says whether `--heatmap` or `--report` was
/// given (a FAIL without them says how to see where it fails).
fn summary(c: &Comparison, candidate: &Path, pictures: bool) -> String {
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
    s.push_str("  scale      tests  smallest adjusted p  (threshold)  largest |z|  failing\n");
    for r in &c.scales {
        s.push_str(&format!(
            "  {:<7} {:>8}  {:>19.3e}  ({:.1e})  {:>11.2}  {:>7}\n",
            r.scale, r.tests, r.smallest_adjusted_p, r.threshold, r.largest_abs_z, r.failing
        ));
    }
    s.push_str(&format!(
        "  bias (linear R G B) {:+.5} {:+.5} {:+.5}; effective spp {}\n",
        c.bias[0],
        c.bias[1],
        c.bias[2],
        c.effective_spp
            .map_or_else(|| "unknown".to_string(), |n| format!("{n:.1}"))
    ));
    for r in c.regions.iter().take(5) {
        s.push_str(&format!(
            "  failing region x {} y {} {}x{}: {} scale, channel {}, adjusted p {:.2e}, z {:+.1}\n",
            r.x, r.y, r.width, r.height, r.scale, r.channel, r.adjusted_p, r.z
        ));
    }
    let total = c.regions_total.max(c.regions.len());
    if total > 5 {
        s.push_str(&format!("  ... and {} more regions\n", total - 5));
    }
    if let Some(n) = c.noise.as_ref().filter(|n| !n.passed) {
        s.push_str(&format!(
            "  noise: the pixels differ from the golden as much as a render of about {} spp would, not {} spp (p {:.2e} < {:.0e})\n",
            n.effective_spp
                .map_or_else(|| "fewer".to_string(), |e| format!("{e:.1}")),
            n.claimed_spp,
            n.p,
            n.threshold
        ));
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
    let encoding: Encoding = args
        .encoding
        .parse()
        .map_err(|e: String| anyhow::anyhow!(e))?;
    if let Some(h) = &args.heatmap {
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
    let (golden, default_spp): (Box<dyn FnOnce(u32) -> anyhow::Result<Golden>>, u32) =
        match (&args.scene, &args.golden) {
            (Some(name), Some(path)) => {
                // The golden given, checked against the scene (as a rubric's `golden` is).
                let (_, description) = super::render::load_scene(name)?;
                let bytes = std::fs::read(path).map_err(|e| {
                    let why = match e.kind() {
                        std::io::ErrorKind::NotFound => "no such file".to_string(),
                        std::io::ErrorKind::IsADirectory => "is a folder".to_string(),
                        _ => e.to_string(),
                    };
                    anyhow::anyhow!("--golden {}: {why}", path.display())
                })?;
                let image =
                    rtoracle::golden::golden_fits(&bytes, path, &description).map_err(|why| {
                        anyhow::anyhow!(
                            "--golden {}: {why}; make it with `rtoracle golden {name} -o {}`",
                            path.display(),
                            path.display()
                        )
                    })?;
                let g = Golden::from_exr_image(image, path)?;
                check_size(&args.candidate, &candidate, g.width, g.height)?;
                (
                    Box::new(move |_| Ok(g)),
                    description.image.samples_per_pixel,
                )
            }
            (Some(name), None) => {
                let (_, description) = super::render::load_scene(name)?;
                let camera = description.camera(None);
                check_size(&args.candidate, &candidate, camera.width, camera.height)?;
                let default_spp = description.image.samples_per_pixel;
                if rtoracle::scene::builtin(name).is_ok() {
                    let name = name.clone();
                    (
                        Box::new(move |spp| Ok(golden_for_scene(&name, spp)?)),
                        default_spp,
                    )
                } else {
                    // A scene file: its golden from the cache, as grading gets it.
                    let label = Path::new(name)
                        .file_name()
                        .map_or_else(|| name.clone(), |n| n.to_string_lossy().to_string());
                    (
                        Box::new(move |spp| {
                            let spp = golden_spp(spp);
                            let cached = rtoracle::golden::cache_dir()
                                .map(|d| rtoracle::golden::cache_file(&d, &description, spp));
                            if !cached.is_some_and(|p| p.is_file()) {
                                errln!(
                                    "rendering the golden of {} at {spp} spp (once; it is cached)",
                                    rtoracle::escape::terminal_line(&label)
                                );
                            }
                            let made =
                                rtoracle::golden::cached_golden(&description, &label, spp, true)?;
                            let path = made.path.unwrap_or_else(|| PathBuf::from(&label));
                            let image = decode_exr(&made.bytes, &path)?;
                            Ok(Golden::from_exr_image(image, &path)?)
                        }),
                        default_spp,
                    )
                }
            }
            (None, Some(path)) => {
                let g = Golden::from_exr(path)?;
                check_size(&args.candidate, &candidate, g.width, g.height)?;
                (Box::new(move |_| Ok(g)), 20)
            }
            (None, None) => anyhow::bail!("give --scene NAME or --golden FILE.exr"),
        };
    let spp = args.spp.unwrap_or(default_spp);
    let golden = golden(spp)?;
    let options = CompareOptions {
        samples_per_pixel: spp,
        encoding,
        ..Default::default()
    };
    let comparison = compare_image(&candidate, &golden, &options)
        .with_context(|| args.candidate.display().to_string())?;
    if let Some(h) = &args.heatmap {
        write_heatmap(h, &comparison)?;
    }
    if let Some(out) = report_out {
        write_report_to(out, &comparison, &candidate, &golden, encoding)?;
    }
    if args.json {
        outln!("{}", report::to_json(&comparison))?;
    } else {
        let pictures = args.heatmap.is_some() || args.report.is_some();
        out!("{}", summary(&comparison, &args.candidate, pictures))?;
    }
    Ok(ExitCode::from(if comparison.passed() { 0 } else { 1 }))
}
