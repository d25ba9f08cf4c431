//! One running `anim preview`, on a small copy of `animations/orbit.ron` in a temporary
//! folder (its base scene including its materials from a file of their own), stopped with
//! Ctrl-C (SIGINT) when dropped; and plain HTTP/1.1 over a socket.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The test animation: the orbit, small and short, with one keyed track whose first key
/// shapes frames 0 and 1 only (frames from 0.25 s on hold the last key).
pub fn spec(first_key: &str) -> String {
    format!(
        r#"(
    scene: File("showcase.sdf"),
    camera: "cam",
    fps: 8,
    length: Frames(6),
    resolution: (96, 54),
    output: "frame_{{frame}}.png",
    orbit: (center: (0, 0, 0), radius: 9, height: 3.5, turns: 1, look_at: (0, -0.2, 0)),
    tracks: [
        (target: "ball", translate: [(at: 0, value: {first_key}), (at: 0.25, value: (0, 0.5, 0))]),
    ],
)
"#
    )
}

/// `animations/showcase.sdf`, the orbit's base scene.
pub fn showcase() -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(root.join("animations/showcase.sdf")).unwrap()
}

/// The file the test animation's base scene includes its materials from.
pub const MATERIALS: &str = "materials.sdf";

/// The showcase's material lines, the test animation's `materials.sdf`.
pub fn materials() -> String {
    showcase_lines(true)
}

/// The showcase with its materials taken from `materials.sdf`, the test animation's base scene.
fn base_scene() -> String {
    format!("include {MATERIALS}\n{}", showcase_lines(false))
}

/// The lines of the showcase that define materials, or the others.
fn showcase_lines(materials: bool) -> String {
    let text = showcase();
    let lines = text
        .lines()
        .filter(|l| l.starts_with("define material ") == materials);
    lines.map(|l| format!("{l}\n")).collect()
}

/// `materials` with the floor of the showcase red instead of grey.
pub fn red_floor(materials: &str) -> String {
    let grey = "define material floor  0.12 0.12 0.11  0.55 0.52 0.48  0.1 0.1 0.1   8";
    assert!(materials.contains(grey));
    materials.replace(
        grey,
        "define material floor  0.15 0.02 0.02  0.8 0.1 0.1  0.1 0.1 0.1   8",
    )
}

pub const FIRST_KEY: &str = "(0, 0, 0)";
pub const EDITED_KEY: &str = "(0, 1.5, 0)";
pub const FRAMES: usize = 6;

/// A folder holding the test animation: `small.ron`, its base scene `showcase.sdf` and the
/// materials file that includes.
pub fn test_animation() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("showcase.sdf"), base_scene()).unwrap();
    std::fs::write(dir.path().join(MATERIALS), materials()).unwrap();
    std::fs::write(dir.path().join("small.ron"), spec(FIRST_KEY)).unwrap();
    dir
}

pub struct Preview {
    pub dir: tempfile::TempDir,
    pub port: u16,
    child: Child,
    /// What it has printed on stderr so far.
    terminal: Arc<Mutex<String>>,
}

impl Preview {
    /// Starts `anim preview` on the test animation; returns once it prints its address.
    pub fn start() -> Preview {
        Preview::launch(test_animation(), "small.ron")
    }

    /// Starts `anim preview` on one scene file, `scene.sdf`: the showcase, small.
    pub fn start_scene() -> Preview {
        Preview::start_scene_of(&small_showcase())
    }

    /// Starts `anim preview` on one scene file, `scene.sdf`, holding `scene`.
    pub fn start_scene_of(scene: &str) -> Preview {
        Preview::start_with(&[("scene.sdf", scene.to_string())])
    }

    /// Starts `anim preview` on the last of `files` (name, text), written first.
    pub fn start_with(files: &[(&str, String)]) -> Preview {
        Preview::start_in(tempfile::tempdir().unwrap(), files)
    }

