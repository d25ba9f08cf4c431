//! `anim preview` through plain HTTP: what it serves, what it refuses, and that its frames
//! are the pixels `anim render` writes, before and after an edit.

use crate::session::{
    all_full, materials, per_frame, red_floor, rendered_by_anim_render, request, request_with,
    small_showcase, spec, Preview, EDITED_KEY, FIRST_KEY, FRAMES, MATERIALS,
};
use std::io::{Read as _, Write as _};
use std::process::Command;
use std::time::{Duration, Instant};

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
    let before = rendered_by_anim_render(&spec(FIRST_KEY), &materials());
    let state = preview.wait_for(Duration::from_secs(60), all_full);
    assert_eq!(per_frame(&state, "renders"), vec!["2"; FRAMES]);
    for (i, expected) in before.iter().enumerate() {
        let (status, png) = preview.get(&format!("/frame/{i}.png"));
        assert_eq!(status, 200);
        let shown = image::load_from_memory(&png).unwrap().to_rgb8();
        assert!(shown == *expected, "frame {i} differs from anim render's");
    }
    std::fs::write(preview.spec_path(), spec(EDITED_KEY)).unwrap();
    let after = rendered_by_anim_render(&spec(EDITED_KEY), &materials());
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

#[test]
fn an_edit_of_a_file_the_base_scene_includes_renders_the_frames_again() {
    let preview = Preview::start();
    let grey = rendered_by_anim_render(&spec(FIRST_KEY), &materials());
    preview.wait_for(Duration::from_secs(60), all_full);
    // The floor shows in every frame, so every frame changes.
    let red = red_floor(&materials());
    let reddened = rendered_by_anim_render(&spec(FIRST_KEY), &red);
    for (i, (g, r)) in grey.iter().zip(&reddened).enumerate() {
        assert_ne!(g, r, "frame {i} shows no floor");
    }
    let shows = |expected: &[image::RgbImage], renders: &str, edit: &str| {
        let state = preview.wait_for(Duration::from_secs(60), |s| {
            all_full(s) && per_frame(s, "renders").iter().all(|r| r == renders)
        });
        assert!(state.contains("\"diagnostics\":[]"), "{edit}: {state}");
        for (i, expected) in expected.iter().enumerate() {
            let png = preview.get(&format!("/frame/{i}.png")).1;
            let shown = image::load_from_memory(&png).unwrap().to_rgb8();
            assert!(shown == *expected, "frame {i} after {edit} differs");
        }
    };
    let dir = preview.dir.path();
    std::fs::write(dir.join(MATERIALS), &red).unwrap();
    shows(&reddened, "4", "the edit of the included file");
    // The floor moves to a file that the included file includes: the same statements.
    let all = materials();
    let (floor, others): (Vec<&str>, Vec<&str>) = all
        .lines()
        .partition(|l| l.starts_with("define material floor "));
    std::fs::write(dir.join("floor.sdf"), format!("{}\n", floor[0])).unwrap();
    let nested = format!("include floor.sdf\n{}\n", others.join("\n"));
    std::fs::write(dir.join(MATERIALS), nested).unwrap();
    shows(&grey, "6", "the floor's move to floor.sdf");
    std::fs::write(dir.join("floor.sdf"), red_floor(floor[0])).unwrap();
    shows(
        &reddened,
        "8",
        "the edit of the file the included file includes",
    );
}

#[test]
fn an_edit_of_a_mesh_renders_the_frames_that_draw_it_again() {
    let triangle = |top: f64| format!("v -1 0 0\nv 1 0 0\nv 0 {top} 0\nf 1 2 3\n");
    let preview = Preview::start_with(&[
        ("tri.obj", triangle(1.5)),
        (
            "base.sdf",
            "define material m 0.2 0.2 0.2 0.8 0.3 0.3 0 0 0 1\n\
             define shape obj tri tri.obj m\n\
             define light l 0 0 5 1 1 1 1\n\
             define camera cam 60 0 0.5 4 0 0 -1 0 1 0\n"
                .to_string(),
        ),
        (
            "spec.ron",
            r#"(scene: File("base.sdf"), camera: "cam", fps: 4, length: Frames(2),
                resolution: (32, 24), output: "frame_{frame}.png",
                tracks: [(target: "tri", translate: [(at: 0, value: (0, 0, 0)),
                                                     (at: 0.25, value: (0.5, 0, 0))])])"#
                .to_string(),
        ),
    ]);
    let renders = |s: &str| per_frame(s, "renders");
    let full = |s: &str| per_frame(s, "state") == ["full", "full"];
    let state = preview.wait_for(Duration::from_secs(60), |s| full(s));
    assert_eq!(renders(&state), ["2", "2"], "{state}");
    let before = preview.get("/frame/0.png").1;
    std::fs::write(preview.dir.path().join("tri.obj"), triangle(0.75)).unwrap();
    let state = preview.wait_for(Duration::from_secs(60), |s| {
        full(s) && renders(s) == ["4", "4"]
    });
    assert!(state.contains("\"diagnostics\":[]"), "{state}");
    assert_ne!(preview.get("/frame/0.png").1, before);
}

/// The showcase, small, with a sphere scaled below what a float holds (`anim render` says it
/// is not drawn) in its root.
fn with_a_lost_sphere() -> String {
    let root = "define shape composite root ground board lens ball pillar crate ring";
    let scene = small_showcase();
    assert!(scene.contains(root));
    let tiny = format!(
        "define shape sphere tiny 0 0 0 1 red\n{}{root} tiny",
        "transform tiny scale 1e-8\n".repeat(6)
    );
    scene.replace(root, &tiny)
}

