#![no_main]
//! Fuzz target `quad`: see `rtoracle::oracle::fuzzing::check_quad_bytes`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(v) = rtoracle::oracle::fuzzing::check_quad_bytes(data) {
        panic!("{v}");
    }
});
