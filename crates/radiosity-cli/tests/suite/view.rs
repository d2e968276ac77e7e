//! `radiosity view` where it cannot open a window: a message that says what is missing and
//! what to do, exit status 1, no panic.

use crate::fixtures::radiosity_command;

#[test]
fn view_without_a_display_says_what_to_do() {
    // Unset, or set but empty (QA of issue #16: the empty ones got GPU advice).
    for empty in [false, true] {
        let mut command = radiosity_command();
        command.arg("view");
        if empty {
            command.env("DISPLAY", "").env("WAYLAND_DISPLAY", "");
        } else {
            command.env_remove("DISPLAY").env_remove("WAYLAND_DISPLAY");
        }
        let out = command.output().expect("the radiosity binary runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "stderr: {err}");
        assert!(!err.contains("panicked"), "{err}");
        if cfg!(feature = "viewer") {
            assert!(
                err.contains("no display") && err.contains("xvfb-run"),
                "{err}"
            );
            assert!(!err.contains("mesa-vulkan-drivers"), "{err}");
        } else {
            assert!(err.contains("feature `viewer`"), "{err}");
        }
    }
}

#[cfg(feature = "viewer")]
#[test]
fn view_bench_refuses_zero_counts_up_front() {
    for (flag, value) in [("--bench-elements", "1000,0"), ("--bench-frames", "0")] {
        let out = radiosity_command()
            .args(["view", "--bench", flag, value])
            .output()
            .expect("the radiosity binary runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{flag}: {err}");
        assert!(err.contains(flag) && err.contains("at least 1"), "{err}");
        assert!(
            !err.contains("inf") && !err.contains("view --bench:"),
            "nothing ran: {err}"
        );
    }
}

#[cfg(feature = "viewer")]
#[test]
fn view_with_no_x_server_at_display_names_display() {
    // DISPLAY set to a display nothing serves (QA of issue #16: GPU advice and a path into
    // the cargo registry). Where no graphics adapter is found at all, that is said first.
    let out = radiosity_command()
        .arg("view")
        .env("DISPLAY", ":4711")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("the radiosity binary runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "stderr: {err}");
    assert!(
        !err.contains("panicked") && !err.contains(".cargo"),
        "{err}"
    );
    if !err.contains("adapter") {
        assert!(
            err.contains("DISPLAY=:4711") && err.contains("xvfb-run"),
            "{err}"
        );
    }
}
