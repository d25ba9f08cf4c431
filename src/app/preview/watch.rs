//! Following edits: the folders of the spec, its base scene, the files that includes (to any
//! depth) and the OBJ files they all name are watched (`notify`); a change to one of those
//! files builds the animation again, and the state takes in the new frames, or the
//! diagnostics with the last good frames kept.

use super::project::Project;
use super::state::Shared;
use notify::event::ModifyKind;
use notify::{EventKind, RecursiveMode, Watcher as _};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::Duration;

/// Editors save in bursts (write, rename, touch): events this close together are one edit.
const SETTLE: Duration = Duration::from_millis(40);

/// Builds the project, then again after every edit of its files, until the preview stops.
/// Runs on its own thread; a watcher that cannot start leaves a warning and no following.
pub fn follow(project: &Project, shared: &Arc<Shared>) {
    let (tx, rx) = mpsc::channel();
    let watcher = notify::recommended_watcher(move |event: notify::Result<notify::Event>| {
        // Reading a file is an event too (the build reads them all): only changes count.
        let changes = |kind: &EventKind| {
            !matches!(
                kind,
                EventKind::Access(_) | EventKind::Modify(ModifyKind::Metadata(_))
            )
        };
        match event {
            Ok(event) if changes(&event.kind) => {
                let _ = tx.send(event.paths);
            }
            _ => {}
        }
    });
    let mut watcher = match watcher {
        Ok(w) => Some(w),
        Err(e) => {
            let mut state = shared.lock();
            state
                .warnings
                .push(format!("warning: edits are not followed: {e}"));
            None
        }
    };
    let mut dirs = BTreeSet::new();
    let mut files = rebuild(project, shared);
    loop {
        if let Some(w) = watcher.as_mut() {
            for dir in files.iter().filter_map(|f| f.parent()) {
                if !dirs.contains(dir) && w.watch(dir, RecursiveMode::NonRecursive).is_ok() {
                    dirs.insert(dir.to_path_buf());
                }
            }
        }
        let paths = match rx.recv_timeout(Duration::from_millis(200)) {
            Ok(paths) => paths,
            Err(mpsc::RecvTimeoutError::Timeout) => Vec::new(),
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                std::thread::sleep(Duration::from_millis(200));
                Vec::new()
            }
        };
        if shared.lock().stop {
            return;
        }
        if !paths.iter().any(|p| files.contains(&absolute(p))) {
            continue;
        }
        std::thread::sleep(SETTLE);
        while rx.try_recv().is_ok() {}
        files = rebuild(project, shared);
    }
}

/// Builds once and hands the result to the state; returns the files to watch, absolute.
fn rebuild(project: &Project, shared: &Shared) -> BTreeSet<PathBuf> {
    let built = project.build();
    let mut state = shared.lock();
    match built {
        Ok(built) => state.apply(built),
        Err(diagnostics) => state.diagnostics = diagnostics,
    }
    shared.publish(state);
    project.watched().iter().map(|p| absolute(p)).collect()
}

fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}
