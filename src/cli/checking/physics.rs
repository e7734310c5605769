//! `rtoracle physics`: the physics checks that need no golden, on a candidate speaking the
//! protocol (its materials through the material requests).

use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use rtoracle::candidate::process::options::RunOptions;
use rtoracle::physics::check_candidate_materials;
use rtoracle::physics::{Family, MaterialCase, MaterialOptions, default_materials};

use crate::cli::checking::check::{SandboxArgs, Target};

/// `rtoracle physics (--adapter 'CMD ARGS' | --python-course DIR) [--material JSON]...`
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    target: Target,
    #[command(flatten)]
    sandbox: SandboxArgs,
    /// A material to check, as the protocol describes it (repeatable), e.g.
    /// '{"type":"metal","albedo":[0.9,0.8,0.7],"roughness":0.3}'; add "reciprocal":false to
    /// report reciprocity without judging it. Default: the book's lambertian, metal (fuzz 0.3
    /// and 0), dielectric and the course's phong, blinn and cook_torrance (a candidate declines
    /// the ones it does not have).
    #[arg(long, value_name = "JSON", value_parser = material)]
    material: Vec<MaterialCase>,
    /// Samples per outgoing direction (100 to 1,000,000).
    #[arg(long, value_name = "N", default_value_t = rtoracle::physics::DEFAULT_SAMPLES, value_parser = samples)]
    samples: usize,
    /// Seeds the normals, the outgoing directions and the random numbers sent.
    #[arg(long, value_name = "S", default_value_t = 0, value_parser = crate::cli::args::seed)]
    seed: u64,
    /// The false-alarm rate of the whole run (shared by its statistical tests).
    #[arg(long, value_name = "P", default_value_t = rtoracle::weekly::stats::DEFAULT_ALPHA, value_parser = crate::cli::args::alpha)]
    alpha: f64,
    /// Time allowed per request, in milliseconds.
    #[arg(long, value_name = "N", default_value_t = 20_000, value_parser = crate::cli::args::millis)]
    timeout_ms: u64,
    /// Time allowed for the candidate to start and answer the hello, in milliseconds.
    #[arg(long, value_name = "N", default_value_t = 10_000, value_parser = crate::cli::args::millis)]
    hello_timeout_ms: u64,
    /// Print the report as one JSON object.
    #[arg(long)]
    json: bool,
    /// Render the furnace scenes (scenes whose every pixel has a known value) through the
    /// candidate's render requests and judge them against their exact images, instead of
    /// checking materials (docs/physics-checks.md).
    #[arg(long, conflicts_with_all = ["material", "samples"])]
    furnace: bool,
    /// With --furnace: render them with rtoracle's own renderer, no candidate.
    #[arg(long, requires = "furnace", conflicts_with_all = ["python_course", "adapter"])]
    reference: bool,
    /// With --furnace: samples per pixel of each render (1 to 4096).
    #[arg(long, value_name = "N", default_value_t = rtoracle::physics::DEFAULT_SPP, value_parser = furnace_spp, requires = "furnace")]
    furnace_spp: u32,
    /// With --furnace: renders of each scene, each with its own seed (2 to 64).
    #[arg(long, value_name = "K", default_value_t = rtoracle::physics::DEFAULT_RENDERS, value_parser = renders, requires = "furnace")]
    renders: usize,
}

/// Samples per pixel of a furnace render: 1 to 4096.
fn furnace_spp(s: &str) -> Result<u32, String> {
    crate::cli::args::int_in::<1, 4096>(s).map(|n| n as u32)
}

/// Renders per furnace: 2 to 64.
fn renders(s: &str) -> Result<usize, String> {
    crate::cli::args::int_in::<2, 64>(s).map(|n| n as usize)
}

/// Samples per direction: 100 to 1,000,000.
fn samples(s: &str) -> Result<usize, String> {
    crate::cli::args::int_in::<100, 1_000_000>(s).map(|n| n as usize)
}

