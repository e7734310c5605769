//! `cargo bench --bench oracle`: the oracle's figures (see `rtoracle::bench::oracle`).
//! `ORACLE_BENCH_SPHERES=N` changes the number of random sphere cases (default 10^6).

fn main() {
    let mut opts = rtoracle::bench::oracle::Options::default();
    if let Some(n) = std::env::var("ORACLE_BENCH_SPHERES")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        opts.sphere_cases = n;
        opts.plane_cases = n / 5;
        opts.silhouette_cases = (n / 10).max(1000);
    }
    print!("{}", rtoracle::bench::oracle::run(opts));
}
