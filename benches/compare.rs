//! `cargo bench --bench compare`: the comparison's speed against a plain difference pass.

fn main() {
    print!("{}", rtoracle::bench::compare::run());
}
