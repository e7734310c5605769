use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use rtoracle::oracle::explain::explain_with;
use rtoracle::oracle::generate::CAMERA;
use rtoracle::oracle::profile::Profile;
use rtoracle::oracle::vectors::{Case, RaySpec, ShapeSpec, read_vectors};
use rtoracle::oracle::{classify::classify_with, suite::default_suite_with};

/// `rtoracle explain (ID | 'JSON') [--seed S] [--vectors FILE]`
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A vector id (from the default suite, or from --vectors), or one case as JSON: a vector
    /// line, or just `{"shape": .., "ray": .., "interval": ..}` (the interval defaults to the
    /// camera's `(1e-6, f64::MAX)`).
    case: String,
    /// Seed of the default suite the id refers to.
    #[arg(long, value_name = "S", default_value_t = 0, value_parser = crate::cli::args::seed)]
    seed: u64,
    /// A vector file the id refers to instead of the default suite.
    #[arg(long, value_name = "FILE")]
    vectors: Option<PathBuf>,
    #[command(flatten)]
    judging: crate::cli::args::JudgingArgs,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Bare {
    shape: ShapeSpec,
    ray: RaySpec,
    #[serde(default = "camera", with = "rtoracle::oracle::vectors::num2")]
    interval: [f64; 2],
}

fn camera() -> [f64; 2] {
    CAMERA
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let judging = args.judging.judging(Profile::Course);
    let text = args.case.trim();
    let case = if text.starts_with('{') {
        match Case::from_json_line(text) {
            Ok(case) => case,
            Err(_) => {
                let bare: Bare = serde_json::from_str(text)
                    .map_err(|e| anyhow::anyhow!("the case JSON is not valid: {e}"))?;
                Case {
                    id: "(given)".into(),
                    expect: classify_with(&bare.shape, &bare.ray, bare.interval, judging),
                    shape: bare.shape,
                    ray: bare.ray,
                    interval: bare.interval,
                }
            }
        }
    } else {
        let (cases, source) = match &args.vectors {
            Some(path) => (read_vectors(path)?, path.display().to_string()),
            None => (
                default_suite_with(args.seed, judging),
                format!("the default suite (seed {})", args.seed),
            ),
        };
        cases
            .into_iter()
            .find(|c| c.id == text)
            .with_context(|| format!("no vector with id {text:?} in {source}"))?
    };
    out!("{}", explain_with(&case, judging))?;
    Ok(ExitCode::SUCCESS)
}