/// The warnings `anim render` prints for scene file `text`, as it prints them.
fn warnings_of_anim_render(text: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.sdf"), text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_anim"))
        .args(["render", "scene.sdf"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{stderr}");
    // The warnings come first, then what was written and the totals.
    let warnings = stderr.split("\nwrote ").next().unwrap();
    warnings.to_string() + "\n"
}

#[test]
fn the_preview_shows_the_warnings_anim_render_prints() {
    let scene = with_a_lost_sphere();
    let printed = warnings_of_anim_render(&scene);
    assert!(
        printed.contains("warning: shape 'root/tiny' is degenerate once transformed"),
        "{printed}"
    );
    // The state is JSON: lines joined by `\n`, and nothing else in them to escape.
    assert!(!printed.contains(['"', '\\', '<', '>', '&']), "{printed}");
    let in_state = printed.trim_end().replace('\n', "\\n");
    let preview = Preview::start_scene_of(&scene);
    let state = preview.wait_for(Duration::from_secs(60), |s| {
        per_frame(s, "state") == ["full"] && s.contains("is degenerate")
    });
    assert!(state.contains(&in_state), "{state}\n---\n{printed}");
    // The terminal hears of it too, once.
    let start = std::time::Instant::now();
    while !preview.terminal().contains(&printed) && start.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(50));
    }
    let terminal = preview.terminal();
    assert_eq!(terminal.matches(&printed).count(), 1, "{terminal}");
    // The warning goes with the shape.
    std::fs::write(preview.dir.path().join("scene.sdf"), small_showcase()).unwrap();
    let state = preview.wait_for(Duration::from_secs(60), |s| {
        per_frame(s, "state") == ["full"] && !s.contains("is degenerate")
    });
    assert!(state.contains("\"warnings\":[]"), "{state}");
}

/// A one-frame scene, small, under `ulimit -n 1024`: 600 connections that never send a byte
/// (about 510 once made the server's library panic on accept and refuse every connection
/// from then on). The page is served while they are open and after they are gone.
#[test]
fn half_open_connections_leave_the_page_served() {
    let preview = Preview::start_limited(&[("scene.sdf", small_showcase())], "-n 1024");
    let mut idle = Vec::new();
    for _ in 0..600 {
        match std::net::TcpStream::connect(("127.0.0.1", preview.port)) {
            Ok(s) => idle.push(s),
            Err(e) => panic!("connection {} refused: {e}", idle.len()),
        }
    }
    let (status, body) = preview.get("/");
    assert_eq!(status, 200);
    assert!(String::from_utf8_lossy(&body).contains("<html"));
    drop(idle);
    let (status, _) = preview.get("/");
    assert_eq!(status, 200);
    assert_eq!(preview.get("/api/state").0, 200);
}

/// One client pipelines requests for the script and never reads an answer: another client's
/// request is answered within a second all the same (it once waited for the first).
#[test]
fn a_client_that_never_reads_does_not_delay_another() {
    let preview = Preview::start_scene();
    let port = preview.port;
    let mut hog = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
    hog.set_write_timeout(Some(Duration::from_secs(3))).unwrap();
    let one = format!("GET /app.js HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n");
    let many = one.repeat(2000);
    // Until the server stops taking requests because the hog's answers fill its socket.
    let _ = hog.write_all(many.as_bytes());
    for _ in 0..3 {
        let start = Instant::now();
        let (status, _) = preview.get("/style.css");
        assert_eq!(status, 200);
        let took = start.elapsed();
        assert!(took < Duration::from_secs(1), "took {took:?}");
    }
    drop(hog);
}

/// The event stream of a 100,000-frame spec, for ten seconds once it is built: the whole
/// state once, then only the frames that changed (it once sent the whole state, megabytes,
/// ten times a second).
#[test]
fn an_event_stream_sends_what_changed() {
    let frames = 100_000;
    let big = spec(FIRST_KEY)
        .replace("length: Frames(6)", &format!("length: Frames({frames})"))
        .replace("resolution: (96, 54)", "resolution: (16, 9)");
    // One sphere, so that a hundred thousand frame files stay small.
    let scene = "define camera cam 60 0 0 9 0 0 -1 0 1 0\n\
                 define material m 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 1\n\
                 define light l 0 10 0 1 1 1\n\
                 define shape sphere ball 0 0 0 1 m\n";
    let preview = Preview::start_with(&[("showcase.sdf", scene.to_string()), ("big.ron", big)]);
    preview.wait_for(Duration::from_secs(300), |s| !s.contains("\"builds\":0,"));
    let mut events = std::net::TcpStream::connect(("127.0.0.1", preview.port)).unwrap();
    write!(
        events,
        "GET /events HTTP/1.1\r\nHost: 127.0.0.1:{}\r\n\r\n",
        preview.port
    )
    .unwrap();
    let start = Instant::now();
    let mut received = Vec::new();
    let mut chunk = vec![0u8; 1 << 16];
    while start.elapsed() < Duration::from_secs(10) {
        events
            .set_read_timeout(Some(Duration::from_millis(200)))
            .unwrap();
        match events.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => received.extend_from_slice(&chunk[..n]),
            Err(_) => {}
        }
    }
    let text = String::from_utf8_lossy(&received);
    // The whole state came first: every frame is in it.
    let first = text.split("\n\n").next().unwrap_or("");
    let shown = first.get(..200).unwrap_or(first);
    assert_eq!(first.matches("\"state\":").count(), frames, "{shown}");
    let deltas = text.matches("event: delta\ndata: ").count();
    assert!(deltas > 0, "no delta in {} bytes", received.len());
    assert!(
        received.len() < 10 << 20,
        "{} bytes in 10 s",
        received.len()
    );
}
