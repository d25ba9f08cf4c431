//! The preview contract: `anim preview` serves the animation in a browser, the small frames
//! first and then each frame as `anim render` draws it, follows edits (of the spec, the base
//! scene, the files it includes and its meshes) by rendering only the frames whose content
//! changed, shows located diagnostics and the warnings `anim render` prints, and serves
//! nothing but its own routes to nothing but its own address.
//!
//! - `session`: starting the real binary on a small copy of `animations/orbit.ron` (its base
//!   scene including its materials file), and plain HTTP requests to it.
//! - `http`: the routes, refusals (traversal, encoded traversal, foreign `Host`), pixels, edits
//!   and warnings, through plain HTTP requests.
//!   The server under load: half-open connections, a client that never reads, the event
//!   stream of a 100,000-frame spec.
//! - `watch`: named pipes as a mesh, as the scene after an edit, as a spec's base scene.
//! - `fuzz`: random requests and connection patterns (FUZZING.md).
//! - `lifecycle`: `--export` (full-quality frames only, wrong outputs refused before any
//!   render), SIGTERM and SIGHUP, the diagnostics the terminal prints.
//! - `browser`: the page in headless Chromium, driven by `scripts/preview-browser.py`.

#[path = "../common/mod.rs"]
mod common;

mod browser;
mod fuzz;
mod http;
mod lifecycle;
mod session;
mod watch;
