//! `anim preview` through plain HTTP: what it serves, what it refuses, and that its frames
//! are the pixels `anim render` writes, before and after an edit.

use crate::session::{
    all_full, per_frame, rendered_by_anim_render, request, request_with, spec, Preview, EDITED_KEY,
    FIRST_KEY, FRAMES,
};
use std::time::Duration;

#[test]
fn refuses_what_is_not_its_own() {
    let preview = Preview::start();
    let port = preview.port;
    let own = format!("127.0.0.1:{port}");
    assert_eq!(preview.get("/").0, 200);
    assert_eq!(
        request(port, "GET", "/", &format!("localhost:{port}")).0,
        200
    );
    // Climbing out, plain, encoded (either case) and with backslashes.
    for path in [
        "/../etc/passwd",
        "/../../../../../../etc/passwd",
        "/frame/../../etc/passwd",
        "/%2e%2e/%2e%2e/etc/passwd",
        "/%2E%2E%2Fsmall.ron",
        "/frame/%2e%2e%2fsmall.ron",
        "/..%5c..%5cetc%5cpasswd",
        "/..\\small.ron",
        "//etc/passwd",
    ] {
        let (status, body) = preview.get(path);
        assert!((400..500).contains(&status), "{path}: {status}");
        assert!(!String::from_utf8_lossy(&body).contains("root:"), "{path}");
    }
    // Absolute paths: in the request line, and as a file of the preview's own folder.
    for path in [
        "/etc/passwd",
        "http://127.0.0.1/etc/passwd",
        "/small.ron",
        "/showcase.sdf",
        "/frames/frame_0.sdf",
        "/export/../small.ron",
    ] {
        let (status, _) = preview.get(path);
        assert!((400..500).contains(&status), "{path}: {status}");
    }
    // DNS rebinding: a page of another site reaching this port names its own host.
    for host in [
        "evil.example",
        "evil.example:80",
        "127.0.0.1:1",
        "localhost",
    ] {
        let (status, _) = request(port, "GET", "/api/state", host);
        assert_eq!(status, 421, "Host: {host}");
    }
    assert_eq!(request(port, "GET", "/", &own).0, 200);
    // No route writes, and methods other than the routes' are refused.
    for (method, path) in [
        ("PUT", "/frame/0.png"),
        ("POST", "/frame/0.png"),
        ("DELETE", "/"),
    ] {
        assert!((400..500).contains(&request(port, method, path, &own).0));
    }
    // A page of another site posting to this address names its own origin.
    let posted = |origin: &str| {
        let headers = format!("Host: {own}\r\nOrigin: {origin}\r\n");
        request_with(port, "POST", "/api/focus?frame=1", &headers).0
    };
    assert_eq!(posted("http://evil.example"), 403);
    assert_eq!(posted(&format!("http://{own}")), 200);
}

#[test]
fn serves_the_frames_anim_render_draws_and_follows_an_edit() {
    let mut preview = Preview::start();
    let before = rendered_by_anim_render(&spec(FIRST_KEY));
    let state = preview.wait_for(Duration::from_secs(60), all_full);
    assert_eq!(per_frame(&state, "renders"), vec!["2"; FRAMES]);
    for (i, expected) in before.iter().enumerate() {
        let (status, png) = preview.get(&format!("/frame/{i}.png"));
        assert_eq!(status, 200);
        let shown = image::load_from_memory(&png).unwrap().to_rgb8();
        assert!(shown == *expected, "frame {i} differs from anim render's");
    }
    std::fs::write(preview.spec_path(), spec(EDITED_KEY)).unwrap();
    let after = rendered_by_anim_render(&spec(EDITED_KEY));
    let state = preview.wait_for(Duration::from_secs(60), |s| {
        all_full(s) && per_frame(s, "renders")[0] == "4"
    });
    // Frames 0 and 1 changed (small, then full); the others were not rendered again.
    let renders = per_frame(&state, "renders");
    assert_eq!(renders, ["4", "4", "2", "2", "2", "2"], "{state}");
    for (i, expected) in after.iter().enumerate() {
        let png = preview.get(&format!("/frame/{i}.png")).1;
        let shown = image::load_from_memory(&png).unwrap().to_rgb8();
        assert!(shown == *expected, "frame {i} after the edit differs");
    }
    assert_ne!(before[0], after[0]);
    assert_eq!(before[5], after[5]);
    // An error keeps the frames and says where it is.
    std::fs::write(preview.spec_path(), spec("(0, 1.5,, 0)")).unwrap();
    let state = preview.wait_for(Duration::from_secs(20), |s| {
        !s.contains("\"diagnostics\":[]")
    });
    assert!(state.contains("small.ron:10:"), "{state}");
    assert_eq!(preview.get("/frame/0.png").0, 200);
    assert_eq!(preview.temporary_files(), 1);
    assert!(preview.stop(), "Ctrl-C did not end the preview cleanly");
    assert_eq!(preview.temporary_files(), 0, "Ctrl-C left temporary files");
}

#[test]
fn a_scene_file_is_one_frame_and_its_errors_are_located() {
    let preview = Preview::start_scene();
    let state = preview.wait_for(Duration::from_secs(60), |s| {
        per_frame(s, "state") == ["full"]
    });
    assert!(state.contains("\"diagnostics\":[]"), "{state}");
    let png = preview.get("/frame/0.png").1;
    let shown = image::load_from_memory(&png).unwrap().to_rgb8();
    assert_eq!(shown.dimensions(), (96, 54));
    let scene = preview.dir.path().join("scene.sdf");
    let text = std::fs::read_to_string(&scene).unwrap();
    let broken = text.replace("sphere lens 0 0.2 0 1.2 glass", "sphere lens 0 0.2 0 glass");
    std::fs::write(&scene, broken).unwrap();
    let state = preview.wait_for(Duration::from_secs(20), |s| {
        !s.contains("\"diagnostics\":[]")
    });
    let line = 1 + text
        .lines()
        .position(|l| l.contains("sphere lens"))
        .unwrap();
    assert!(state.contains(&format!("scene.sdf:{line}:")), "{state}");
    assert_eq!(
        preview.get("/frame/0.png").1,
        png,
        "the last good frame stays"
    );
}
