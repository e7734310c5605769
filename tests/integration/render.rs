//! The reference tracer end to end.

use crate::common::*;

#[test]
fn render_writes_a_png_of_the_scene_size() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["render", "week04-sphere", "--spp", "2"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let img = rtoracle::image_io::read_png(&dir.path().join("week04-sphere.png")).unwrap();
    assert_eq!((img.width, img.height), (400, 225));
}
