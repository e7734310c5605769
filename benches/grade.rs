//! `cargo bench --bench grade`: grading speed, one submission and a batch of 30 on 2 threads.

fn main() {
    print!("{}", rtoracle::bench::grade::run());
}
