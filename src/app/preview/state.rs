//! What the preview knows, shared by the server, the render workers and the watcher: each
//! frame's source and images, the diagnostics of the last build, the warnings of the build and
//! of the frames, and where the playhead is. Images are whole PNG files in memory, swapped in
//! only once complete.

use super::project::Built;
use anim_core::diag::Diagnostic;
use anim_core::util::Fnv64;
use anim_pipeline::frames::distinct_warnings;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::Duration;

/// How well a frame is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Quality {
    /// A quarter of the size, one sample per pixel.
    Small,
    /// The spec's size and the default sampling, as `anim render` draws it.
    Full,
}

/// One image of a frame, and the content fingerprint it was drawn from.
#[derive(Clone, Debug)]
pub struct Image {
    pub png: Arc<Vec<u8>>,
    pub key: u64,
    /// What rendering it warned of.
    pub warnings: Vec<Diagnostic>,
}

/// What a worker made of a frame: the PNG, and the warnings `anim render` gives the frame.
#[derive(Clone, Debug)]
pub struct Drawing {
    pub png: Vec<u8>,
    pub warnings: Vec<Diagnostic>,
}

#[derive(Clone, Debug, Default)]
pub struct Frame {
    pub path: PathBuf,
    pub key: u64,
    pub small: Option<Image>,
    pub full: Option<Image>,
    /// The job a worker is on, if any.
    pub busy: Option<Quality>,
    /// Bumped whenever the image served for this frame changes.
    pub version: u64,
    /// Images rendered for this frame since the preview started.
    pub renders: u64,
    /// Why the last render of this content failed.
    pub error: Option<String>,
    error_key: Option<u64>,
}

impl Frame {
    /// The image to show: the full one of the current content, else the small one, else
    /// whatever is left from before an edit.
    pub fn best(&self) -> Option<(&Image, Quality)> {
        let key = self.key;
        let full = self.full.as_ref().filter(|i| i.key == key);
        let small = self.small.as_ref().filter(|i| i.key == key);
        full.map(|i| (i, Quality::Full))
            .or_else(|| small.map(|i| (i, Quality::Small)))
            .or_else(|| self.full.as_ref().map(|i| (i, Quality::Full)))
            .or_else(|| self.small.as_ref().map(|i| (i, Quality::Small)))
    }

    fn needs(&self, q: Quality) -> bool {
        let image = match q {
            Quality::Small => &self.small,
            Quality::Full => &self.full,
        };
        self.busy.is_none()
            && self.error_key != Some(self.key)
            && image.as_ref().is_none_or(|i| i.key != self.key)
    }

    /// The frame as the page reads it (JSON; `error` only when there is one).
    fn write_json(&self, out: &mut String) {
        let _ = write!(
            out,
            "{{\"state\":\"{}\",\"v\":{},\"renders\":{}",
            self.state(),
            self.version,
            self.renders
        );
        if let Some(e) = &self.error {
            let _ = write!(out, ",\"error\":{}", json_string(e));
        }
        out.push('}');
    }

    /// Changes whenever what [`Frame::write_json`] writes does (its error changes only with
    /// a render, which `renders` counts).
    fn mark(&self) -> u64 {
        let mut h = Fnv64::default();
        h.write(self.state().as_bytes());
        h.write(&self.version.to_le_bytes());
        h.write(&self.renders.to_le_bytes());
        h.finish()
    }

    fn state(&self) -> &'static str {
        match self.best() {
            _ if self.error_key == Some(self.key) => "error",
            Some((i, q)) if i.key == self.key => match q {
                Quality::Full => "full",
                Quality::Small => "small",
            },
            Some(_) => "stale",
            None => "none",
        }
    }
}

/// A frame to render.
#[derive(Clone, Debug)]
pub struct Job {
    pub index: usize,
    pub quality: Quality,
    pub path: PathBuf,
    pub key: u64,
}

#[derive(Debug, Default)]
pub struct State {
    pub frames: Vec<Frame>,
    pub fps: f64,
    pub keys: Vec<f64>,
    /// The errors of the last build (the frames shown are from the last good one).
    pub diagnostics: Vec<String>,
    pub warnings: Vec<String>,
    pub playhead: usize,
    /// Bumped on every change the page should hear of.
    pub version: u64,
    pub stop: bool,
    /// Builds applied so far (0 until the first one ends).
    pub builds: u64,
    /// The warnings shown when the terminal last heard of them.
    printed: Vec<String>,
    /// The diagnostics the terminal last heard of (empty: the build was good).
    printed_diagnostics: Vec<String>,
}

/// The state with the two wake-ups: `changed` for the page's event streams, `work` for the
/// render workers.
#[derive(Default)]
pub struct Shared {
    state: Mutex<State>,
    pub changed: Condvar,
    pub work: Condvar,
}

impl Shared {
    pub fn lock(&self) -> MutexGuard<'_, State> {
        // A worker that panicked left the data whole (every change is one assignment).
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Wakes everyone after a change made under `state`.
    pub fn touch(&self, state: &mut State) {
        state.version += 1;
        self.changed.notify_all();
        self.work.notify_all();
    }