/// A material given on the command line: a JSON object with a string "type".
fn material(s: &str) -> Result<MaterialCase, String> {
    let mut value: serde_json::Value = serde_json::from_str(s)
        .map_err(|e| format!("not JSON ({e}); give an object such as '{{\"type\":\"lambertian\",\"albedo\":[0.8,0.6,0.4]}}'"))?;
    let Some(object) = value.as_object_mut() else {
        return Err("not a JSON object".into());
    };
    let reciprocal = match object.remove("reciprocal") {
        None => true,
        Some(serde_json::Value::Bool(b)) => b,
        Some(_) => return Err("\"reciprocal\" must be true or false".into()),
    };
    let Some(kind) = object
        .get("type")
        .and_then(|t| t.as_str())
        .map(str::to_string)
    else {
        return Err("the material has no \"type\" (a string)".into());
    };
    if kind.is_empty() || kind.len() > 40 || !kind.bytes().all(|b| b.is_ascii_graphic()) {
        return Err("the material's \"type\" must be a short printable name".into());
    }
    Ok(MaterialCase {
        name: kind,
        material: value,
        reciprocal,
    })
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.furnace {
        return furnace(args);
    }
    if args.target.python_course.is_none() && args.target.adapter.is_none() {
        anyhow::bail!("give the candidate: --adapter 'CMD ARGS' or --python-course DIR");
    }
    let command = args.target.command(&args.sandbox)?;
    // Whose breaches are findings about the model: the course's models for a course
    // submission (week 9's sampling from week 9 on), the book's for any other renderer.
    let family = match &args.target.python_course {
        Some(dir) => {
            let week = rtoracle::weekly::week::detect(dir)
                .week
                .map_or(9, |w| w.number());
            Family::Course { cosine: week >= 9 }
        }
        None => Family::Book,
    };
    let cases = if args.material.is_empty() {
        default_materials()
    } else {
        args.material.clone()
    };
    let run = run_options(&args);
    let options = MaterialOptions {
        seed: args.seed,
        samples: args.samples,
        alpha: args.alpha,
    };
    rtoracle::sandbox::facts::announce_on_stderr();
    let report = check_candidate_materials(command, run, &cases, options, Some(family))
        .context("physics")?;
    verdict(args.json, &report, report.to_text(), report.passed())
}

/// `rtoracle physics --furnace`: the furnace scenes, rendered by the candidate (or the reference)
/// and judged against their exact images.
fn furnace(args: Args) -> anyhow::Result<ExitCode> {
    use rtoracle::physics::{CandidateRenderer, FurnaceOptions, ReferenceRenderer, check_furnaces};
    if args.target.python_course.is_some() {
        anyhow::bail!(
            "--furnace takes --adapter or --reference, not --python-course: the course's \
             integrators do not divide a bounce by its pdf, so a furnace's exact answer is not \
             theirs (docs/physics-checks.md)"
        );
    }
    if !args.reference && args.target.adapter.is_none() {
        anyhow::bail!("give the renderer: --adapter 'CMD ARGS' or --reference");
    }
    let options = FurnaceOptions {
        spp: args.furnace_spp,
        renders: args.renders,
        seed: args.seed,
        alpha: args.alpha,
    };
    let report = if args.reference {
        check_furnaces(&mut ReferenceRenderer, options)
    } else {
        let command = args.target.command(&args.sandbox)?;
        let run = run_options(&args);
        rtoracle::sandbox::facts::announce_on_stderr();
        let mut session = rtoracle::candidate::process::session::Session::start(command, run)
            .context("physics")?;
        let mut renderer =
            CandidateRenderer::new(&mut session, Duration::from_millis(args.timeout_ms));
        check_furnaces(&mut renderer, options)
    };
    verdict(args.json, &report, report.to_text(), report.passed())
}

/// The candidate's run options from the command line: the timeouts and the sandbox's limits.
fn run_options(args: &Args) -> RunOptions {
    RunOptions {
        timeout: Duration::from_millis(args.timeout_ms),
        hello_timeout: Duration::from_millis(args.hello_timeout_ms),
        limits: args.sandbox.policy(),
        ..RunOptions::default()
    }
}

/// Prints a report (as JSON, or its `text`) and returns the exit code of its verdict.
fn verdict(
    json: bool,
    report: &impl serde::Serialize,
    text: String,
    passed: bool,
) -> anyhow::Result<ExitCode> {
    if json {
        outln!(
            "{}",
            serde_json::to_string_pretty(report).context("the report as JSON")?
        )?;
    } else {
        out!("{text}")?;
    }
    Ok(ExitCode::from(if passed { 0 } else { crate::cli::FAILED }))
}
