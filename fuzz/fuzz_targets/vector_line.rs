#![no_main]
//! Fuzz target `vector_line`: see `rtoracle::oracle::fuzzing::check_vector_line_bytes`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(v) = rtoracle::oracle::fuzzing::check_vector_line_bytes(data) {
        panic!("{v}");
    }
});
