//! `radiosity view` where it cannot open a window: a message that says what is missing and
//! what to do, exit status 1, no panic.

use crate::fixtures::radiosity_command;

#[test]
fn view_without_a_display_says_what_to_do() {
    let out = radiosity_command()
        .arg("view")
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("the radiosity binary runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    if cfg!(feature = "viewer") {
        assert!(
            err.contains("no display") && err.contains("xvfb-run"),
            "{err}"
        );
    } else {
        assert!(err.contains("feature `viewer`"), "{err}");
    }
}
