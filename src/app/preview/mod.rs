//! `anim preview SPEC.ron|SCENE.sdf`: a local web page that plays the animation while it is
//! rendered, every frame small first and then in full, and follows every edit of its files.
//!
//! The parts, each importing only those after it: `server` (routes, the page, event
//! streams) → `http` (bounded connections) → `export` (ffmpeg) → `watch` (notify, builds again) → `render` (the workers)
//! → `state` (what is shared) → `project` (the spec's frames, via the pipeline).

mod export;
mod http;
mod project;
mod render;
mod server;
mod state;
mod watch;

use anim_core::render::RenderSettings;
use anim_core::sdf::LoadOptions;
use export::Export;
use project::Project;
use rayon::ThreadPool;
use state::Shared;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Arc, Barrier};
use std::time::{Duration, Instant};

/// Everything `anim preview` was asked to do.
#[derive(Clone, Debug)]
pub struct PreviewConfig {
    pub input: PathBuf,
    pub addr: SocketAddr,
    pub open: bool,
    /// Render everything, encode it here and stop, without a server.
    pub export: Option<PathBuf>,
    pub load: LoadOptions,
    /// The full-quality settings, those of `anim render` by default.
    pub settings: RenderSettings,
}

pub fn run(config: &PreviewConfig, pool: &ThreadPool) -> ExitCode {
    if !config.input.is_file() {
        eprintln!("{}: error: no such file", super::shown(&config.input));
        return ExitCode::FAILURE;
    }
    let temp = match tempfile::Builder::new().prefix("anim-preview-").tempdir() {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: cannot make the preview's temporary folder: {e}");
            return ExitCode::FAILURE;
        }
    };
    let project = Project {
        input: config.input.clone(),
        frames_dir: temp.path().join("frames"),
        load: config.load.clone(),
        settings: config.settings.clone(),
    };
    if let Some(out) = &config.export {
        // Before anything renders: a wrong name would otherwise cost the whole render.
        if let Err(e) = export::check_output(out, &project.watched()) {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    }
    let shared = Arc::new(Shared::default());
    {
        let shared = shared.clone();
        // Ctrl-C, SIGTERM (a process manager, `kill`) and SIGHUP (the terminal closed) all
        // stop the preview the same way, so its temporary folder goes with it. A second
        // signal while stopping is the same request.
        let _ = ctrlc::set_handler(move || shared.stop());
    }
    let export = Export::new(temp.path().join("export"));
    let threads = pool.current_num_threads();
    // Every worker holds its pool thread before any renders, so none can start inside
    // another's wait for its rows.
    let all_in = Barrier::new(threads);
    let code = pool.in_place_scope(|scope| {
        for _ in 0..threads {
            let (shared, all_in) = (&shared, &all_in);
            let (load, settings) = (&config.load, &config.settings);
            // The pool's threads have the stack deep recursion needs.
            scope.spawn(move |_| {
                all_in.wait();
                render::worker(shared, load, settings);
            });
        }
        let (watcher_done, watcher_ended) = std::sync::mpsc::channel::<()>();
        {
            let (project, shared) = (project.clone(), shared.clone());
            std::thread::spawn(move || {
                watch::follow(&project, &shared);
                drop(watcher_done);
            });
        }
        let code = match &config.export {
            Some(out) => export_only(&shared, &export, out),
            None => serve(config, &shared, export),
        };
        shared.stop();
        // A build under way ends at its next file; one stuck on a file is left behind, so
        // that Ctrl-C always ends the preview.
        let _ = watcher_ended.recv_timeout(WATCHER_STOP);
        code
    });
    drop(temp);
    code
}

/// How long a stop waits for the watcher to end.
const WATCHER_STOP: Duration = Duration::from_secs(1);

/// Serves the page until Ctrl-C.
fn serve(config: &PreviewConfig, shared: &Arc<Shared>, export: Export) -> ExitCode {
    let listener = match std::net::TcpListener::bind(config.addr) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("error: cannot listen on {}: {e}", config.addr);
            return ExitCode::FAILURE;
        }
    };
    let addr = match listener.local_addr() {
        Ok(addr) => addr,
        Err(e) => {
            eprintln!("error: the server has no address: {e}");
            return ExitCode::FAILURE;
        }
    };
    let url = format!("http://{addr}/");
    eprintln!("previewing {} at {url}", super::shown(&config.input));
    if !addr.ip().is_loopback() {
        eprintln!(
            "warning: listening on {}: other machines can see this preview",
            addr.ip()
        );
    }
    eprintln!("press Ctrl-C to stop");
    if config.open {
        open_browser(&url);
    }
    let ctx = server::Context::new(shared.clone(), addr, export);
    server::serve(&listener, ctx);
    eprintln!("stopped");
    ExitCode::SUCCESS
}

/// `--export`: waits until every frame is drawn in full, then encodes them into `out`. The
/// build's diagnostics are the terminal's already (`Shared::publish` prints them).
fn export_only(shared: &Shared, export: &Export, out: &Path) -> ExitCode {
    let start = Instant::now();
    let copied = export::encode(shared, export).and_then(|frames| {
        std::fs::copy(export.video(), out)
            .map(|_| frames)
            .map_err(|e| format!("error: {}: {e}", out.display()))
    });
    match copied {
        Ok(frames) => {
            eprintln!(
                "wrote {} ({frames} frames at full quality) in {:.2} s",
                out.display(),
                start.elapsed().as_secs_f64()
            );
            ExitCode::SUCCESS
        }
        Err(_) if shared.lock().builds == 0 => {
            eprintln!("error: nothing exported: the animation does not build");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}

/// Opens `url` in the system's browser, when there is one.
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(windows) {
        "explorer"
    } else {
        "xdg-open"
    };
    if let Err(e) = std::process::Command::new(opener).arg(url).spawn() {
        eprintln!("note: cannot open a browser ({opener}: {e}); open {url} yourself");
    }
}