    /// Waits on `cv` for at most `timeout`.
    pub fn wait<'a>(
        &self,
        cv: &Condvar,
        guard: MutexGuard<'a, State>,
        timeout: Duration,
    ) -> MutexGuard<'a, State> {
        match cv.wait_timeout(guard, timeout) {
            Ok((g, _)) => g,
            Err(e) => e.into_inner().0,
        }
    }

    /// Wakes everyone after a change made under `state` (a build or a frame taken in), and
    /// prints what it brought: a build's diagnostics, or that it builds again, and the new
    /// warnings.
    pub fn publish(&self, mut state: MutexGuard<'_, State>) {
        self.touch(&mut state);
        let mut news = state.build_news();
        news.extend(state.new_warnings());
        drop(state);
        for warning in news {
            eprintln!("{warning}");
        }
    }

    pub fn stop(&self) {
        let mut s = self.lock();
        s.stop = true;
        self.touch(&mut s);
    }
}

impl State {
    /// Takes in a new build: frames whose content is unchanged keep their images and are not
    /// rendered again.
    pub fn apply(&mut self, built: Built) {
        let old = std::mem::take(&mut self.frames);
        self.frames = built
            .frames
            .into_iter()
            .enumerate()
            .map(|(i, src)| {
                let mut frame = old.get(i).cloned().unwrap_or_default();
                if frame.path != src.path || frame.key != src.key {
                    frame.version += 1;
                }
                frame.path = src.path;
                frame.key = src.key;
                frame
            })
            .collect();
        self.fps = built.fps;
        self.keys = built.keys;
        self.warnings = built.warnings;
        self.diagnostics.clear();
        self.playhead = self.playhead.min(self.frames.len().saturating_sub(1));
        self.builds += 1;
    }

    /// The next frame to render: every frame small first, then full, nearest the playhead
    /// first (round the loop, as the player wraps).
    pub fn next_job(&mut self) -> Option<Job> {
        let (n, playhead) = (self.frames.len(), self.playhead);
        // Walked outward under the lock, without sorting: a spec of 100,000 frames asks for
        // the next job as often as a frame is drawn.
        let (index, quality) = [Quality::Small, Quality::Full].into_iter().find_map(|q| {
            around(playhead, n)
                .find(|&i| self.frames[i].needs(q))
                .map(|i| (i, q))
        })?;
        let frame = &mut self.frames[index];
        frame.busy = Some(quality);
        Some(Job {
            index,
            quality,
            path: frame.path.clone(),
            key: frame.key,
        })
    }

    /// Stores what a worker made of `job` (dropped if the frame changed meanwhile).
    pub fn finish(&mut self, job: &Job, result: Result<Drawing, String>) {
        let Some(frame) = self.frames.get_mut(job.index) else {
            return;
        };
        frame.busy = None;
        if frame.key != job.key || frame.path != job.path {
            return;
        }
        frame.renders += 1;
        match result {
            Ok(drawing) => {
                let image = Some(Image {
                    png: Arc::new(drawing.png),
                    key: job.key,
                    warnings: drawing.warnings,
                });
                match job.quality {
                    Quality::Small => frame.small = image,
                    Quality::Full => frame.full = image,
                }
                frame.error = None;
                frame.version += 1;
            }
            Err(e) => {
                frame.error = Some(e);
                frame.error_key = Some(job.key);
            }
        }
    }

    /// The warnings to show: the build's, then each warning of the frames drawn in full (what
    /// `anim render` says of them) once, with the number of frames that had it.
    fn shown_warnings(&self) -> Vec<(String, usize)> {
        let mut shown: Vec<(String, usize)> =
            self.warnings.iter().map(|w| (w.clone(), 1)).collect();
        let drawn = self
            .frames
            .iter()
            .filter_map(|f| f.full.as_ref().filter(|i| i.key == f.key))
            .flat_map(|i| i.warnings.iter().cloned());
        for (d, count) in distinct_warnings(drawn) {
            let text = d.to_string();
            if !shown.iter().any(|(w, _)| *w == text) {
                shown.push((text, count));
            }
        }
        shown
    }

    /// The shown warnings that were not shown when this was last asked, in order: a warning
    /// that went away and came back is new again.
    fn new_warnings(&mut self) -> Vec<String> {
        let shown: Vec<String> = self.shown_warnings().into_iter().map(|(w, _)| w).collect();
        let news = shown
            .iter()
            .filter(|w| !self.printed.contains(w))
            .cloned()
            .collect();
        self.printed = shown;
        news
    }

    /// What the terminal should hear of the last build, once: its diagnostics when they
    /// differ from those it printed last (the page shows the same), or one line when the
    /// animation builds again after diagnostics.
    fn build_news(&mut self) -> Vec<String> {
        if self.diagnostics == self.printed_diagnostics {
            return Vec::new();
        }
        let mended = self.diagnostics.is_empty();
        self.printed_diagnostics = self.diagnostics.clone();
        if mended {
            vec![format!(
                "note: the animation builds again ({} frames)",
                self.frames.len()
            )]
        } else {
            self.diagnostics.clone()
        }
    }

