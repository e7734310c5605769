#![no_main]
//! Fuzz target `triangle`: see `rtoracle::oracle::fuzzing::check_triangle_bytes`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(v) = rtoracle::oracle::fuzzing::check_triangle_bytes(data) {
        panic!("{v}");
    }
});
