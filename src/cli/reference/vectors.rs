use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use rtoracle::oracle::generate::generate_with;
use rtoracle::oracle::profile::Profile;
use rtoracle::oracle::suite::{DEFAULT_COUNT, suite_with};
use rtoracle::oracle::vectors::{SCHEMA_VERSION, ShapeKind};
use rtoracle::output::OutputFile;

/// `rtoracle vectors [--seed S] [--count N] [--shapes sphere,quad,triangle] -o FILE.jsonl`
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Seed of the generators: the same seed gives the same bytes.
    #[arg(long, value_name = "S", default_value_t = 0, value_parser = crate::cli::args::seed)]
    seed: u64,
    /// Number of generated vectors (the default suite has 4000).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_COUNT, value_parser = crate::cli::args::count)]
    count: usize,
    /// Comma-separated shapes to generate.
    #[arg(long, value_name = "LIST", default_value = "sphere,quad,triangle")]
    shapes: String,
    #[command(flatten)]
    judging: crate::cli::args::JudgingArgs,
    /// Add the watertight groups of the shapes asked for after the generated vectors, as the
    /// built-in suite of `check` has them (`--count 4000 --watertight` is that suite).
    #[arg(long)]
    watertight: bool,
    /// The JSON-lines file to write; `FILE.jsonl.meta.json` (the name with `.meta.json`
    /// added) is written beside it.
    #[arg(short, long, value_name = "FILE.jsonl")]
    output: PathBuf,
}

/// Parses a `--shapes` list.
pub fn parse_shapes(list: &str) -> anyhow::Result<Vec<ShapeKind>> {
    let mut out = Vec::new();
    for name in list.split(',').map(str::trim) {
        let kind = ShapeKind::from_name(name).with_context(|| {
            format!("--shapes {list}: unknown shape {name:?} (expected sphere, quad or triangle)")
        })?;
        if !out.contains(&kind) {
            out.push(kind);
        }
    }
    out.sort();
    Ok(out)
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let shapes = parse_shapes(&args.shapes)?;
    let count = args.count;
    let mut meta_path = args.output.clone().into_os_string();
    meta_path.push(".meta.json");
    let meta_path = PathBuf::from(meta_path);
    // Both files are checked before the work and appear together, whole, or not at all.
    let mut out = OutputFile::create(&args.output, "-o")?;
    let mut meta_out = OutputFile::create(&meta_path, "-o")?;
    let judging = args.judging.judging(Profile::Course);
    let cases = if args.watertight {
        suite_with(args.seed, count, &shapes, judging)
    } else {
        generate_with(args.seed, count, &shapes, judging)
    };
    let mut text = String::with_capacity(cases.len() * 400);
    let mut classes = std::collections::BTreeMap::<String, usize>::new();
    for c in &cases {
        text.push_str(&c.to_json_line());
        text.push('\n');
        let class = serde_json::to_value(c.expect.class)?;
        *classes
            .entry(class.as_str().unwrap_or("?").to_string())
            .or_default() += 1;
    }
    let meta = serde_json::json!({
        "schema_version": SCHEMA_VERSION,
        "generator": format!("rtoracle {}", env!("CARGO_PKG_VERSION")),
        "seed": args.seed,
        "count": cases.len(),
        "shapes": shapes.iter().map(|k| k.name()).collect::<Vec<_>>(),
        "classes": classes,
        "profile": judging.profile,
        "precision": judging.precision,
        "judged_by": judging.to_string(),
    });
    out.write_all(text.as_bytes())?;
    meta_out.write_all((serde_json::to_string_pretty(&meta)? + "\n").as_bytes())?;
    out.commit()?;
    meta_out.commit()?;
    errln!(
        "wrote {} vectors judged by {judging} to {} ({})",
        cases.len(),
        args.output.display(),
        classes
            .iter()
            .map(|(k, v)| format!("{v} {k}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(ExitCode::SUCCESS)
}
