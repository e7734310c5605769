#![no_main]
//! Fuzz target `sphere`: see `rtoracle::oracle::fuzzing::check_sphere_bytes`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(v) = rtoracle::oracle::fuzzing::check_sphere_bytes(data) {
        panic!("{v}");
    }
});
