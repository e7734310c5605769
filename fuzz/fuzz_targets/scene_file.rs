#![no_main]
//! Fuzz target `scene_file`: see `rtoracle::oracle::fuzzing::check_scene_bytes`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(v) = rtoracle::oracle::fuzzing::check_scene_bytes(data) {
        panic!("{v}");
    }
});
