//! Renders a built-in scene with one of the common mistakes injected, as a course-encoded PNG:
//! `cargo run --release --example mistake -- SCENE MISTAKE OUT.png [SEED]`.
//! MISTAKE is one of: honest, no-gamma, gamma22, albedo, half-pixel, jitter01, flip-y, flip-x,
//! bgr,
//! fov, missing, sky.

use rtoracle::compare::diagnose::mistakes::{Mistake, render_with_mistake};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scene, mistake, out, rest @ ..] = args.as_slice() else {
        anyhow::bail!("usage: mistake SCENE MISTAKE OUT.png [SEED]");
    };
    let mistake = Mistake::from_argument(mistake)
        .ok_or_else(|| anyhow::anyhow!("unknown mistake '{mistake}'"))?;
    let seed = rest.first().map(|s| s.parse()).transpose()?.unwrap_or(1);
    let description = rtoracle::scene::builtin(scene)?;
    let spp = description.image.samples_per_pixel;
    let image = render_with_mistake(&description, mistake, spp, seed);
    rtoracle::image_io::write_png(std::path::Path::new(out), &image)?;
    eprintln!(
        "wrote {out}: {scene} with '{}', {spp} spp, seed {seed}",
        mistake.name()
    );
    Ok(())
}
