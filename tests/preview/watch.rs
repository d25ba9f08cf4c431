//! The watcher against files that never end or never come: a named pipe as a mesh, as the
//! scene file after an edit, or as a spec's base scene gives a diagnostic within seconds, and
//! Ctrl-C still stops the preview at once (each once blocked it for good).

use crate::session::{small_showcase, spec, Preview, FIRST_KEY};
use std::path::Path;
use std::time::{Duration, Instant};

fn make_fifo(path: &Path) {
    let _ = std::fs::remove_file(path);
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .unwrap();
    assert!(status.success());
}

/// Stops the preview as Ctrl-C does, and checks it ended cleanly within two seconds.
fn stops_at_once(mut preview: Preview) {
    let start = Instant::now();
    assert!(preview.stop(), "the preview did not end cleanly");
    let took = start.elapsed();
    assert!(took < Duration::from_secs(2), "stopping took {took:?}");
}

/// Waits at most five seconds for a diagnostic that holds `wanted`.
fn shows(preview: &Preview, wanted: &str) {
    let within = Duration::from_secs(5);
    preview.wait_for(within, |s| {
        s.split("\"diagnostics\":[")
            .nth(1)
            .is_some_and(|d| d.contains(wanted))
    });
}

#[test]
fn a_pipe_as_a_mesh_shows_a_diagnostic_and_ctrl_c_stops() {
    let scene = small_showcase() + "define shape obj pipe part.obj floor\n";
    let dir = tempfile::tempdir().unwrap();
    make_fifo(&dir.path().join("part.obj"));
    let preview = Preview::start_in(dir, &[("scene.sdf", scene)]);
    shows(&preview, "part.obj");
    shows(&preview, "not a regular file");
    stops_at_once(preview);
}

#[test]
fn a_scene_file_replaced_by_a_pipe_shows_a_diagnostic_and_ctrl_c_stops() {
    let preview = Preview::start_scene();
    preview.wait_for(Duration::from_secs(60), |s| {
        s.contains("\"state\":\"full\"")
    });
    make_fifo(&preview.dir.path().join("scene.sdf"));
    shows(&preview, "scene.sdf");
    stops_at_once(preview);
}

#[test]
fn a_pipe_as_a_specs_base_scene_shows_a_diagnostic_and_ctrl_c_stops() {
    let dir = tempfile::tempdir().unwrap();
    make_fifo(&dir.path().join("showcase.sdf"));
    let preview = Preview::start_in(dir, &[("small.ron", spec(FIRST_KEY))]);
    shows(&preview, "showcase.sdf");
    stops_at_once(preview);
}