    /// Starts `anim preview` in `dir` (which may hold other files) on the last of `files`
    /// (name, text), written first.
    pub fn start_in(dir: tempfile::TempDir, files: &[(&str, String)]) -> Preview {
        for (name, text) in files {
            std::fs::write(dir.path().join(name), text).unwrap();
        }
        let input = files.last().unwrap().0;
        Preview::launch(dir, input)
    }

    /// Starts `anim preview` on the last of `files` (name, text), written first, under the
    /// shell's `ulimit` with `limit` (e.g. `-n 1024`).
    pub fn start_limited(files: &[(&str, String)], limit: &str) -> Preview {
        let dir = tempfile::tempdir().unwrap();
        for (name, text) in files {
            std::fs::write(dir.path().join(name), text).unwrap();
        }
        let input = files.last().unwrap().0;
        Preview::launch_with(dir, input, Some(limit))
    }

    fn launch(dir: tempfile::TempDir, input: &str) -> Preview {
        Preview::launch_with(dir, input, None)
    }

    fn launch_with(dir: tempfile::TempDir, input: &str, limit: Option<&str>) -> Preview {
        std::fs::create_dir(dir.path().join("tmp")).unwrap();
        let mut command = match limit {
            // `exec` keeps the pid, so Ctrl-C (SIGINT) still reaches the preview.
            Some(limit) => {
                let mut c = Command::new("sh");
                c.arg("-c")
                    .arg(format!(
                        "ulimit {limit} && exec \"$0\" preview \"$1\" --port 0"
                    ))
                    .arg(env!("CARGO_BIN_EXE_anim"))
                    .arg(input);
                c
            }
            None => {
                let mut c = Command::new(env!("CARGO_BIN_EXE_anim"));
                c.args(["preview", input, "--port", "0"]);
                c
            }
        };
        let mut child = command
            .current_dir(dir.path())
            .env("TMPDIR", dir.path().join("tmp"))
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
        let first = lines.next().unwrap().unwrap();
        // The rest of stderr is kept, and read as it comes so the preview never blocks
        // writing it.
        let terminal = Arc::new(Mutex::new(String::new()));
        let kept = terminal.clone();
        std::thread::spawn(move || {
            for line in lines.map_while(Result::ok) {
                let mut kept = kept.lock().unwrap();
                kept.push_str(&line);
                kept.push('\n');
            }
        });
        let port = first
            .rsplit("http://127.0.0.1:")
            .next()
            .and_then(|p| p.trim_end_matches('/').parse().ok())
            .unwrap_or_else(|| panic!("no address in {first:?}"));
        Preview {
            dir,
            port,
            child,
            terminal,
        }
    }

    /// What the preview has printed on stderr after its address.
    pub fn terminal(&self) -> String {
        self.terminal.lock().unwrap().clone()
    }

    /// The entries of the preview's `TMPDIR`: its temporary folder while it runs.
    pub fn temporary_files(&self) -> usize {
        std::fs::read_dir(self.dir.path().join("tmp"))
            .unwrap()
            .count()
    }

    pub fn spec_path(&self) -> PathBuf {
        self.dir.path().join("small.ron")
    }

    /// GET `path` with the right `Host`.
    pub fn get(&self, path: &str) -> (u16, Vec<u8>) {
        request(self.port, "GET", path, &format!("127.0.0.1:{}", self.port))
    }

    pub fn state(&self) -> String {
        let (status, body) = self.get("/api/state");
        assert_eq!(status, 200);
        String::from_utf8(body).unwrap()
    }

