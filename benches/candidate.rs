//! `cargo bench --bench candidate`: throughput of candidate checking against baselines.

fn main() {
    match rtoracle::bench::harness::run(Default::default()) {
        Ok(text) => print!("{text}"),
        Err(e) => {
            eprintln!("bench candidate: {e}");
            std::process::exit(2);
        }
    }
}