    /// The state as the page reads it (JSON).
    pub fn to_json(&self) -> String {
        let mut out = self.head_json();
        out.push_str(",\"keys\":");
        out.push_str(&self.keys_json());
        out.push_str(",\"frames\":[");
        for (i, f) in self.frames.iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            f.write_json(&mut out);
        }
        out.push(']');
        out.push_str(&self.notes_json());
        out.push('}');
        out
    }

    /// What changed since a page was sent the state whose frames had `marks` (see
    /// [`State::frame_marks`]): the small fields, `n` (the number of frames), `changed` (the
    /// frames whose marks differ, by index), and the keys, diagnostics and warnings when
    /// `with_notes`. `None` when the frames are not the same list (a full state is due).
    pub fn delta_json(&self, marks: &[u64], now: &[u64], with_notes: bool) -> Option<String> {
        if marks.len() != self.frames.len() || now.len() != self.frames.len() {
            return None;
        }
        let mut out = self.head_json();
        let _ = write!(out, ",\"n\":{},\"changed\":{{", self.frames.len());
        let mut first = true;
        for (i, f) in self.frames.iter().enumerate() {
            if marks[i] != now[i] {
                let _ = write!(out, "{}\"{i}\":", if first { "" } else { "," });
                f.write_json(&mut out);
                first = false;
            }
        }
        out.push('}');
        if with_notes {
            out.push_str(",\"keys\":");
            out.push_str(&self.keys_json());
            out.push_str(&self.notes_json());
        }
        out.push('}');
        Some(out)
    }

    /// A mark of what the page shows of each frame: equal marks, nothing to send.
    pub fn frame_marks(&self) -> Vec<u64> {
        self.frames.iter().map(Frame::mark).collect()
    }

    /// A mark of the keys, diagnostics and warnings, and the JSON that carries them.
    pub fn notes_mark(&self) -> u64 {
        let mut text = self.keys_json();
        text.push_str(&self.notes_json());
        Fnv64::of(text.as_bytes())
    }

    fn head_json(&self) -> String {
        format!(
            "{{\"version\":{},\"builds\":{},\"fps\":{},\"playhead\":{}",
            self.version,
            self.builds,
            json_number(self.fps),
            self.playhead
        )
    }

    fn keys_json(&self) -> String {
        let keys: Vec<String> = self.keys.iter().map(|&k| json_number(k)).collect();
        format!("[{}]", keys.join(","))
    }

    /// `,"diagnostics":[...],"warnings":[...]`.
    fn notes_json(&self) -> String {
        let mut out = String::from(",\"diagnostics\":");
        out.push_str(&json_list(&self.diagnostics));
        out.push_str(",\"warnings\":");
        let warnings: Vec<String> = self
            .shown_warnings()
            .iter()
            .map(|(w, count)| crate::app::render::in_frames(w, *count))
            .collect();
        out.push_str(&json_list(&warnings));
        out
    }
}

fn json_number(x: f64) -> String {
    if x.is_finite() {
        x.to_string()
    } else {
        "0".to_string()
    }
}

fn json_list(items: &[String]) -> String {
    let items: Vec<String> = items.iter().map(|s| json_string(s)).collect();
    format!("[{}]", items.join(","))
}

/// `s` as a JSON string literal.
pub fn json_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x20 || c == '<' || c == '>' || c == '&' => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Every frame of `n` once, nearest the playhead first (circularly: the preview loops), the
/// later of two at one distance first.
fn around(playhead: usize, n: usize) -> impl Iterator<Item = usize> {
    (0..n).map(move |k| {
        let d = k.div_ceil(2);
        if k % 2 == 1 {
            (playhead + d) % n
        } else {
            (playhead + n - d) % n
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_visited_once_each_by_circular_distance_later_first() {
        for n in 1..12 {
            for playhead in 0..n {
                let walked: Vec<usize> = around(playhead, n).collect();
                let distance = |i: usize| {
                    let d = i.abs_diff(playhead);
                    d.min(n - d)
                };
                let mut expected: Vec<usize> = (0..n).map(|d| (playhead + d) % n).collect();
                expected.sort_by_key(|&i| distance(i));
                assert_eq!(walked, expected, "n {n} playhead {playhead}");
            }
        }
    }

    #[test]
    fn the_terminal_hears_each_new_set_of_diagnostics_then_that_it_builds_again() {
        let mut state = State::default();
        assert!(
            state.build_news().is_empty(),
            "a good first build says nothing"
        );
        let broken = vec!["a.ron:3:7: error: expected `)`".to_string()];
        state.diagnostics = broken.clone();
        assert_eq!(state.build_news(), broken);
        assert!(state.build_news().is_empty(), "printed once");
        let other = vec!["a.ron:4:1: error: expected `,`".to_string()];
        state.diagnostics = other.clone();
        assert_eq!(state.build_news(), other);
        state.frames = vec![Frame::default(); 3];
        state.diagnostics.clear();
        assert_eq!(
            state.build_news(),
            ["note: the animation builds again (3 frames)"]
        );
        assert!(state.build_news().is_empty());
    }
}