    /// Waits until `done` holds for the state, at most `limit`; returns that state.
    pub fn wait_for(&self, limit: Duration, done: impl Fn(&str) -> bool) -> String {
        let start = Instant::now();
        loop {
            let state = self.state();
            if done(&state) {
                return state;
            }
            assert!(start.elapsed() < limit, "gave up waiting; state: {state}");
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// Stops the preview as Ctrl-C does; returns whether it ended cleanly.
    pub fn stop(&mut self) -> bool {
        self.signal("INT")
    }

    /// Sends the preview signal `name` (`INT`, `TERM`, `HUP`); returns whether it ended
    /// cleanly within 10 s.
    pub fn signal(&mut self, name: &str) -> bool {
        let _ = Command::new("kill")
            .args([&format!("-{name}"), &self.child.id().to_string()])
            .status();
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(10) {
            if let Ok(Some(status)) = self.child.try_wait() {
                return status.success();
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        false
    }
}

impl Drop for Preview {
    fn drop(&mut self) {
        // As a user stops it, so it removes its temporary folder; killed only if it hangs.
        if !matches!(self.child.try_wait(), Ok(Some(_))) && !self.stop() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// The value of `"field":N` in each frame of a state, in order.
pub fn per_frame(state: &str, field: &str) -> Vec<String> {
    let frames = state.split("\"frames\":[").nth(1).unwrap_or("");
    let frames = frames.split("],\"diagnostics\"").next().unwrap_or("");
    frames
        .split("},{")
        .filter_map(|f| {
            let rest = f.split(&format!("\"{field}\":")).nth(1)?;
            let end = rest.find([',', '}']).unwrap_or(rest.len());
            Some(rest[..end].trim_matches('"').to_string())
        })
        .collect()
}

pub fn all_full(state: &str) -> bool {
    let states = per_frame(state, "state");
    states.len() == FRAMES && states.iter().all(|s| s == "full")
}

/// One HTTP/1.1 request with the given `Host`; the status and body of the answer.
pub fn request(port: u16, method: &str, path: &str, host: &str) -> (u16, Vec<u8>) {
    request_with(port, method, path, &format!("Host: {host}\r\n"))
}

/// One HTTP/1.1 request with the given header lines; the status and body of the answer.
pub fn request_with(port: u16, method: &str, path: &str, headers: &str) -> (u16, Vec<u8>) {
    let mut stream = TcpStream::connect(("127.0.0.1", port)).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    write!(
        stream,
        "{method} {path} HTTP/1.1\r\n{headers}Connection: close\r\nContent-Length: 0\r\n\r\n"
    )
    .unwrap();
    let mut answer = Vec::new();
    let _ = stream.read_to_end(&mut answer);
    let head_end = answer
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .unwrap_or_else(|| panic!("no HTTP answer: {:?}", String::from_utf8_lossy(&answer)));
    let head = String::from_utf8_lossy(&answer[..head_end]).into_owned();
    let status = head
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap();
    (status, answer[head_end + 4..].to_vec())
}

/// The showcase as one scene file, small.
pub fn small_showcase() -> String {
    showcase().replace("render cam showcase.png 640 360", "render cam s.png 96 54")
}

/// The frames `anim render` writes for the test animation as `spec_text` and the materials
/// file `materials_text` say, decoded.
pub fn rendered_by_anim_render(spec_text: &str, materials_text: &str) -> Vec<image::RgbImage> {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("showcase.sdf"), base_scene()).unwrap();
    std::fs::write(dir.path().join(MATERIALS), materials_text).unwrap();
    std::fs::write(dir.path().join("small.ron"), spec_text).unwrap();
    let anim = env!("CARGO_BIN_EXE_anim");
    let frames = dir.path().join("frames");
    let ok = |args: &[&str]| {
        let out = Command::new(anim)
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    ok(&["generate", "small.ron", "-o", "frames", "--quiet"]);
    ok(&["render", "frames", "--quiet"]);
    // The names are padded alike, so their order is the frames'.
    let mut pngs: Vec<PathBuf> = std::fs::read_dir(&frames)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "png"))
        .collect();
    pngs.sort();
    assert_eq!(pngs.len(), FRAMES);
    pngs.iter()
        .map(|p| image::open(p).unwrap().to_rgb8())
        .collect()
}
